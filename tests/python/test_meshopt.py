"""tspline.meshopt: the meshopt program's runs from Python where the build has
Gmsh (the same output files and reports as `meshopt smooth` and `meshopt
remesh` on the same model), and a clear error where it has not."""
import json
import subprocess

import pytest

import tspline
from conftest import APP

MESHOPT = APP.parent / "meshopt"
SPHERE = 'SetFactory("OpenCASCADE");\nSphere(1) = {0, 0, 0, 1};\nMesh.MeshSizeMax = 0.3;\n'


def test_available_where_the_meshopt_program_is_built(tmp_path):
    assert tspline.meshopt.available == MESHOPT.exists()
    if not tspline.meshopt.available:
        with pytest.raises(tspline.InputError, match="no Gmsh"):
            tspline.meshopt.smooth(tmp_path / "m.geo", tmp_path / "o.msh")


@pytest.mark.skipif(not MESHOPT.exists(), reason="built without Gmsh (checked above)")
def test_smooth_and_remesh_as_the_program(tmp_path):
    model = tmp_path / "sphere.geo"
    model.write_text(SPHERE)
    r = tspline.meshopt.smooth(model, tmp_path / "py.msh")
    subprocess.run([str(MESHOPT), "smooth", str(model), "--out", str(tmp_path / "cli.msh"), "--quiet"], check=True,
                   capture_output=True)
    cli = json.loads((tmp_path / "cli.json").read_text())
    assert r == json.loads((tmp_path / "py.json").read_text())  # the report it wrote
    assert r["after"] == cli["after"] and r["nodes"] == cli["nodes"] and r["sweeps"] == cli["sweeps"]
    assert r["after"]["tangled"] == 0 and r["after"]["min"] > r["before"]["min"]
    assert (tmp_path / "py.msh").stat().st_size > 1000
    q = tspline.meshopt.remesh(model, tmp_path / "rpy.msh", max_deviation=0.02, vtu=tmp_path / "rpy.vtu")
    subprocess.run([str(MESHOPT), "remesh", str(model), "--out", str(tmp_path / "rcli.msh"), "--max-deviation",
                    "0.02", "--quiet"], check=True, capture_output=True)
    rcli = json.loads((tmp_path / "rcli.json").read_text())
    assert q["after"] == rcli["after"] and q["operations"] == rcli["operations"]
    assert q["chordal_deviation"]["max"] <= 0.02 and (tmp_path / "rpy.vtu").exists()
    with pytest.raises(tspline.InputError, match="--length or --max-deviation"):
        tspline.meshopt.remesh(model, tmp_path / "x.msh")
    with pytest.raises(tspline.InputError, match="--measure"):
        tspline.meshopt.smooth(model, tmp_path / "x.msh", measure="round")
