#!/usr/bin/env bash
# The main job on a bundled example: installs what is missing, builds the
# tspline program only (the test command builds the rest), and parameterizes tests/data/polygons/flower.txt into out/flower (open the .vtu files in ParaView).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
TARGETS=tspline_app bash scripts/build.sh
./build/apps/tspline param tests/data/polygons/flower.txt --out out/flower "$@"
