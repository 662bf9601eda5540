"""Radiosity (Goral et al. 1984; Cohen & Greenberg 1985; Cohen et al. 1988).

Public API for scripts (``workbench.radiosity`` is a lazy alias of this package)::

    from workbench import radiosity
    ff = radiosity.form_factors(polygons, method="hemicube", resolution=128)
    ff[i, j], ff.row_sums, ff.reciprocity_error          # index it like the (P, P) matrix
    res = radiosity.solve(ff, emission, reflectance, method="gauss_seidel", tol=1e-6)
    res.radiosity, res.iterations, res.residuals, res.converged, res.message

Modules: :mod:`.patches` (scene -> patches), :mod:`.formfactors` (analytic, dispatcher),
:mod:`.hemicube` (GL item buffer), :mod:`.raycast` (numba), :mod:`.solvers`, :mod:`.display`
(Gouraud through GL), :mod:`.method` and :mod:`.hybrid` (the registered renderers).
"""
from __future__ import annotations

from .formfactors import FormFactors
from .geometry import geometry_from_polygons
from .formfactors import compute as _compute
from .solvers import SolveResult, solve  # noqa: F401

__all__ = ["form_factors", "solve", "FormFactors", "SolveResult"]


def form_factors(polygons, method: str = "hemicube", resolution: int = 128, *,
                 rotate: bool = False, rays: int = 4096, order: int = 8,
                 seed: int = 0, normalize: bool = True) -> FormFactors:
    """Form-factor matrix of planar convex polygons.

    Parameters
    ----------
    polygons : list of (k, 3) arrays, counter-clockwise seen from the front (the side that
        emits and receives), one patch each.
    method : ``hemicube`` (GL item buffer from each centre, with occlusion), ``raycast``
        (Malley's rays, with occlusion) or ``analytic`` (exact, unoccluded, Gauss-Legendre
        over the emitter).
    resolution : hemicube pixels across the top face.
    rotate, rays, order, seed, normalize : see
        :func:`workbench.renderers.radiosity.formfactors.compute` (``normalize``: hemicube
        delta form factors scaled to sum to exactly 1; their raw sum is 1 + O(1/res^2)).

    Returns
    -------
    FormFactors : ``F`` (P, P) (``ff[i, j]`` indexes it), ``row_sums``, ``reciprocity_error``.
    """
    return _compute(geometry_from_polygons(polygons), method, resolution, rotate=rotate,
                    rays=rays, order=order, seed=seed, normalize=normalize)
