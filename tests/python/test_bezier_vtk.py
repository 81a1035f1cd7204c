"""surface_bezier.vtu of a multi-patch map, read by VTK's own reader (Python
VTK): every cell a rational bicubic Bezier quadrilateral whose evaluation by
VTK at random parametric points equals `tspline eval` of its patch to 1e-12 of
the domain's diameter; Map.save_vtk_bezier writes the same file."""
import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import tspline
from conftest import DATA, cli_eval, diameter


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    out = tmp_path_factory.mktemp("sea")
    m = tspline.parameterize(DATA / "holes" / "plate_with_hole_lonlat.geojson")
    m.save(out)
    return m, out


def test_vtk_evaluates_every_cell_as_tspline_eval(saved):
    m, out = saved
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(out / "surface_bezier.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    n = grid.GetNumberOfCells()
    assert n > m.cells  # the elements: T-mesh cells split by knot lines (and some cells not)
    assert {grid.GetCellType(c) for c in range(n)} == {vtk.VTK_BEZIER_QUADRILATERAL}
    assert grid.GetPointData().GetRationalWeights().GetName() == "RationalWeights"
    degrees = vtk_to_numpy(grid.GetCellData().GetHigherOrderDegrees())
    assert (degrees[:, :2] == 3).all()
    data = {name: vtk_to_numpy(grid.GetCellData().GetArray(name)) for name in
            ["patch", "certified", "parametric_lo", "parametric_hi"]}
    assert set(data["patch"]) == set(range(m.patches))
    assert (data["certified"] == 1).all()  # the map is certified: every element
    # Random local points of every cell, evaluated by VTK; the same parameters through `tspline eval`.
    rng = np.random.default_rng(11)
    cell = vtk.vtkGenericCell()
    weights = [0.0] * 16
    vtk_xy, uv, patch = [], [], []
    for c in range(n):
        grid.GetCell(c, cell)
        for pc in rng.uniform(0.0, 1.0, (2, 2)):
            x = [0.0, 0.0, 0.0]
            cell.EvaluateLocation(vtk.reference(0), [pc[0], pc[1], 0.0], x, weights)
            lo, hi = data["parametric_lo"][c, :2], data["parametric_hi"][c, :2]
            vtk_xy.append(x[:2])
            uv.append(lo + pc * (hi - lo))
            patch.append(data["patch"][c])
    vtk_xy, uv, patch = np.array(vtk_xy), np.array(uv), np.array(patch)
    tol = 1e-12 * diameter(m)
    for p in range(m.patches):
        mine = patch == p
        assert np.abs(vtk_xy[mine] - cli_eval(out / "tspline.json", uv[mine], patch=p)).max() <= tol
    # J_r as point data: at a cell's corner points (its first four, where the
    # rational Bernstein basis is 1) the data are J_r = 2 det J / |J|^2 there.
    jr = vtk_to_numpy(grid.GetPointData().GetArray("mean_ratio_jacobian"))
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    for c in range(0, n, 7):
        lo, hi = data["parametric_lo"][c, :2], data["parametric_hi"][c, :2]
        J = m.jacobian(lo + corners * (hi - lo), patch=int(data["patch"][c]))
        expected = 2 * np.linalg.det(J) / np.einsum("kij,kij->k", J, J)
        ids = [grid.GetCell(c).GetPointId(k) for k in range(4)]
        assert np.abs(jr[ids] - expected).max() < 1e-12


def test_save_vtk_bezier_writes_the_same_cells(saved, tmp_path):
    m, out = saved
    m.save_vtk_bezier(tmp_path / "cells.vtu")
    assert (tmp_path / "cells.vtu").read_bytes() == (out / "surface_bezier.vtu").read_bytes()
    loaded = tspline.load(out / "tspline.json")
    loaded.save_vtk_bezier(tmp_path / "loaded.vtu")
    assert (tmp_path / "loaded.vtu").read_bytes() == (out / "surface_bezier.vtu").read_bytes()
