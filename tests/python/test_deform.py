"""Map.deform: the map of a moved boundary from the previous map (the same
T-mesh and corners): no motion returns the same map, a rigid motion the
moved map, a smooth motion a certified map; mismatches are InputError."""
import math

import numpy as np
import pytest

import tspline
from conftest import DATA

COAST = DATA / "coastlines" / "isle_of_man.txt"


@pytest.fixture(scope="module")
def island():
    ring = np.loadtxt(COAST)
    return ring, tspline.parameterize(ring, layout="single")


UV = np.array([[u, v] for u in np.linspace(0, 1, 7) for v in np.linspace(0, 1, 7)])


def test_no_motion_returns_the_same_map(island):
    ring, m = island
    same = m.deform(ring)
    assert same.certified_valid
    assert same.cells == m.cells
    assert np.max(np.abs(same.evaluate(UV) - m.evaluate(UV))) < 1e-11


def test_rigid_motion_returns_the_moved_map(island):
    ring, m = island
    th = 0.4
    R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    t = np.array([10.0, -3.0])
    moved = m.deform(ring @ R.T + t)
    assert moved.certified_valid
    assert moved.cells == m.cells
    assert np.max(np.abs(moved.evaluate(UV) - (m.evaluate(UV) @ R.T + t))) < 1e-11


def test_smooth_motion_is_certified_on_the_same_tmesh(island):
    ring, m = island
    d = np.linalg.norm(ring.max(axis=0) - ring.min(axis=0))
    c = 0.5 * (ring.max(axis=0) + ring.min(axis=0))
    s = 0.03 * d
    moved = ring + s * np.column_stack([np.sin(2 * np.pi * (ring[:, 1] - c[1]) / d),
                                        np.cos(2 * np.pi * (ring[:, 0] - c[0]) / d)])
    m2 = m.deform(moved)
    assert m2.certified_valid
    assert m2.cells == m.cells
    # The certified whole-map lower bound of J_r, at least half the first map's.
    def jr(x):
        return x.report["jacobian"]["whole_map"]["mean_ratio"]["certified_lower_bound"]
    assert jr(m2) > 0.5 * jr(m)
    # The corners follow their vertices.
    corners = m2.evaluate(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    assert np.min(np.linalg.norm(moved[:, None, :] - corners[None, :, :], axis=2), axis=0).max() < 1e-9 * d


def test_mismatched_boundary_is_an_input_error(island):
    ring, m = island
    with pytest.raises(tspline.InputError, match="71 vertices"):
        m.deform(ring[:-1])
    crossing = ring.copy()
    crossing[[5, 40]] = crossing[[40, 5]]
    with pytest.raises(tspline.InputError, match="not simple"):
        m.deform(crossing)
