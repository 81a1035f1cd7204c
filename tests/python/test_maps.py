"""tspline.Map as the program's files: save(dir) writes the files of `tspline
param`, byte for byte where they are deterministic; T-spline files of version
1 and 2 round-trip through save_tspline and load; check() gives `tspline
check`'s certificate; render() the picture of `tspline render`."""
import json
import pathlib
import re

import numpy as np
import pytest

import tspline
from conftest import DATA, cli_param, run_app

PLATE = DATA / "holes" / "plate_with_hole.txt"
FLOWER = DATA / "polygons" / "flower.txt"


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    """The plate with a hole by the module (from its path) and by the program."""
    out = tmp_path_factory.mktemp("plate")
    cli_param(PLATE, out / "cli")
    return tspline.parameterize(PLATE), out


@pytest.fixture(scope="module")
def flower():
    return tspline.parameterize(np.loadtxt(FLOWER), layout="single")


def test_save_writes_the_files_of_tspline_param(plate):
    m, out = plate
    m.save(out / "py")
    cli_files = sorted(p.name for p in (out / "cli").iterdir())
    assert sorted(p.name for p in (out / "py").iterdir()) == cli_files
    assert "surface_bezier.vtu" in cli_files and "tspline.json" in cli_files
    for name in ["tspline.json", "surface.vtu", "surface_bezier.vtu", "control_net.vtu", "physical_tmesh.vtu",
                 "boundary.vtu", "parametric_tmesh.vtu"]:
        assert (out / "py" / name).read_bytes() == (out / "cli" / name).read_bytes(), name
    py, cli = (json.loads((out / d / "report.json").read_text()) for d in ("py", "cli"))
    assert py["totals"]["cells"] == cli["totals"]["cells"] and py["layout"] == cli["layout"]
    assert py == m.report


def test_a_single_patch_run_writes_its_adaptive_rounds_too(flower, tmp_path):
    flower.save(tmp_path)
    assert (tmp_path / "adapt.pvd").exists() and (tmp_path / "surface_bezier.vtu").exists()
    assert json.loads((tmp_path / "tspline.json").read_text())["version"] == 1


@pytest.mark.parametrize("which", ["flower", "plate"])
def test_load_round_trips_versions_1_and_2(which, flower, plate, tmp_path):
    m = flower if which == "flower" else plate[0]
    f = tmp_path / "tspline.json"
    m.save_tspline(f)
    version = json.loads(f.read_text())["version"]
    assert version == m.version == (1 if which == "flower" else 2)
    m2 = tspline.load(f)
    assert m2.version == version and m2.patches == m.patches and m2.certified_valid
    assert m2.interfaces == m.interfaces
    uv = np.random.default_rng(5).uniform(0, 1, size=(30, 2))
    for p in range(m.patches):
        assert np.array_equal(m2.evaluate(uv, patch=p), m.evaluate(uv, patch=p))  # every bit kept
        assert np.array_equal(m2.jacobian(uv, patch=p), m.jacobian(uv, patch=p))
    g = tmp_path / "again.json"
    m2.save_tspline(g)
    assert g.read_bytes() == f.read_bytes()
    with pytest.raises(tspline.InputError, match="no parameterization"):
        m2.save(tmp_path / "dir")


def test_check_is_the_certificate_of_tspline_check(plate):
    m, out = plate
    c = m.check()
    assert c["certified_valid"] is True and len(c["patches"]) == m.patches
    printed = run_app("check", out / "cli" / "tspline.json", "--per-patch").stdout
    elements = [int(n) for n in re.findall(r"^bezier elements: (\d+)$", printed, re.M)]
    # Every patch's block, then the whole map's.
    assert [p["elements"] for p in c["patches"]] + [c["elements"]] == elements
    assert c["elements"] == sum(p["elements"] for p in c["patches"]) == c["certified"]
    for p in c["patches"]:
        assert p["certified"] == p["elements"] and p["failures"] == [] and p["min_det_lower_bound"] > 0
        assert 0 < p["whole_map"]["mean_ratio"]["certified_lower_bound"] <= 1
    for q in ["mean_ratio", "scaled_jacobian"]:
        assert c["whole_map"][q]["certified_lower_bound"] == min(
            p["whole_map"][q]["certified_lower_bound"] for p in c["patches"])
    jr = float(re.search(r"^whole map: J_r >= (\S+)", printed, re.M).group(1))
    assert c["whole_map"]["mean_ratio"]["certified_lower_bound"] == pytest.approx(jr, rel=1e-5)
    assert c["min_relative_det_lower_bound"] == min(p["min_relative_det_lower_bound"] for p in c["patches"])
    gap = float(re.search(r"largest gap between the two images of a cut: (\S+)", printed).group(1))
    assert c["max_interface_gap"] == pytest.approx(gap, rel=1e-5, abs=1e-15)


def test_render_draws_the_picture_of_tspline_render(plate, tmp_path):
    m, out = plate
    m.save(tmp_path / "saved")
    for view in ["jacobian", "tmesh", "control-net", "layout"]:
        summary = m.render(tmp_path / f"{view}.png", view=view, size=(400, 300))
        run_app("render", tmp_path / "saved", "--view", view, "--size", "400x300", "--png", tmp_path / f"cli_{view}.png")
        png = (tmp_path / f"{view}.png").read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 1000
        assert png == (tmp_path / f"cli_{view}.png").read_bytes(), view
        if view == "layout":
            assert summary["max"] == m.patches
        if view == "jacobian":
            assert 0 < summary["min"] <= summary["max"] <= 1
    with pytest.raises(tspline.InputError, match="solution"):
        m.render(tmp_path / "x.png", view="solution")
    with pytest.raises(tspline.InputError):
        m.render(tmp_path / "x.png", view="sideways")


def test_patch_arguments_are_checked(plate):
    m, _ = plate
    with pytest.raises(tspline.InputError, match="out of range"):
        m.evaluate(np.array([[0.5, 0.5]]), patch=m.patches)
    with pytest.raises(tspline.InputError, match="outside"):
        m.jacobian(np.array([[0.5, 1.5]]), patch=0)
    with pytest.raises(tspline.InputError, match=r"shape \(n, 2\)"):
        m.evaluate(np.zeros((3, 3)))
