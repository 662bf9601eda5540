"""Solvers against exact solutions: two plates (published entry), sphere interior, the
furnace (B = E / (1 - rho)) up to rho = 0.999, and honest non-convergence."""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from workbench import radiosity
from published import entry
from workbench.core.errors import WorkbenchError

SOLVERS = ["direct", "jacobi", "gauss_seidel", "progressive"]


def _two_plates():
    e = entry("RAD-plates-E10-r0.5-0.8")
    return e["inputs"], e["expected"]


@pytest.mark.parametrize("method", SOLVERS)
def test_two_plates(method):
    inp, exp = _two_plates()
    F = np.array([[0.0, 1.0], [1.0, 0.0]])
    res = radiosity.solve(F, [inp["E1"], inp["E2"]], [inp["rho1"], inp["rho2"]], method=method,
                          tol=1e-12)
    assert res.converged, res.message
    assert res.radiosity == pytest.approx([exp["B1"], exp["B2"]], rel=1e-11)


@pytest.mark.parametrize("method", SOLVERS)
def test_sphere_interior(method):
    """Inside a sphere F_ij = A_j / A for every pair (any patches): B_i = E_i + rho_i Bbar with
    Bbar = Ebar / (1 - rhobar), area means.  RGB, random areas, emission and reflectance."""
    rng = np.random.default_rng(3)
    n = 40
    A = rng.uniform(0.1, 2.0, n)
    E = rng.uniform(0, 1, (n, 3)) * (rng.random((n, 1)) < 0.2)
    E[0] = 1.0
    R = rng.uniform(0.1, 0.95, (n, 3))
    F = np.broadcast_to(A / A.sum(), (n, n)).copy()
    w = A / A.sum()
    Bbar = (w @ E) / (1 - w @ R)
    exact = E + R * Bbar
    res = radiosity.solve(F, E, R, method=method, tol=1e-8, areas=A)
    assert res.converged, res.message
    assert np.abs(res.radiosity - exact).max() <= 1e-8 * np.abs(exact).max()
    assert res.error_bound <= 1e-8


def _exact_relative_error(F, E, R, B) -> Fraction:
    """max_c ||B*_c - B_c||_inf / ||B_c||_inf in exact rational arithmetic: B* solves
    (I - diag(R) F) B* = E for the float64 inputs AS GIVEN (Gauss-Jordan on Fractions), so the
    check has no rounding of its own."""
    n = len(F)
    E2, R2, B2 = (np.asarray(a, dtype=np.float64).reshape(n, -1) for a in (E, R, B))
    worst = Fraction(0)
    for c in range(E2.shape[1]):
        M = [[Fraction(int(i == j)) - Fraction(R2[i, c]) * Fraction(F[i, j]) for j in range(n)]
             + [Fraction(E2[i, c])] for i in range(n)]
        for k in range(n):
            p = next(i for i in range(k, n) if M[i][k] != 0)
            M[k], M[p] = M[p], M[k]
            M[k] = [v / M[k][k] for v in M[k]]
            for i in range(n):
                if i != k and M[i][k] != 0:
                    M[i] = [a - M[i][k] * b for a, b in zip(M[i], M[k])]
        err = max(abs(Fraction(B2[i, c]) - M[i][n]) for i in range(n))
        worst = max(worst, err / max(abs(Fraction(b)) for b in B2[:, c]))
    return worst


@pytest.mark.parametrize("rho", [0.5, 0.9, 0.99, 0.999])
@pytest.mark.parametrize("method", SOLVERS)
def test_furnace(method, rho):
    """Closed cube, uniform E and rho: B = E / (1 - rho), and the reported bound holds for the
    TRUE error, computed exactly (rationals), with no slack: rounding of the solve and of the
    residual are inside the bound."""
    n = 6
    F = (np.ones((n, n)) - np.eye(n)) / (n - 1)
    tol = 1e-6
    res = radiosity.solve(F, np.ones(n), rho, method=method, tol=tol)
    assert res.converged, res.message
    true_err = _exact_relative_error(F, np.ones(n), np.full(n, rho), res.radiosity)
    assert true_err <= Fraction(res.error_bound) <= Fraction(tol)
    if method != "direct":
        assert res.iterations == len(res.residuals) > 1


@pytest.mark.parametrize("method", SOLVERS)
def test_bound_holds_exactly_on_random_systems(method):
    """Random open enclosures (rows of F sum to < 1), RGB, rho up to 0.999: the exact error
    never exceeds the reported bound, and the bound is not vacuous (below tol)."""
    rng = np.random.default_rng(11)
    for _ in range(3):
        n = 5
        F = rng.random((n, n))
        F *= rng.uniform(0.5, 1.0, (n, 1)) / F.sum(1, keepdims=True)
        E = rng.uniform(0, 1, (n, 3)) * (rng.random((n, 1)) < 0.5)
        E[0] = 1.0
        R = rng.uniform(0.9, 0.999, (n, 3))
        res = radiosity.solve(F, E, R, method=method, tol=1e-9)
        assert res.converged, res.message
        assert _exact_relative_error(F, E, R, res.radiosity) <= Fraction(res.error_bound) <= Fraction(1e-9)


