#!/usr/bin/env bash
# Stage timings of the front half at about 1e3, 1e4, 1e5 (and 2.6e5) cells, Release build.
# Usage: bash bench/run_benchmarks.sh [POLYGON]   (default: tests/data/polygons/flower.txt)
# Whole runs of `tspline param` on the bundled coastlines: bench/bench_coastlines.sh.
# A second table refines a boundary-dominated domain (fjords) by tolerance alone.
set -euo pipefail
cd "$(dirname "$0")/.."
POLY=${1:-tests/data/polygons/flower.txt}
BUILD_DIR=build BUILD_TYPE=Release bash scripts/build.sh > /dev/null
header() { printf "%9s %9s %9s %9s %9s %9s %6s %9s %8s\n" cells vertices boundary tmesh coons optimize sweeps peak_MiB inverted; }
echo "domain: $POLY (size set by the initial uniform level 5, 7, 8, 9; tol-rel 1e-6)"
header
for level in 5 7 8 9; do
  ./build/bench/bench_front "$POLY" "$level" 1e-6
done
echo "domain: tests/data/polygons/fjords.txt (initial level 3; size set by tol-rel 1e-5, 1e-7, 1e-8)"
header
for tol in 1e-5 1e-7 1e-8; do
  ./build/bench/bench_front tests/data/polygons/fjords.txt 3 "$tol"
done
echo "T-spline stages on $POLY (initial level 5, 7, 9; tol-rel 1e-6); fit includes its own basis build"
printf "%9s %9s %9s %9s %9s %9s %9s %8s\n" cells functions basis fit check dense peak_MiB min_Jr
for level in 5 7 9; do
  ./build/bench/bench_fit "$POLY" "$level" 1e-6
done
echo "Certified validity (Bezier elements, (8,8) Bernstein numerator) on $POLY (initial level 5, 7, 8; tol-rel 1e-6)"
printf "%9s %9s %9s %9s %9s %9s %9s %9s %9s %13s %9s\n" cells elements functions fit extract certify us_per_el check certified min_rel_bound max_depth
for level in 5 7 8; do
  ./build/bench/bench_certify "$POLY" "$level" 1e-6
done
echo "Global untangling of the map (map_untangling.h) on tests/data/coastlines/bali.txt, initial level 4, 6, 7, 8 (about 7e2, 4e3, 1.7e4, 6.6e4 free control points; default tolerance)"
printf "%9s %9s %9s %9s %6s %7s %7s %9s %9s %13s %9s\n" cells elements free_pts samples stages lbfgs evals seconds certified min_rel_bound min_Jr
for level in 4 6 7 8; do
  ./build/bench/bench_untangle tests/data/coastlines/bali.txt "$level" | tail -n 1
done
echo "IGA Poisson on the unit square (identity map), uniform analysis T-mesh 2^L x 2^L, sin(pi x) sin(pi y)"
printf "%5s %9s %9s %8s %11s %10s %8s %-6s %9s %9s %9s\n" level cells dofs space_s dirichlet_s assembly_s solve_s solver residual max_err peak_MiB
for level in 7 8 9 10; do
  ./build/bench/bench_poisson "$level"
done
echo "libmeshopt on surfaces: torus patch, N x N nodes randomly displaced, 20 Gauss-Seidel sweeps (smooth_surface)"
printf "%8s %9s %8s %6s %12s %14s %8s %6s\n" nodes elements tangled sweeps s_per_sweep visits_per_s tangled min_q
for n in 100 317; do
  ./build/bench/bench_surface "$n" 20
done
