#!/usr/bin/env python3
"""Example 6 — the toolkit from Python (module `tspline`, built into
build/python/ and installed by `cmake --install`).

Parameterizes a domain given as a NumPy array of polygon vertices (a file —
text polygon with holes, Shapefile, GeoPackage, GeoJSON — a list of rings, a
GeoJSON dict or a shapely polygon work alike), with the options and the
layout choice of `tspline param`; evaluates the map and its Jacobian on a grid
of every patch's parameter square; writes the files of `tspline param` and
reloads the T-spline file; solves a Poisson problem with the source given as a
Python function.

    PYTHONPATH=build/python python3 examples/ex6_python.py tests/data/polygons/flower.txt out/ex6
"""
import pathlib
import sys

import numpy as np

import tspline

polygon_file = sys.argv[1] if len(sys.argv) > 1 else "tests/data/polygons/flower.txt"
out = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else "out/ex6")

# 1. The polygon as an (n, 2) array; keyword options as on the command line
#    (tspline.param_options() lists them). The layout is chosen as by
#    `tspline param`: one patch where one is good, a quad layout otherwise.
vertices = np.loadtxt(polygon_file)
m = tspline.parameterize(vertices, tol_rel=1e-5)
print(f"{len(vertices)} vertices -> layout {m.layout}: {m.patches} patch(es), {m.cells} cells, "
      f"{m.functions} functions, certified valid: {m.certified_valid}")

# 2. Every patch maps its own unit square: the map and its Jacobian on a
#    21 x 21 grid of each (arrays in, arrays out).
t = np.linspace(0.0, 1.0, 21)
uv = np.stack(np.meshgrid(t, t), axis=-1).reshape(-1, 2)
xy = np.concatenate([m.evaluate(uv, patch=p) for p in range(m.patches)])          # (441 P, 2)
det = np.concatenate([np.linalg.det(m.jacobian(uv, patch=p)) for p in range(m.patches)])
print(f"grid: x in [{xy[:, 0].min():.3f}, {xy[:, 0].max():.3f}], det J in [{det.min():.4g}, {det.max():.4g}]")

# 3. The files of `tspline param` (ParaView: surface.vtu, surface_bezier.vtu,
#    ...; report.json), and the T-spline file read back.
m.save(out)
m2 = tspline.load(out / "tspline.json")
same = all(np.array_equal(m2.evaluate(uv, patch=p), m.evaluate(uv, patch=p)) for p in range(m.patches))
print("reloaded map identical:", same)

# 4. Poisson: -Laplace u = f with f a Python function, u = 0 on the boundary,
#    on every patch at once (continuous across the interfaces).
sol = m.poisson(f=lambda x, y: 1.0, g="0", steps=3)
for s in sol.steps:
    print(f"step {s['step']}: {s['dofs']} dofs, eta {s['eta']:.3e}")
u = np.concatenate([sol.evaluate(uv, patch=p) for p in range(m.patches)])
print(f"max u_h on the grids: {u.max():.5f}")
