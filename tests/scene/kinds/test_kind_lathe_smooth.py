"""lathe with a smooth profile (spline = quadratic | cubic | bezier, POV-Ray's curves): a spline
that is a straight line is the linear lathe's cylinder or cone; a quadratic profile r = a s,
y = b s^2 is the paraboloid y = b (x^2 + z^2) / a^2 (closed-form ray hits); the numba twin
agrees with the readable one; scale invariance; the tessellation's volume converges to the
exact one; bad profiles fail in one line."""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from kind_checks import SCALES, assert_alternates, mesh_volume, scratch, table, welded_edge_uses
from kernel_twins import Twins
from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import lathe as L
from workbench.scene.kinds import lathe_kernels
from workbench.scene.kinds import lathe_spline as S

LK = Twins(lathe_kernels)
"""The kind's kernels callable from Python (``kernel_twins.Twins``)."""

REL = 1e-9
CUP = [[0.0, 2.2], [0.0, 0.0], [0.8, 0.05], [1.0, 1.0], [1.3, 2.0], [1.1, 2.1], [0.7, 1.2], [0.0, 1.0], [0.0, -1.0]]
"""A closed cubic profile (from (0, 0) to (0, 1), both on the axis): a goblet's bowl."""
EGG = [[0.0, 0.0], [0.6, 0.0], [0.9, 0.5], [0.9, 1.0], [0.9, 1.0], [0.9, 1.5], [0.5, 2.0], [0.0, 2.0]]
"""A closed bezier profile of two segments."""


def _lathe(points, spline):
    return L.read({"points": points, "spline": spline}, "o", {"material": "m"})


def _first(la, O, D):
    head, aux = L.params(la, 0)
    par = table(head)
    t, f = LK.first(par, 0, aux, *map(float, O), *map(float, D), 0.0, np.inf, *scratch())
    n = np.array(LK.normal(par, 0, aux, f, *(O + t * D), scratch()[2])) if t < np.inf else None
    return t, n


RAYS = [((-5.0, 0.3, 0.2), (1.0, 0.0, 0.0)), ((-5.0, 0.3, 0.2), (2.0, 0.1, 0.0)),
        ((0.1, -0.4, 4.0), (0.0, 0.05, -0.5)), ((-5.0, 0.3, 0.2), (1.0, 1e-9, 0.01)),
        ((-3.0, 0.9, 0.4), (1.0, -0.3, 0.0))]


@pytest.mark.parametrize("O, D", RAYS)
def test_straight_cubic_is_the_cylinder(O, D):
    """Catmull-Rom through equally spaced points on r = 1.5 is the segment (1.5, -1) -> (1.5, 1)."""
    r = 1.5
    la = _lathe([[r, -3], [r, -1], [r, 1], [r, 3]], "cubic")
    O, D = np.array(O), np.array(D)
    a, b, c = D[0] ** 2 + D[2] ** 2, 2 * (O[0] * D[0] + O[2] * D[2]), O[0] ** 2 + O[2] ** 2 - r * r
    q = -0.5 * (b + math.copysign(math.sqrt(b * b - 4 * a * c), b))
    t = min(q / a, c / q)
    P = O + t * D
    assert abs(P[1]) < 1
    want_n = np.array([P[0], 0.0, P[2]]) / r
    got_t, got_n = L.intersect(la, O, D)
    nt, nn = _first(la, O, D)
    assert got_t == pytest.approx(t, rel=REL) and nt == pytest.approx(t, rel=REL)
    assert np.allclose(got_n, want_n, atol=REL) and np.allclose(nn, want_n, atol=REL)


def test_straight_quadratic_is_the_linear_cone():
    """Quadratic through equally spaced collinear points (the first off the axis on the other
    side: a control point) = the linear lathe (0, 2) -> (1, 0): same hits and normals."""
    smooth, lin = _lathe([[-1, 4], [0, 2], [1, 0]], "quadratic"), L.read({"points": [[0, 2], [1, 0]]}, "o", {"material": "m"})
    rng = np.random.default_rng(3)
    n = 0
    for _ in range(200):
        O = rng.normal(size=3) * 3
        D = rng.normal(size=3) * 0.3 + [0, 1, 0] - O
        want = L.crossings(lin, O, D)
        got = L.crossings(smooth, O, D)
        assert np.allclose([t for t, _ in got], [t for t, _ in want], rtol=REL, atol=0)
        for t, f in got:
            assert np.allclose(L.normal(smooth, f, O + t * D), L.normal(lin, 0, O + t * D), atol=REL)
        n += len(got)
    assert n > 100