def test_residual_alone_is_not_a_bound():
    """The former bound ||fl(r)|| / (1 - q) ignored the rounding of computing r: for one patch
    (F = 0.99, rho = 0.999) the computed residual is exactly 0 while the solution is 4e-15 off.
    The rigorous bound covers it."""
    from workbench.renderers.radiosity.solvers import rigorous_error_bound
    F, E, R = np.array([[0.99]]), np.array([[1.0]]), np.array([[0.999]])
    B = radiosity.solve(F, E, R).radiosity
    assert (B - R * (F @ B)) - E == 0.0                      # the old bound: 0
    err = _exact_relative_error(F, E, R, B)
    assert err > 0
    bound, floor = rigorous_error_bound(F, E, R, B, 0.999 * 0.99)
    assert err <= Fraction(bound) and bound == floor          # all of it is rounding


def test_bound_follows_a_perturbed_solution():
    """An a-posteriori bound holds for any B: perturb the direct solution by 1e-9 relative in
    one entry; the exact error grows to about that and stays within the bound, which stays
    within 1 / (1 - q) of it (up to rounding)."""
    from workbench.renderers.radiosity.solvers import rigorous_error_bound
    n = 6
    F = (np.ones((n, n)) - np.eye(n)) / (n - 1)
    E, R = np.ones((n, 1)), np.full((n, 1), 0.9)
    B = radiosity.solve(F, E, R).radiosity.copy()
    B[2] *= 1 + 1e-9
    err = _exact_relative_error(F, E, R, B)
    bound, _ = rigorous_error_bound(F, E, R, B, 0.9)
    assert Fraction(0.9e-9) <= err <= Fraction(bound)
    assert bound <= 1.1e-9 / (1 - 0.9)


@pytest.mark.parametrize("method", ["jacobi", "gauss_seidel", "progressive"])
def test_not_converged_is_said(method):
    n = 6
    F = (np.ones((n, n)) - np.eye(n)) / (n - 1)
    res = radiosity.solve(F, np.ones(n), 0.999, method=method, tol=1e-6, max_iterations=50)
    assert not res.converged
    assert "NOT converged" in res.message
    assert res.error_bound > 1e-6


def test_no_bound_when_rows_exceed_one():
    F = np.full((2, 2), 0.6)   # rows sum to 1.2: rho F has norm 1.188 >= 1
    res = radiosity.solve(F, [1.0, 0.0], 0.99, method="jacobi", max_iterations=200)
    assert not res.converged and "no error bound" in res.message


def test_matrix_uses_rho_of_the_row():
    """Errata 3: with rho_j the plates would give the 'wrong_if_rho_j' values."""
    F = np.array([[0.0, 1.0], [1.0, 0.0]])
    B = radiosity.solve(F, [1.0, 0.0], [0.5, 0.8]).radiosity
    assert B[1] == pytest.approx(0.8 * B[0])


def test_bad_input():
    with pytest.raises(WorkbenchError, match="reflectance"):
        radiosity.solve(np.zeros((2, 2)), [1, 0], [0.5, 1.5])
    with pytest.raises(WorkbenchError, match="square"):
        radiosity.solve(np.zeros((2, 3)), [1, 0], 0.5)
    with pytest.raises(WorkbenchError, match="solver"):
        radiosity.solve(np.zeros((2, 2)), [1, 0], 0.5, method="magic")


@pytest.mark.parametrize("relax", [1.0, 1.2, 1.6])
def test_progressive_rows_overshooting_converges(relax):
    """Matrix-free shooting from rows F[i, :] (receivers take F_ji = F_ij A_i / A_j) inside a
    sphere (exact reciprocity), plain and overshooting: the true error is within the bound
    (negative unshot radiosity included), and overshooting by 1.2 needs fewer shots."""
    from workbench.renderers.radiosity.solvers import progressive_rows
    rng = np.random.default_rng(5)
    n = 30
    A = rng.uniform(0.1, 2.0, n)
    E = rng.uniform(0, 1, (n, 3)) * (rng.random((n, 1)) < 0.3)
    E[0] = 1.0
    R = rng.uniform(0.3, 0.9, (n, 3))
    F = np.broadcast_to(A / A.sum(), (n, n)).copy()
    w = A / A.sum()
    exact = E + R * ((w @ E) / (1 - w @ R))
    runs = {r: progressive_rows(lambda idx: F[idx], A, E, R, tol=1e-8, relax=r)
            for r in {1.0, relax}}
    res = runs[relax]
    assert res.converged, res.message
    err = np.abs(res.radiosity - exact).max() / np.abs(res.radiosity).max()
    assert err <= res.error_bound * (1 + 1e-9) + 1e-15 and res.error_bound <= 1e-8
    if relax == 1.2:
        assert res.iterations < runs[1.0].iterations


def test_progressive_rows_refuses_divergent_relaxation():
    from workbench.renderers.radiosity.solvers import progressive_rows
    with pytest.raises(WorkbenchError, match="relax"):
        progressive_rows(lambda idx: np.zeros((len(idx), 2)), np.ones(2), [1.0, 0.0], 0.5, relax=2.0)


def test_row_cache_drops_the_least_recently_used():
    from workbench.renderers.radiosity.solvers import RowCache
    calls = []

    def rows(idx):
        calls.extend(idx.tolist())
        return np.ones((len(idx), 1024)) * idx[:, None]

    cache = RowCache(rows, budget_mb=2 * 1024 * 4 / 2 ** 20)     # room for two float32 rows
    for i in (0, 1, 0, 2, 0, 1):
        assert cache([i])[0, 0] == i
    assert calls == [0, 1, 2, 1]          # 0, used last, stayed; 1 was dropped for 2
    assert cache.hits == 2 and cache.computed == 4
