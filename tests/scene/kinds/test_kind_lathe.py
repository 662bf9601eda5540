"""lathe: a vertical segment is a cylinder, a slanted one a cone, a horizontal one an annulus;
the numba twin agrees; closed profiles are solids whose crossings alternate; scale invariance;
the tessellation's volume against Pappus."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kind_checks import SCALES, assert_alternates, mesh_volume, scratch, table, welded_edge_uses
from kernel_twins import Twins
from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import lathe as L
from workbench.scene.kinds import lathe_kernels

LK = Twins(lathe_kernels)
"""The kind's kernels callable from Python (``kernel_twins.Twins``)."""

REL = 1e-9
CUP = [[0, 0], [1, 0], [1.5, 2], [1.2, 2], [0.8, 0.3], [0, 0.3]]


def _lathe(points):
    return L.read({"points": points}, "o", {"material": "m"})


def _first(la, O, D, tmin=0.0, tmax=np.inf):
    head, aux = L.params(la, 0)
    par = table(head)
    t, f = LK.first(par, 0, aux, *map(float, O), *map(float, D), tmin, tmax, *scratch())
    n = LK.normal(par, 0, aux, f, *(O + t * D), scratch()[2]) if t < np.inf else None
    return t, f, n


@pytest.mark.parametrize("O, D", [((-5.0, 0.3, 0.2), (1.0, 0.0, 0.0)), ((-5.0, 0.3, 0.2), (2.0, 0.1, 0.0)),
                                  ((0.1, -0.4, 4.0), (0.0, 0.05, -0.5))])
def test_vertical_segment_is_a_cylinder(O, D):
    r = 1.5
    la = _lathe([[r, -1], [r, 1]])
    O, D = np.array(O), np.array(D)
    # |(O + t D)_xz| = r
    a, b, c = D[0] ** 2 + D[2] ** 2, 2 * (O[0] * D[0] + O[2] * D[2]), O[0] ** 2 + O[2] ** 2 - r * r
    q = -0.5 * (b + math.copysign(math.sqrt(b * b - 4 * a * c), b))
    t = min(q / a, c / q)
    P = O + t * D
    want_n = np.array([P[0], 0.0, P[2]]) / r
    got_t, got_n = L.intersect(la, O, D)
    nt, _, nn = _first(la, O, D)
    assert got_t == pytest.approx(t, rel=REL) and nt == pytest.approx(t, rel=REL)
    assert np.allclose(got_n, want_n, atol=REL) and np.allclose(nn, want_n, atol=REL)


def test_cone_and_annulus():
    """Profile (0, 2) -> (1, 0) -> (2, 0): a cone of apex (0, 2, 0), base radius 1, and the
    annulus 1 <= r <= 2 of the plane y = 0."""
    la = _lathe([[0, 2], [1, 0], [2, 0]])
    # straight down at x = 0.5: the cone's surface at y = 1, normal (2, 1, 0)/sqrt 5 (upwards
    # for a profile that goes down and out: the normal is to the right of its direction)
    O, D = np.array([0.5, 5.0, 0.0]), np.array([0.0, -1.0, 0.0])
    t, n = L.intersect(la, O, D)
    assert t == pytest.approx(4.0, rel=REL)
    assert np.allclose(np.abs(n), np.array([2.0, 1.0, 0.0]) / math.sqrt(5), atol=REL)
    nt, nf, nn = _first(la, O, D)
    assert nt == pytest.approx(4.0, rel=REL) and nf == 0 and np.allclose(nn, n, atol=1e-15)
    # down at x = 1.5: the annulus at y = 0
    t, n = L.intersect(la, np.array([0.0, 3.0, 1.5]), D)
    assert t == pytest.approx(3.0, rel=REL) and abs(n[1]) == 1.0
    assert L.intersect(la, np.array([0.0, 3.0, 2.5]), D)[0] == np.inf


def test_closed_cup_is_a_solid():
    la = _lathe(CUP)
    assert la.closed and not _lathe([[1, 0], [1, 1]]).closed
    head, aux = L.params(la, 0)
    par = table(head)
    rng = np.random.default_rng(11)
    ot, of = np.zeros(32), np.zeros(32, dtype=np.int64)
    hits = 0
    for _ in range(400):
        O = rng.normal(size=3) * 3
        D = rng.normal(size=3) * 0.5 + [0, 1, 0] - O
        ref = L.crossings(la, O, D)
        n = LK.events(par, 0, aux, *O, *D, ot, of, 32, scratch()[2])
        assert np.allclose(ot[:n], [t for t, _ in ref], rtol=1e-13, atol=0) and of[:n].tolist() == [f for _, f in ref]
        assert_alternates(ref, lambda t: bool(L.inside(la, O + t * D)))
        for t, f in ref[::2]:       # entering: the outward normal faces the ray
            assert L.normal(la, f, O + t * D) @ D < 0
        p = rng.normal(size=3)
        assert LK.inside(par, 0, aux, *p, scratch()[2]) == L.inside(la, p)
        hits += bool(ref)
    assert hits > 200


def test_scale_invariance():
    O, D = np.array([-4.0, 0.7, 0.3]), np.array([1.0, 0.02, 0.01])
    base = [t for t, _ in L.crossings(_lathe(CUP), O, D)]
    assert len(base) >= 2
    for k in SCALES:
        la = _lathe((np.array(CUP, dtype=float) * k).tolist())
        got = [t for t, _ in L.crossings(la, k * O, D)]
        assert np.allclose(np.array(got) / k, base, rtol=REL, atol=0)
        assert _first(la, k * O, D)[0] / k == pytest.approx(base[0], rel=REL)


def test_tessellation_volume_is_pappus():
    la = _lathe(CUP)
    P, N, F = L.mesh(la, 256)
    assert (welded_edge_uses(P, F) == 2).all()
    p = np.array(CUP, dtype=float)
    exact = sum(math.pi * (y1 - y0) * (r0 * r0 + r0 * r1 + r1 * r1) / 3
                for (r0, y0), (r1, y1) in zip(p, np.roll(p, -1, axis=0)))
    inscribed = exact * 256 / (2 * math.pi) * math.sin(2 * math.pi / 256)   # polygon of 256 sides
    assert mesh_volume(P, F) == pytest.approx(inscribed, rel=1e-12)


@pytest.mark.parametrize("points, key", [([[1, 0]], "o.points"), ([[-1, 0], [1, 1]], "o.points[0]"),
                                         ([[1, 0], [1, 0], [1, 1]], "o.points[1]"),
                                         ([[0, 0], [0, 1]], "o.points"), ([[1, 0], [1, "a"]], "o.points[1]")])
def test_bad_profiles_fail_in_one_line(points, key):
    with pytest.raises(WorkbenchError) as e:
        _lathe(points)
    msg = str(e.value)
    assert msg.startswith(key + ":") and "\n" not in msg