def _paraboloid_t(k, O, D, ymax):
    """Nearest t > 0 with O_y + t D_y = k |O_xz + t D_xz|^2 and y <= ymax (closed form)."""
    A = k * (D[0] ** 2 + D[2] ** 2)
    B = 2 * k * (O[0] * D[0] + O[2] * D[2]) - D[1]
    C = k * (O[0] ** 2 + O[2] ** 2) - O[1]
    if A == 0.0:
        ts = [-C / B]
    else:
        q = -0.5 * (B + math.copysign(math.sqrt(B * B - 4 * A * C), B))
        ts = [q / A, C / q]
    return min(t for t in ts if t > 0 and O[1] + t * D[1] <= ymax)


@pytest.mark.parametrize("spline", ["quadratic", "bezier"])
@pytest.mark.parametrize("O, D", [((0.3, 2.0, 0.1), (0.1, -1.0, 0.05)), ((-4.0, 1.0, 0.3), (1.0, 0.0, 0.0)),
                                  ((-4.0, 0.2, 0.3), (1.0, 0.3, -0.1)), ((0.2, 5.0, -0.1), (0.0, -1.0, 0.0)),
                                  ((-4.0, 0.5, 0.0), (1.0, 1e-8, 0.0))])
def test_paraboloid(spline, O, D):
    """r = a s, y = b s^2: quadratic spline of (-a, b), (0, 0), (a, b); cubic bezier of
    (0, 0), (a/3, 0), (2a/3, b/3), (a, b).  The outward normal (open profile going up and out:
    to the right of the curve) is (2 k x, -1, 2 k z) normalised, k = b / a^2."""
    a, b = 1.3, 2.0
    pts = [[-a, b], [0, 0], [a, b]] if spline == "quadratic" else [[0, 0], [a / 3, 0], [2 * a / 3, b / 3], [a, b]]
    la = _lathe(pts, spline)
    O, D = np.array(O), np.array(D)
    k = b / a ** 2
    t = _paraboloid_t(k, O, D, b)
    P = O + t * D
    want_n = np.array([2 * k * P[0], -1.0, 2 * k * P[2]])
    want_n /= np.linalg.norm(want_n)
    got_t, got_n = L.intersect(la, O, D)
    nt, nn = _first(la, O, D)
    assert got_t == pytest.approx(t, rel=REL) and nt == pytest.approx(t, rel=REL)
    assert np.allclose(got_n, want_n, atol=REL) and np.allclose(nn, want_n, atol=REL)


@pytest.mark.parametrize("points, spline", [(CUP, "cubic"), (EGG, "bezier")])
def test_numba_twin_and_solid(points, spline):
    la = _lathe(points, spline)
    assert la.closed
    head, aux = L.params(la, 0)
    par = table(head)
    rng = np.random.default_rng(12)
    ot, of = np.zeros(64), np.zeros(64, dtype=np.int64)
    hits = 0
    for i in range(120):
        O = rng.normal(size=3) * 3
        D = rng.normal(size=3) * 0.5 + [0, 1, 0] - O
        if i % 10 == 0:
            D[1] = 0.0 if i % 20 == 0 else 1e-6 * D[0]     # horizontal and nearly horizontal
        ref = L.crossings(la, O, D)
        n = LK.events(par, 0, aux, *O, *D, ot, of, 64, scratch()[2])
        assert np.allclose(ot[:n], [t for t, _ in ref], rtol=1e-12, atol=0) and of[:n].tolist() == [f for _, f in ref]
        assert_alternates(ref, lambda t: bool(L.inside(la, O + t * D)))
        for t, f in ref:
            nr = L.normal(la, f, O + t * D)
            nn = LK.normal(par, 0, aux, f, *(O + t * D), scratch()[2])
            assert np.allclose(nn, nr, atol=1e-9)
        for t, f in ref[::2]:       # entering: the outward normal faces the ray
            assert L.normal(la, f, O + t * D) @ D < 0
        p = rng.normal(size=3)
        assert LK.inside(par, 0, aux, *p, scratch()[2]) == L.inside(la, p)
        hits += bool(ref)
    assert hits > 60


