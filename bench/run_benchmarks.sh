#!/usr/bin/env bash
# Stage timings of the front half at about 1e3, 1e4 and 1e5 cells (Release build).
# Usage: bash bench/run_benchmarks.sh [POLYGON]   (default: tests/data/polygons/flower.txt)
set -euo pipefail
cd "$(dirname "$0")/.."
POLY=${1:-tests/data/polygons/flower.txt}
BUILD_DIR=build BUILD_TYPE=Release bash scripts/build.sh > /dev/null
echo "domain: $POLY"
printf "%9s %9s %9s %9s %9s %9s %6s %9s %8s\n" cells vertices boundary tmesh coons optimize sweeps peak_MiB inverted
# Sizes are set by the initial uniform level (the boundary tolerance adds a little).
for level in 5 7 8; do
  ./build/bench/bench_front "$POLY" "$level" 1e-6
done
