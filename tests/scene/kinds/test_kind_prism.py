"""prism: a square is a box (hits and normals against the slab method), a concave star is a
solid whose crossings alternate, the numba twin agrees, scale invariance, bad polygons are
refused, the tessellation is closed with the polygon's area times the height as volume."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kind_checks import SCALES, assert_alternates, mesh_volume, scratch, table, welded_edge_uses
from kernel_twins import Twins
from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import prism as R
from workbench.scene.kinds import prism_kernels

RK = Twins(prism_kernels)
"""The kind's kernels callable from Python (``kernel_twins.Twins``)."""

REL = 1e-9
STAR = [[math.cos(a) * (1.0 if i % 2 == 0 else 0.4), math.sin(a) * (1.0 if i % 2 == 0 else 0.4)]
        for i, a in enumerate(np.linspace(0, 2 * np.pi, 11)[:-1])]


def _prism(polygon, heights):
    return R.read({"polygon": polygon, "heights": heights}, "o", {"material": "m"})


def _slab(lo, hi, O, D):
    """Box entry t and its outward normal (Kay & Kajiya), for a ray from outside."""
    t0, n0 = -np.inf, None
    t1 = np.inf
    for a in range(3):
        if D[a] == 0.0:
            if not lo[a] <= O[a] <= hi[a]:
                return np.inf, None
            continue
        ta, tb = (lo[a] - O[a]) / D[a], (hi[a] - O[a]) / D[a]
        na = -np.eye(3)[a] if D[a] > 0 else np.eye(3)[a]
        if min(ta, tb) > t0:
            t0, n0 = min(ta, tb), na
        t1 = min(t1, max(ta, tb))
    return (t0, n0) if t0 < t1 and t0 > 0 else (np.inf, None)


@pytest.mark.parametrize("clockwise", [False, True])
def test_square_is_a_box(clockwise):
    sq = [[-1, -2], [3, -2], [3, 1], [-1, 1]]
    p = _prism(sq[::-1] if clockwise else sq, [-0.5, 2.0])
    lo, hi = np.array([-1, -0.5, -2]), np.array([3, 2.0, 1])
    head, aux = R.params(p, 0)
    par = table(head)
    rng = np.random.default_rng(4)
    hit = 0
    for _ in range(300):
        O = rng.normal(size=3) * 2 + np.sign(rng.normal(size=3)) * 6
        D = rng.uniform(lo, hi) - O + rng.normal(size=3)
        want_t, want_n = _slab(lo, hi, O, D)
        t, n = R.intersect(p, O, D)
        nt, nf = RK.first(par, 0, aux, *O, *D, 0.0, np.inf, *scratch())
        if want_t == np.inf:
            assert t == np.inf and nt == np.inf
            continue
        hit += 1
        assert t == pytest.approx(want_t, rel=REL) and nt == pytest.approx(want_t, rel=REL)
        assert np.allclose(n, want_n, atol=1e-15) and np.allclose(RK.normal(par, 0, aux, nf, *(O + nt * D), scratch()[2]), want_n, atol=1e-15)
    assert hit > 150


def test_concave_star_is_a_solid():
    p = _prism(STAR, [0.0, 0.5])
    head, aux = R.params(p, 0)
    par = table(head)
    rng = np.random.default_rng(2)
    ot, of = np.zeros(32), np.zeros(32, dtype=np.int64)
    for _ in range(400):
        O = rng.normal(size=3) * 2
        D = rng.normal(size=3) * 0.5 - O
        ref = R.crossings(p, O, D)
        n = RK.events(par, 0, aux, *O, *D, ot, of, 32, scratch()[2])
        assert np.allclose(ot[:n], [t for t, _ in ref], rtol=1e-13, atol=0) and of[:n].tolist() == [f for _, f in ref]
        assert_alternates(ref, lambda t: bool(R.inside(p, O + t * D)))
        for t, f in ref[::2]:
            assert R.normal(p, f) @ D < 0
        q = rng.normal(size=3) * 0.7
        assert RK.inside(par, 0, aux, *q, scratch()[2]) == R.inside(p, q)


def test_ray_through_a_vertex_enters_once():
    """Through the star's tip (1, 0) along x: both walls meeting there give the same t."""
    p = _prism(STAR, [0.0, 0.5])
    ref = R.crossings(p, np.array([3.0, 0.25, 0.0]), np.array([-1.0, 0.0, 0.0]))
    assert [t for t, _ in ref] == pytest.approx([2.0, 3.4], rel=REL)


def test_scale_invariance():
    O, D = np.array([-3.0, 0.2, 0.1]), np.array([1.0, 0.01, 0.02])
    base = [t for t, _ in R.crossings(_prism(STAR, [0.0, 0.5]), O, D)]
    assert len(base) >= 2
    for k in SCALES:
        p = _prism((np.array(STAR) * k).tolist(), [0.0, 0.5 * k])
        got = [t for t, _ in R.crossings(p, k * O, D)]
        assert np.allclose(np.array(got) / k, base, rtol=REL, atol=0)
        head, aux = R.params(p, 0)
        assert RK.first(table(head), 0, aux, *(k * O), *D, 0.0, np.inf, *scratch())[0] / k == pytest.approx(base[0], rel=REL)


def test_tessellation_is_closed_with_the_right_volume():
    p = _prism(STAR, [0.0, 0.5])
    P, N, F = R.mesh(p)
    assert (welded_edge_uses(P, F) == 2).all()
    x, z = np.array(STAR).T
    area = abs(0.5 * np.sum(x * np.roll(z, -1) - np.roll(x, -1) * z))
    assert mesh_volume(P, F) == pytest.approx(area * 0.5, rel=1e-12)


@pytest.mark.parametrize("t, key", [
    ({"polygon": [[0, 0], [1, 1], [1, 0], [0, 1]], "heights": [0, 1]}, "o.polygon"),
    ({"polygon": [[0, 0], [1, 1]], "heights": [0, 1]}, "o.polygon"),
    ({"polygon": [[0, 0], [1, 0], [0, 1]], "heights": [1, 0]}, "o.heights"),
    ({"polygon": [[0, 0], [1, 0], [2, 0]], "heights": [0, 1]}, "o.polygon"),
    ({"polygon": [[0, 0], [1, 0], [1, 0], [0, 1]], "heights": [0, 1]}, "o.polygon[2]"),
    ({"polygon": [[0, 0], [1, 0], [0, 1]]}, "o.heights"),
])
def test_bad_tables_fail_in_one_line(t, key):
    with pytest.raises(WorkbenchError) as e:
        R.read(t, "o", {"material": "m"})
    msg = str(e.value)
    assert msg.startswith(key + ":") and "\n" not in msg


def test_patch_surfaces_are_outward_convex_polygons_covering_the_surface():
    p = _prism(STAR, [0.0, 0.5])
    W = np.diag([2.0, 1.0, -1.0, 1.0])      # a mirror: the winding must follow
    polys = [v for kind, v in R.patch_surfaces(p, W, 0.1) if kind == "polygon"]
    area = sum(np.linalg.norm(np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)) / 2 for v in polys)
    P, _, F = R.mesh(p)
    Pw = P @ W[:3, :3].T
    tri = np.cross(Pw[F[:, 1]] - Pw[F[:, 0]], Pw[F[:, 2]] - Pw[F[:, 0]])
    assert area == pytest.approx(np.linalg.norm(tri, axis=1).sum() / 2, rel=1e-12)
    c = Pw.mean(0)
    for v in polys:       # outward: the normal points away from the (star-shaped) solid's centre
        n = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
        assert n @ (v.mean(0) - c) > 0