def test_scale_invariance():
    O, D = np.array([-4.0, 0.7, 0.3]), np.array([1.0, 0.02, 0.01])
    base = [t for t, _ in L.crossings(_lathe(CUP, "cubic"), O, D)]
    assert len(base) >= 2
    for k in SCALES:
        la = _lathe((np.array(CUP) * k).tolist(), "cubic")
        got = [t for t, _ in L.crossings(la, k * O, D)]
        assert np.allclose(np.array(got) / k, base, rtol=REL, atol=0)
        assert _first(la, k * O, D)[0] / k == pytest.approx(base[0], rel=REL)


def _exact_volume(la) -> float:
    """pi * |sum over segments of the integral of r(s)^2 y'(s) ds| (the closing edge is on the axis)."""
    total = 0.0
    for seg in la.segments:
        f = np.polynomial.Polynomial(seg[0]) ** 2 * np.polynomial.Polynomial(seg[1]).deriv()
        F = f.integ()
        total += F(1.0) - F(0.0)
    return math.pi * abs(total)


def test_tessellation_converges_to_the_volume():
    la = _lathe(CUP, "cubic")
    exact = _exact_volume(la)
    errs = []
    for level in (1, 4, 16):
        P, N, F = L.level_mesh(la, level)
        assert (welded_edge_uses(P, F) == 2).all()
        errs.append(abs(abs(mesh_volume(P, F)) / exact - 1.0))
    # second order in the steps: 16 times the steps, at least 100 times less error
    assert errs[0] > errs[1] > errs[2] and errs[2] < errs[0] / 100, errs


@pytest.mark.parametrize("points, spline, key", [
    ([[1, 0], [1, 1], [1, 2]], "cubic", "o.points"),                      # too few for a cubic
    ([[1, 0], [1, 1]], "quadratic", "o.points"),
    ([[1, 0], [1, 1], [1, 2], [1, 3], [1, 4]], "bezier", "o.points"),     # not a multiple of 4
    ([[1, 0], [1, 1], [1, 2], [1, 3], [2, 3], [2, 4], [2, 5], [2, 6]], "bezier", "o.points[4]"),
    ([[3, 0], [0.1, 1], [1, 2]], "quadratic", "o.points"),                  # its curve dips below r = 0
    ([[0, 0], [0, 1], [0, 2], [0, 3]], "cubic", "o.points"),              # on the axis
    ([[1, 0], [1, 0], [1, 0], [1, 0]], "bezier", "o.points"),             # a single point
    ([[1, 0], [1, 1]], "nurbs", "o.spline"),
])
def test_bad_profiles_fail_in_one_line(points, spline, key):
    with pytest.raises(WorkbenchError) as e:
        _lathe(points, spline)
    msg = str(e.value)
    assert msg.startswith(key + ":") and "\n" not in msg, msg


def test_bad_profile_in_a_scene_file_exits_2(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('[camera]\nposition = [0, 0, -5]\nlook_at = [0, 0, 0]\n[materials.m]\ncolor = [1, 1, 1]\n'
                 '[[objects]]\ntype = "lathe"\nspline = "cubic"\npoints = [[1, 0], [1, 1], [1, 2]]\nmaterial = "m"\n')
    r = subprocess.run([sys.executable, "-m", "workbench.app.cli", "info", str(p)], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 2 and "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert "points" in r.stderr and "4 to" in r.stderr, r.stderr


def test_polynomial_roots_are_isolated():
    """The readable root finder: (s - 0.1)(s - 0.5)(s - 0.50001)(s + 2)(s - 0.9)(s - 3) on
    [0, 1] gives 0.1, 0.5, 0.50001, 0.9 to the accuracy of evaluating the polynomial divided by
    its slope (1e-16 / 1e-5 for the close pair); both ends' roots to adjacent floats."""
    c = np.polynomial.polynomial.polyfromroots([0.1, 0.5, 0.50001, -2.0, 0.9, 3.0])
    got = S.roots_in(list(c), 0.0, 1.0)
    assert np.allclose(got, [0.1, 0.5, 0.50001, 0.9], rtol=0, atol=1e-9)
    assert np.allclose(got[::3], [0.1, 0.9], rtol=0, atol=1e-15)
