#!/usr/bin/env bash
# IGA Poisson solvers at scale: direct (CHOLMOD) vs iterative (PETSc CG +
# AMG) with 1 and 2 MPI ranks, on the unit square (bench_poisson: identity map,
# uniform 2^L x 2^L cubic analysis mesh), then on a curved domain (the disk) with
# `tspline poisson --refine uniform` up to about 1.7e5 DOFs (direct) and 6.6e5 (iterative).
# Usage: bash bench/run_poisson_solvers.sh [LEVELS]   (default "8 9 10 11"; level 11 = 4.2e6 DOFs)
# DIRECT_MAX_LEVEL (default 10): no direct solve above it (CHOLMOD needs ~20 GB at level 11).
set -euo pipefail
cd "$(dirname "$0")/.."
LEVELS=${1:-8 9 10 11}
DIRECT_MAX_LEVEL=${DIRECT_MAX_LEVEL:-10}
BUILD_DIR=build BUILD_TYPE=Release bash scripts/build.sh > /dev/null
if [ "$(id -u)" -eq 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
MPIRUN="mpirun --oversubscribe -n"
B=./build/bench/bench_poisson
echo "unit square, u = sin(pi x) sin(pi y); peak_MiB = largest process, peak_total_MiB = sum over ranks"
printf "%5s %9s %9s %8s %11s %10s %8s %-9s %9s %9s %9s %5s %5s %9s %8s %8s\n" level cells dofs space_s dirichlet_s \
  assembly_s solve_s solver residual max_err peak_MiB ranks its peak_total_MiB asm_cpu solve_cpu
for level in $LEVELS; do
  if [ "$level" -le "$DIRECT_MAX_LEVEL" ]; then $B "$level" direct; fi
  $B "$level" iterative boomeramg
  $B "$level" iterative gamg
  $MPIRUN 2 $B "$level" iterative boomeramg
done
echo "disk (curved), tspline poisson --problem sinsin --refine uniform (default --rtol auto): every step;"
echo "direct to about 1.7e5 DOFs (6 steps), iterative to about 6.6e5 (7 steps)"
T=$(mktemp -d)
./build/apps/tspline param tests/data/polygons/disk.txt --out "$T/disk" -q
for solver in direct iterative; do
  steps=6; if [ "$solver" = iterative ]; then steps=7; fi
  ./build/apps/tspline poisson "$T/disk/tspline.json" --problem sinsin --refine uniform --steps "$steps" --samples 1 \
    --max-dofs 700000 --solver "$solver" -q --out "$T/$solver"
  python3 -c "
import json,sys
for s in json.load(open('$T/$solver/report.json'))['steps']:
  print('%-9s dofs %7d assembly_s %6.2f solve_s %6.2f its %3d rtol %.1e residual %.1e L2 %.9e H1 %.9e peak_MiB %.0f' % (
    '$solver', s['dofs'], s['assembly_seconds'], s['solve_seconds'], s['solver']['iterations'], s['solver']['rtol'],
    s['solver']['relative_residual'], s['l2'], s['h1'], s['peak_memory_mib']['total']))"
done
echo "multi-patch maps (bench_poisson MAP.json R): the framed square cut along its diagonals (4 patches) at"
echo "1.06e6 DOFs and the disk's quad layout (44 patches) at 7.3e5, 1 and 2 ranks"
printf "0 0\n10 0\n10 10\n0 10\n\n3 3\n7 3\n7 7\n3 7\n" > "$T/framed.txt"
printf "3 3\n0 0\n\n7 3\n10 0\n\n7 7\n10 10\n\n3 7\n0 10\n" > "$T/framed_cuts.txt"
./build/apps/tspline param "$T/framed.txt" --cuts "$T/framed_cuts.txt" --out "$T/framed" -q
./build/apps/tspline param tests/data/polygons/disk.txt --out "$T/disk_layout" -q
for map in "framed 6" "disk_layout 4"; do
  set -- $map
  /usr/bin/time -f "whole process: %e s wall, %U s user, %M KB" $B "$T/$1/tspline.json" "$2" iterative
  $MPIRUN 2 $B "$T/$1/tspline.json" "$2" iterative
done
rm -rf "$T"
