"""Tests of the Python module tspline (pytest): the single-patch
parameterization from an array and from a file, evaluation against the
polygon and finite differences, T-spline files, the Poisson solver with
expressions and callables, errors as Python exceptions of one hierarchy with
the library's messages, and the example script."""
import json
import math
import pathlib
import subprocess

import numpy as np
import pytest

import tspline
from conftest import APP, DATA, cli_eval

FLOWER = DATA / "polygons" / "flower.txt"


@pytest.fixture(scope="module")
def flower():
    return tspline.parameterize(np.loadtxt(FLOWER), layout="single")


def distance_to_polygon(points, poly):
    """Distance of each point to the closed polygon (its edges)."""
    a = poly
    b = np.roll(poly, -1, axis=0)
    d = np.full(len(points), np.inf)
    for p, q in zip(a, b):
        t = np.clip(((points - p) @ (q - p)) / ((q - p) @ (q - p)), 0.0, 1.0)
        d = np.minimum(d, np.linalg.norm(points - (p + t[:, None] * (q - p)), axis=1))
    return d


def test_parameterize_array_is_certified(flower):
    assert flower.certified_valid is True
    assert isinstance(flower.report, dict)
    assert flower.report["certified_valid"] is True
    assert flower.report["input_geometry"]["format"] == "array"
    assert flower.report["layout"]["chosen"] == "single" and flower.layout == "single"
    assert flower.patches == 1 and flower.version == 1 and flower.interfaces == []
    assert flower.cells > 64 and flower.functions > flower.cells


