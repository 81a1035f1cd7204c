"""The options of tspline.parameterize and `tspline param` come from one table
(apps/param_options.h): walking it, every option given to the program and to
the module sets the same settings fields, and only its own; every option of
the program's help is in the table; bad values are refused by both, with the
documented exceptions in Python."""
import re

import numpy as np
import pytest

import tspline
from conftest import DATA, run_app

SQUARE = DATA / "polygons" / "square.txt"
# What `tspline param` has besides the table: the domain, the output folder, how it prints.
PROGRAM_ONLY = {"--help", "--out", "--quiet", "--json"}


def sample_value(option):
    """A value of the option that differs from its default, as (Python value, command-line text)."""
    if option["type"] == "bool":
        return True, None
    if option["choices"]:
        value = next(c for c in option["choices"] if c != option["default"])
        return value, value
    if option["name"] == "corners":
        return [0, 5, 10, 15], "0,5,10,15"
    if option["type"] == "int":
        value = 13 if option["range"] is None else int(option["range"][0] + option["range"][1]) // 2 + 3
        return value, str(value)
    if option["type"] == "float":
        return 0.3700000000000001, repr(0.3700000000000001)  # read back to the same double by both
    return "some_" + option["name"], "some_" + option["name"]


def test_the_table_walked_option_by_option():
    options = tspline.param_options()
    assert len(options) >= 20
    base = tspline._settings_of_keywords()
    assert base == tspline._settings_of_arguments([str(SQUARE), "--out", "o"])  # the same defaults
    for option in options:
        value, text = sample_value(option)
        py = tspline._settings_of_keywords(**{option["name"]: value})
        cli = tspline._settings_of_arguments([str(SQUARE), "--out", "o", option["cli"]] + ([text] if text else []))
        assert py == cli, option["name"]
        changed = [key for key in base if py[key] != base[key]]
        assert changed == [option["cli"][2:]], option["name"]  # its own fields, and only those
        assert base[option["cli"][2:]] == option["default"]


def test_every_option_of_the_program_is_in_the_table():
    help_text = run_app("param", "--help").stdout
    flags = set(re.findall(r"(--[a-z][a-z-]*)", help_text))
    table = {o["cli"] for o in tspline.param_options()}
    assert table <= flags
    assert flags - table == PROGRAM_ONLY
    for o in tspline.param_options():
        assert o["help"].split()[0] in help_text  # the same help text


GEOJSON = DATA / "gis" / "corsica_lonlat.geojson"
# For every option that takes a value: a value out of its range (or a path
# that does not exist), and the domain to give it with. Flags have no bad value.
BAD_VALUES = {
    "layout": ("sideways", SQUARE), "optimizer": ("adam", SQUARE), "corners": ("0,1,2", SQUARE),
    "corner_trials": (0, SQUARE), "tol": (-1.0, SQUARE), "tol_rel": (float("nan"), SQUARE),
    "init_level": (11, SQUARE), "max_level": (0, SQUARE), "max_sweeps": (0, SQUARE), "omega": (2.5, SQUARE),
    "sweep_tol": (0.0, SQUARE), "min_jacobian": (1.5, SQUARE), "max_adapt": (-1, SQUARE),
    "max_cells": (0, SQUARE), "cert_depth": (30, SQUARE), "samples": (0, SQUARE), "blunt_tips": (95.0, SQUARE),
    "polygon": (5, GEOJSON), "feature": (99, GEOJSON), "layer": ("0", SQUARE),
    "vtu_compression": ("gzip", SQUARE),
}
MISSING_PATHS = {"cuts", "from"}  # a path that does not exist: an IoError / exit 2 naming the file


def cli_text(value):
    return ",".join(map(str, value)) if isinstance(value, list) else str(value)


def test_every_option_refuses_its_bad_value_in_both_front_ends_naming_it():
    options = tspline.param_options()
    with_value = {o["name"] for o in options if o["type"] != "bool"}
    assert with_value == set(BAD_VALUES) | MISSING_PATHS  # a new option needs its case here
    for name, (value, domain) in BAD_VALUES.items():
        flag = "--" + name.replace("_", "-")
        r = run_app("param", domain, "--out", "/nonexistent/o", flag, cli_text(value), check=False)
        assert r.returncode == 1 and r.stderr.count("\n") == 1, (name, r.stderr)
        assert flag in r.stderr and "`" not in r.stderr, (name, r.stderr)  # the flag, not a field name
        with pytest.raises(tspline.InputError) as error:
            tspline.parameterize(domain, **{name: value})
        message = str(error.value)
        assert re.search(r"\b%s\b" % name, message) and "--" not in message and "`" not in message, (name, message)
    for name in MISSING_PATHS:
        r = run_app("param", SQUARE, "--out", "/nonexistent/o", "--" + name, "/nonexistent/file", check=False)
        assert r.returncode == 2 and "/nonexistent/file" in r.stderr, (name, r.stderr)
        with pytest.raises(tspline.IoError, match="/nonexistent/file"):
            tspline.parameterize(SQUARE, **{name: "/nonexistent/file"})


def test_python_types_and_unknown_keywords():
    square = np.loadtxt(SQUARE)
    with pytest.raises(TypeError, match="init_level: expected an int, got float"):
        tspline.parameterize(square, init_level=2.5)
    with pytest.raises(TypeError, match="planar: expected True or False"):
        tspline.parameterize(square, planar="yes")
    with pytest.raises(TypeError, match="unknown keyword argument 'tolerance'"):
        tspline.parameterize(square, tolerance=1)
    with pytest.raises(TypeError, match="unknown keyword argument 'init-level'"):
        tspline.parameterize(square, **{"init-level": 2})
    # NumPy numbers are numbers; None is the default.
    m = tspline.parameterize(square, init_level=np.int64(2), max_adapt=1, tol_rel=np.float64(1e-5), corners=None,
                             layout="single")
    assert m.certified_valid and m.patches == 1
    assert m.report["options"]["init-level"]["initial_level"] == 2
