"""isosurface and its expression compiler: parser errors with positions, precedence, the two
evaluators and the automatic gradient agree; sphere, torus and gyroid hits against known
points; the numba twin; the cap on the bounds; scale invariance; marching cubes."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from kind_checks import SCALES, assert_alternates, mesh_volume, table, welded_edge_uses
from kernel_twins import Twins
from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import isosurface as I
from workbench.scene.kinds import isosurface_kernels
from workbench.scene.kinds.expression import MAX_STACK, compile_expression, evaluate_numpy, gradient_numpy
from workbench.scene.kinds import expression_kernels

IK = Twins(isosurface_kernels)
EK = Twins(expression_kernels)
"""The kernels callable from Python (``kernel_twins.Twins``)."""

REL = 1e-9
GYROID = "sin(x)*cos(y) + sin(y)*cos(z) + sin(z)*cos(x)"


def _iso(function, threshold, L, lo, hi):
    return I.read({"function": function, "threshold": threshold, "max_gradient": L,
                    "bounds": {"min": list(lo), "max": list(hi)}}, "o", {"material": "m"})


def _numba(s, O, D, tmin=-np.inf, tmax=np.inf, cap=16):
    head, aux = I.params(s, 0)
    par = table(head)
    ot, of = np.zeros(cap), np.zeros(cap, dtype=np.int64)
    with warnings.catch_warnings():
        # the twin passes a kernel to the root finder as a value (a dispatcher's address): numba
        # compiles it but cannot cache it, and says so at its first call in each process
        warnings.filterwarnings("ignore", message=".*Cannot cache compiled function .iso_crossings__python_twin")
        n = IK.iso_crossings(par, 0, aux, *map(float, O), *map(float, D), tmin, tmax, ot, of, cap,
                             np.zeros((MAX_STACK, 4)))
    return par, aux, ot[:n], of[:n]


# --------------------------------------------------------------------------- expression
@pytest.mark.parametrize("text, pos", [("x^2 +", 6), ("2x", 2), ("sin(x, y)", 1), ("foo(x)", 1),
                                       ("x $ y", 3), ("(x", 3), ("", 1), ("min(x)", 1),
                                       ("1.2.3", 1), ("__import__('os')", 12), ("x ** * 2", 6),
                                       ("x + 1e400", 5)])
def test_expression_errors_name_the_position(text, pos):
    with pytest.raises(WorkbenchError) as e:
        compile_expression(text)
    msg = str(e.value)
    assert f"position {pos}:" in msg and "\n" not in msg


@pytest.mark.parametrize("text, x, want", [("-x^2", 3.0, -9.0), ("2^3^2", 0.0, 512.0), ("x**-2", 2.0, 0.25),
                                          ("-2*x+1", 1.5, -2.0), ("(1+x)*(1-x)/2", 3.0, -4.0),
                                          ("max(x, 2, -1) - min(x, 2)", 5.0, 3.0), ("2*pi - e", 0.0, 2 * math.pi - math.e),
                                          ("1e-3*x + .5", 10.0, 0.51)])
def test_expression_precedence(text, x, want):
    p = compile_expression(text)
    assert evaluate_numpy(p, x, 0.0, 0.0) == pytest.approx(want, rel=1e-15)
    assert EK.evaluate(p.code, 0, p.length, x, 0.0, 0.0, np.zeros((MAX_STACK, 4))) == pytest.approx(want, rel=1e-15)


@pytest.mark.parametrize("text", ["(" * 70 + "x" + "+1)" * 70, "x+(" * 70 + "x" + ")" * 70, "-" * 4000 + "x",
                                  "(" * 4000 + "x" + ")" * 4000])
def test_expression_too_deep_is_refused(text):
    with pytest.raises(WorkbenchError, match="nested too deeply"):
        compile_expression(text[:4096])


@pytest.mark.parametrize("text", [GYROID, "(sqrt(x^2+z^2)-2)^2+y^2", "min(x,y,z)+max(abs(x),y)",
                                  "atan2(y,x)+pow(abs(z),1.5)+exp(-x*x)+log(1+y*y)",
                                  "tanh(x)+sinh(y)*cosh(z)+atan(x)", "x/(y+3) - asin(z/4)+acos(x/5)+tan(y/3)"])
def test_evaluators_and_gradients_agree(text):
    p = compile_expression(text)
    P = np.random.default_rng(3).uniform(-2, 2, (60, 3))
    a = evaluate_numpy(p, *P.T)
    v, g = gradient_numpy(p, *P.T)
    st, st4 = np.zeros((MAX_STACK, 4)), np.zeros((MAX_STACK, 4))
    b = np.array([EK.evaluate(p.code, 0, p.length, *q, st) for q in P])
    c = np.array([EK.evaluate_gradient(p.code, 0, p.length, *q, st4) for q in P])
    assert np.allclose(a, b, rtol=1e-13, atol=1e-13) and np.array_equal(a, v)
    assert np.allclose(c[:, 0], a, rtol=1e-13, atol=1e-13) and np.allclose(c[:, 1:], g, rtol=1e-12, atol=1e-12)
    h = 1e-6   # central differences: error O(h^2) + O(eps / h)
    fd = np.stack([(evaluate_numpy(p, *(P + h * e).T) - evaluate_numpy(p, *(P - h * e).T)) / (2 * h)
                   for e in np.eye(3)], -1)
    assert np.allclose(fd, g, rtol=1e-6, atol=1e-6)


# --------------------------------------------------------------------------- intersection
def test_sphere_hits_and_normals():
    s = _iso("x^2 + y^2 + z^2", 1.0, 7.0, (-2, -2, -2), (2, 2, 2))
    for x, y in ((0.0, 0.0), (0.3, 0.2), (0.6, -0.7)):
        O, D = np.array([x, y, -5.0]), np.array([0.0, 0.0, 0.5])
        h = math.sqrt(1 - x * x - y * y)
        want = [(5 - h) / 0.5, (5 + h) / 0.5]
        got = I.crossings(s, O, D)
        _, _, nt, nf = _numba(s, O, D)
        assert np.allclose([t for t, _ in got], want, rtol=REL, atol=0) and np.allclose(nt, want, rtol=REL, atol=0)
        assert [f for _, f in got] == [0, 0] and nf.tolist() == [0, 0]
        t, n = I.intersect(s, O, D)
        assert np.allclose(n, O + t * D, rtol=0, atol=REL)
        head, aux = I.params(s, 0)
        nn = np.array(IK.normal(table(head), 0, aux, 0, *(O + t * D), np.zeros((MAX_STACK, 4))))
        assert np.allclose(nn / np.linalg.norm(nn), n, rtol=0, atol=1e-12)


def test_torus_known_points():
    R, a = 2.0, 0.5
    s = _iso(f"(sqrt(x^2 + z^2) - {R})^2 + y^2", a * a, 8.0, (-3, -1, -3), (3, 1, 3))
    O, D = np.array([-5.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    want = [5 - R - a, 5 - R + a, 5 + R - a, 5 + R + a]
    assert np.allclose([t for t, _ in I.crossings(s, O, D)], want, rtol=REL, atol=0)
    assert np.allclose(_numba(s, O, D)[2], want, rtol=REL, atol=0)
    # straight down onto the tube's top at angle 30 degrees: hit y = a, normal +y
    c = np.array([R * math.cos(0.5), 3.0, R * math.sin(0.5)])
    t, n = I.intersect(s, c, np.array([0.0, -1.0, 0.0]))
    assert t == pytest.approx(3.0 - a, rel=REL) and np.allclose(n, [0, 1, 0], atol=REL)


def test_gyroid_known_points():
    """Along the x axis the gyroid is sin x: crossings at -pi, 0, pi, then the solid meets the
    bounds' face x = 4 (sin 4 < 0: inside), where the normal is the face's."""
    s = _iso(GYROID, 0.0, 2.5, (-4, -4, -4), (4, 4, 4))
    O, D = np.array([-5.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    want = [5 - math.pi, 5.0, 5 + math.pi, 9.0]
    got = I.crossings(s, O, D)
    _, _, nt, nf = _numba(s, O, D)
    assert np.allclose([t for t, _ in got], want, rtol=REL, atol=1e-15)
    assert np.allclose(nt, want, rtol=REL, atol=1e-15)
    assert [f for _, f in got] == [0, 0, 0, 2] == nf.tolist()
    assert np.allclose(I.normal(s, 0, [0.0, 0.0, 0.0]), np.ones(3) / math.sqrt(3), atol=REL)
    assert np.allclose(I.normal(s, 2, [4.0, 0.0, 0.0]), [1, 0, 0])


def test_numba_twin_agrees_and_crossings_alternate():
    s = _iso(GYROID, 0.2, 2.5, (-3, -3, -3), (3, 3, 3))
    rng = np.random.default_rng(7)
    for _ in range(25):
        O, D = rng.normal(size=3) * 6, rng.normal(size=3)
        ref = I.crossings(s, O, D)[:16]
        _, _, nt, nf = _numba(s, O, D)
        assert np.allclose(nt, [t for t, _ in ref], rtol=1e-12, atol=1e-12)
        assert nf.tolist() == [f for _, f in ref]
        assert_alternates(ref, lambda t: bool(I.inside(s, O + t * D)))


def test_first_hit_respects_tmin():
    s = _iso("x^2 + y^2 + z^2", 1.0, 7.0, (-2, -2, -2), (2, 2, 2))
    _, _, nt, _ = _numba(s, np.zeros(3), np.array([0.0, 0.0, 1.0]), 0.0, np.inf, 1)
    assert nt.tolist() == pytest.approx([1.0], rel=REL)
    _, _, nt, _ = _numba(s, np.array([0, 0, -5.0]), np.array([0.0, 0.0, 1.0]), 4.5, 5.5)
    assert len(nt) == 0


def test_scale_invariance():
    O, D = np.array([0.3, 0.2, -5.0]), np.array([0.01, 0.0, 1.0])
    base = [t for t, _ in I.crossings(_iso("x^2 + y^2 + z^2", 1.0, 7.0, (-2,) * 3, (2,) * 3), O, D)]
    for k in SCALES:
        s = _iso("x^2 + y^2 + z^2", k * k, 7.0 * k, (-2 * k,) * 3, (2 * k,) * 3)
        got = [t for t, _ in I.crossings(s, k * O, D)]
        assert np.allclose(np.array(got) / k, base, rtol=REL, atol=0)
        assert np.allclose(_numba(s, k * O, D)[2] / k, base, rtol=REL, atol=0)


def test_solid_is_closed_by_its_bounds():
    """A sphere cut by the plane x = 0.5 of its bounds: a ray along x enters through the cap."""
    s = _iso("x^2 + y^2 + z^2", 1.0, 7.0, (-0.5, -2, -2), (2, 2, 2))
    t, n = I.intersect(s, np.array([-3.0, 0.1, 0.2]), np.array([1.0, 0.0, 0.0]))
    assert t == pytest.approx(2.5, rel=REL) and np.allclose(n, [-1, 0, 0])
    P, N, F = I.mesh(s, 48)
    assert (welded_edge_uses(P, F) == 2).all()
    want = 4 / 3 * math.pi - math.pi * 0.25 * 2.5 / 3      # sphere minus the cap x < -0.5
    assert abs(mesh_volume(P, F) - want) < 0.01 * want
    cap = (P[F, 0] == -0.5).all(1)
    assert cap.sum() > 100 and (N[F[cap]] == [-1, 0, 0]).all()
    assert (N[F[~cap]][..., 0] > -1).all()


def test_torus_mesh():
    R, a = 2.0, 0.5
    s = _iso(f"(sqrt(x^2 + z^2) - {R})^2 + y^2", a * a, 8.0, (-3, -1, -3), (3, 1, 3))
    P, N, F = I.mesh(s, 48)
    assert (welded_edge_uses(P, F) == 2).all()
    want = 2 * math.pi ** 2 * R * a * a
    assert 0.97 * want < mesh_volume(P, F) < want
    rho = np.hypot(np.hypot(P[:, 0], P[:, 2]) - R, P[:, 1])
    assert np.abs(rho - a).max() < 0.1 * (6.0 / 48)


@pytest.mark.parametrize("table_, key", [
    ({"function": "x^2+", "max_gradient": 1, "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}}, "o.function"),
    ({"function": 3, "max_gradient": 1, "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}}, "o.function"),
    ({"function": "x^2+y^2+z^2", "max_gradient": 1, "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}}, "o.max_gradient"),
    ({"function": "x", "max_gradient": 0, "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}}, "o.max_gradient"),
    ({"function": "x", "max_gradient": 1}, "o.bounds"),
    ({"function": "x", "max_gradient": 1, "bounds": {"min": [1, -1, -1], "max": [1, 1, 1]}}, "o.bounds.max"),
])
def test_bad_tables_fail_in_one_line(table_, key):
    with pytest.raises(WorkbenchError) as e:
        I.read(table_, "o", {"material": "m"})
    msg = str(e.value)
    assert msg.startswith(key + ":") and "\n" not in msg


def test_no_gradient_gives_a_zero_normal_not_nan():
    """sqrt(x^2 + y^2 + z^2) has no gradient at the origin (0/0): both twins say zero."""
    s = _iso("sqrt(x^2 + y^2 + z^2)", 1.0, 1.0, (-2,) * 3, (2,) * 3)
    assert I.normal(s, 0, np.zeros(3)).tolist() == [0.0, 0.0, 0.0]
    head, aux = I.params(s, 0)
    assert IK.normal(table(head), 0, aux, 0, 0.0, 0.0, 0.0, np.zeros((MAX_STACK, 4))) == (0.0, 0.0, 0.0)