def test_border_of_the_square_lies_on_the_polygon(flower):
    poly = np.loadtxt(FLOWER)
    diameter = np.max(np.linalg.norm(poly[:, None, :] - poly[None, :, :], axis=2))
    t = np.linspace(0.0, 1.0, 41)
    uv = np.concatenate([np.c_[t, 0 * t], np.c_[t, 0 * t + 1], np.c_[0 * t, t], np.c_[0 * t + 1, t]])
    xy = flower.evaluate(uv)
    assert xy.shape == (len(uv), 2) and xy.dtype == np.float64
    # The boundary curve follows the polygon to the boundary tolerance (1e-5 of
    # the squared diagonal as an area); well below 1 % of the diameter.
    assert distance_to_polygon(xy, poly).max() < 5e-3 * diameter
    # The four corners of the square are polygon vertices.
    corners = flower.evaluate(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    assert distance_to_polygon(corners, poly).max() < 1e-12 * diameter
    assert np.min(np.linalg.norm(poly[None, :, :] - corners[:, None, :], axis=2), axis=1).max() < 1e-12 * diameter


def test_jacobian_matches_finite_differences(flower):
    rng = np.random.default_rng(3)
    uv = rng.uniform(0.05, 0.95, size=(20, 2))
    J = flower.jacobian(uv)
    assert J.shape == (20, 2, 2)
    h = 1e-6
    for c, e in enumerate(np.eye(2)):
        fd = (flower.evaluate(uv + h * e) - flower.evaluate(uv - h * e)) / (2 * h)
        # Knot lines make the map C2, not smoother: central differences are O(h^2) away.
        assert np.abs(J[:, :, c] - fd).max() < 1e-5 * np.abs(J).max()
    assert (np.linalg.det(J) > 0).all()


def test_save_and_load(flower, tmp_path):
    f = tmp_path / "tspline.json"
    flower.save_tspline(str(f))
    m2 = tspline.load(str(f))
    assert m2.certified_valid is True
    uv = np.random.default_rng(5).uniform(0, 1, size=(50, 2))
    assert np.array_equal(m2.evaluate(uv), flower.evaluate(uv))  # the file keeps every bit
    assert np.array_equal(m2.jacobian(uv), flower.jacobian(uv))


def test_parameterize_a_file_with_options():
    m = tspline.parameterize(str(DATA / "polygons" / "square.txt"), init_level=2, max_adapt=2)
    assert m.certified_valid and m.patches == 1  # auto: one patch is good
    assert m.report["input_geometry"]["format"] == "text"
    # The unit square is mapped onto itself by a rigid motion of the square
    # (whichever vertex is the first corner): J^T J = I, the centre is fixed.
    uv = np.array([[0.25, 0.5], [0.5, 0.5], [0.9, 0.1]])
    J = m.jacobian(uv)
    assert np.allclose(np.einsum("kri,krj->kij", J, J), np.eye(2), atol=1e-12)
    assert np.allclose(m.evaluate(np.array([[0.5, 0.5]])), [[0.5, 0.5]], atol=1e-13)


def test_poisson_expressions_and_callables_agree(flower):
    # u = x + y is harmonic; the IGA solution approximates it (the map is not affine).
    s1 = tspline.poisson(flower, f="0", g="x + y", exact="x + y", steps=2)
    s2 = tspline.poisson(flower, f=lambda x, y: 0.0, g=lambda x, y: x + y, exact=lambda x, y: x + y, steps=2)
    assert len(s1.steps) == 2 and s1.steps[-1]["dofs"] > s1.steps[0]["dofs"]
    uv = np.random.default_rng(7).uniform(0, 1, size=(30, 2))
    u1, u2 = s1.evaluate(uv), s2.evaluate(uv)
    assert u1.shape == (30,)
    assert np.array_equal(u1, u2)
    xy = flower.evaluate(uv)
    scale = np.abs(xy).max()
    # Measured: L2 error 2.6e-3 after 2 steps, pointwise at most 5e-3 here.
    assert np.abs(u1 - (xy[:, 0] + xy[:, 1])).max() < 1e-2 * scale
    assert s1.steps[-1]["l2"] < 0.7 * s1.steps[0]["l2"]


def test_poisson_reproduces_a_cubic_on_the_square():
    # On the square the map is affine, so u = x^3 + x^2 y - 2 y^3 + x y (f = -6x + 10y)
    # lies in the cubic analysis space and is reproduced to round-off.
    m = tspline.parameterize(np.loadtxt(DATA / "polygons" / "square.txt"), init_level=2, max_adapt=1, layout="single")
    u = "x^3 + x^2*y - 2*y^3 + x*y"
    sol = tspline.poisson(m, f=lambda x, y: -6 * x + 10 * y, g=u, exact=u, steps=1)
    uv = np.random.default_rng(11).uniform(0, 1, size=(40, 2))
    x, y = m.evaluate(uv).T
    assert np.abs(sol.evaluate(uv) - (x**3 + x**2 * y - 2 * y**3 + x * y)).max() < 1e-12
    assert sol.steps[0]["l2"] < 1e-12


SIDES = {"bottom": lambda t: (t, 0.0), "right": lambda t: (1.0, t), "top": lambda t: (1.0 - t, 1.0),
         "left": lambda t: (0.0, 1.0 - t)}


def test_poisson_on_a_multi_patch_file(tmp_path):
    # The plate with a hole, mapped by the built `tspline param` (a version-2 file of
    # several patches): the same solver through the path of the file.
    out = tmp_path / "plate"
    subprocess.run([str(APP), "param", str(DATA / "holes" / "plate_with_hole.txt"), "--out", str(out), "-q"],
                   check=True)
    doc = json.loads((out / "tspline.json").read_text())
    assert doc["version"] == 2
    u = "x^2 - y^2"  # harmonic; not in the pulled-back space (x + 2 y would be: reproduced to round-off)
    sol = tspline.poisson(str(out / "tspline.json"), f="0", g=u, exact=u, refine="uniform", steps=2)
    assert sol.patches == len(doc["patches"]) >= 2
    assert sol.steps[1]["l2"] < sol.steps[0]["l2"] / 8  # cubic splines: about 16x per uniform step
    # C0 across every cut: the two sides give the same u_h (t on one side is 1 - t on the other).
    t = np.linspace(0.0, 1.0, 9)
    for f in doc["interfaces"]:
        a = np.array([SIDES[f["side_a"]](s) for s in t])
        b = np.array([SIDES[f["side_b"]](1.0 - s) for s in t])
        assert np.abs(sol.evaluate(a, patch=f["patch_a"]) - sol.evaluate(b, patch=f["patch_b"])).max() < 1e-12
    with pytest.raises(ValueError, match="out of range"):
        sol.evaluate(t[:2, None].repeat(2, axis=1), patch=len(doc["patches"]))


def test_errors_are_python_exceptions_of_one_hierarchy(tmp_path):
    for name, base in [("InputError", ValueError), ("IoError", OSError), ("NumericalError", ArithmeticError)]:
        assert issubclass(getattr(tspline, name), tspline.Error) and issubclass(getattr(tspline, name), base)
    with pytest.raises(tspline.InputError, match=r"shape \(n, 2\)"):
        tspline.parameterize(np.zeros((4, 3)))
    with pytest.raises(TypeError, match="domain: expected a path"):
        tspline.parameterize(42)
    with pytest.raises(tspline.InputError, match="hole 1"):  # a hole outside the outer ring
        tspline.parameterize([np.loadtxt(FLOWER), np.array([[50.0, 50.0], [51.0, 50.0], [50.0, 51.0]])])
    with pytest.raises(tspline.InputError, match="not GeoJSON"):
        tspline.parameterize({"type": "Nothing"})
    with pytest.raises(tspline.InputError, match="crs 'EPSG:nonesuch'"):
        tspline.parameterize({"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]},
                             crs="EPSG:nonesuch")
    with pytest.raises(tspline.IoError, match="nonesuch"):
        tspline.parameterize(tmp_path / "nonesuch.txt")
    bowtie = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    with pytest.raises(tspline.InputError) as e:
        tspline.parameterize(bowtie)
    assert isinstance(e.value, ValueError) and "intersect" in str(e.value)
    with pytest.raises(tspline.InputError, match="apply to a file"):
        tspline.parameterize(np.loadtxt(FLOWER), layer="coast")
    with pytest.raises(OSError, match="nonesuch"):
        tspline.load("/nonesuch/tspline.json")
    with pytest.raises(TypeError, match="unknown keyword argument 'tolerance'"):
        tspline.parameterize(np.loadtxt(FLOWER), tolerance=1)
    m = tspline.parameterize(np.loadtxt(DATA / "polygons" / "square.txt"), init_level=2, max_adapt=1)
    blocker = tmp_path / "blocker"
    blocker.write_text("a file, not a folder")
    with pytest.raises(tspline.IoError, match="blocker"):
        m.save(blocker / "out")
    with pytest.raises(ValueError, match="outside"):
        m.evaluate(np.array([[1.5, 0.5]]))
    with pytest.raises(ValueError, match="f: cannot parse"):
        tspline.poisson(m, f="sin(", g="0")
    with pytest.raises(ZeroDivisionError):
        tspline.poisson(m, f=lambda x, y: 1 / 0, g="0")


def test_example_script(tmp_path):
    import os
    import subprocess
    import sys

    root = pathlib.Path(__file__).resolve().parents[2]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    # On a bundled real coastline (Rhodes, km).
    coast = root / "tests" / "data" / "coastlines" / "rhodes.txt"
    r = subprocess.run([sys.executable, str(root / "examples" / "ex6_python.py"), str(coast), str(tmp_path)],
                       capture_output=True, text=True, env=env, check=False)
    assert r.returncode == 0, r.stderr
    assert "certified valid: True" in r.stdout
    assert "reloaded map identical: True" in r.stdout
    assert (tmp_path / "tspline.json").exists()
    # -Laplace u = 1, u = 0 on the border: u_h > 0 inside.
    last = [line for line in r.stdout.splitlines() if line.startswith("max u_h")][0]
    assert float(last.split(":")[1]) > 0


def test_evaluate_equals_tspline_eval_on_a_coastline(tmp_path):
    """A bundled coastline (km), one patch: the module's evaluate and the
    `tspline eval` command on the saved file agree to round-off (both
    print/hold 17 digits; test_domains does the same on every patch of a layout)."""
    m = tspline.parameterize(str(DATA / "coastlines" / "isle_of_man.txt"), layout="single")
    assert m.certified_valid and m.patches == 1
    path = tmp_path / "iom.json"
    m.save_tspline(path)
    uv = np.array([[0.1, 0.2], [0.5, 0.5], [0.93, 0.41], [0.0, 0.0], [1.0, 0.7]])
    diam = np.ptp(np.loadtxt(DATA / "coastlines" / "isle_of_man.txt"), axis=0).max()
    for p in range(m.patches):
        got = cli_eval(path, uv, patch=p)
        assert got.shape == (len(uv), 2)
        assert np.abs(got - m.evaluate(uv, patch=p)).max() <= 1e-13 * diam
