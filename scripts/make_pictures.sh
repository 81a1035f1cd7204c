#!/usr/bin/env bash
# The README's pictures, made by `tspline render` from the bundled example:
# parameterizes tests/data/polygons/flower.txt, solves the Gaussian-peak Poisson problem
# adaptively on it, and draws four views into docs/images/, with the Poisson
# run's convergence plot; and Corsica from its longitude/latitude GeoJSON (GIS
# input projected to metres); and the Comoros sea as rational Bezier cells in
# VTK (scripts/bezier_picture.py; needs xvfb-run without a display).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
T=./build/apps/tspline
$T param tests/data/polygons/flower.txt --layout single --out out/flower -q   # the one-patch pictures of the README
$T poisson out/flower/tspline.json --problem gaussian --steps 8 --out out/flower_poisson -q
mkdir -p docs/images
for view in jacobian tmesh control-net; do
  $T render out/flower --view "$view" --size 800x600 --png "docs/images/flower_$view.png"
done
$T render out/flower_poisson --view solution --size 800x600 --png docs/images/flower_poisson.png
cp out/flower_poisson/convergence.png docs/images/flower_convergence.png
$T param tests/data/gis/corsica_lonlat.geojson --layout single --out out/corsica -q
$T render out/corsica --view jacobian --size 800x600 --png docs/images/corsica_jacobian.png
# surface_bezier.vtu as ParaView draws it, by VTK's own offscreen rendering
# (python3-vtk9, through the Python module): without a display under xvfb-run (Debian's xvfb).
if [ -n "${DISPLAY:-}" ]; then RUN=(); else RUN=(xvfb-run -a -s "-screen 0 1920x1080x24"); fi
PYTHONPATH=build/python "${RUN[@]}" /usr/bin/python3 scripts/bezier_picture.py out/comoros_py docs/images/comoros_bezier.png
