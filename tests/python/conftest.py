"""Shared helpers of the Python tests: the test data, the built `tspline`
program beside the module (build/apps/tspline), and reading its outputs."""
import json
import pathlib
import subprocess

import numpy as np
import pytest

import tspline

DATA = pathlib.Path(__file__).resolve().parent.parent / "data"
APP = pathlib.Path(tspline.__file__).resolve().parent.parent / "apps" / "tspline"


def run_app(*args, check=True):
    """Runs the tspline program; returns the CompletedProcess (text)."""
    if not APP.exists():
        pytest.fail(f"the tspline program is not built beside the module: {APP}")
    return subprocess.run([str(APP), *map(str, args)], capture_output=True, text=True, check=check)


def cli_param(domain, out, *options):
    """`tspline param DOMAIN --out OUT -q OPTIONS`; returns its report.json."""
    run_app("param", domain, "--out", out, "-q", *options)
    return json.loads((pathlib.Path(out) / "report.json").read_text())


def cli_eval(tspline_json, uv, patch=0):
    """`tspline eval FILE --patch P --at u v ...`: S(uv) as the program prints it (17 digits)."""
    args = ["eval", tspline_json, "--patch", str(patch)]
    for u, v in uv:
        args += ["--at", repr(float(u)), repr(float(v))]
    lines = [line for line in run_app(*args).stdout.splitlines() if line.strip()]
    return np.array([[float(t) for t in line.split()[2:4]] for line in lines])


def text_rings(path):
    """The rings of a text polygon file (blank lines separate them): a list of (n, 2) arrays."""
    rings, ring = [], []
    for line in pathlib.Path(path).read_text().splitlines():
        if line.strip().startswith("#"):
            continue  # a comment line does not separate rings
        line = line.split("#")[0].strip()
        if not line:
            if ring:
                rings.append(np.array(ring))
            ring = []
            continue
        ring.append([float(t) for t in line.split()])
    if ring:
        rings.append(np.array(ring))
    return rings


def diameter(m):
    """Bounding-box diagonal of a map's image (its border, sampled)."""
    t = np.linspace(0.0, 1.0, 33)
    uv = np.concatenate([np.c_[t, 0 * t], np.c_[t, 0 * t + 1], np.c_[0 * t, t], np.c_[0 * t + 1, t]])
    xy = np.concatenate([m.evaluate(uv, patch=p) for p in range(m.patches)])
    return float(np.linalg.norm(xy.max(axis=0) - xy.min(axis=0)))
