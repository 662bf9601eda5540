"""Numba kernels of the ``isosurface`` kind (:mod:`.isosurface`, whose module docstring gives the method):
its entry points for the ray tracer's dispatch (signatures: :mod:`.crossing_events`).  Apart
from the kind so that reading a scene does not import numba."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .illinois import change
from .isosurface import MIN_STEP, Par
from .expression_kernels import evaluate, evaluate_gradient

JIT = dict(cache=True, error_model="numpy", **INTERNAL)
"""Every kernel here is called from compiled code only (``INTERNAL``: no numba wrappers)."""


@nb.njit(**JIT)
def _g(par, k, aux, ox, oy, oz, dx, dy, dz, t, stack):
    return evaluate(aux, int(par[k, Par.OFFSET]), int(par[k, Par.LENGTH]), ox + t * dx, oy + t * dy, oz + t * dz,
                    stack) - par[k, Par.THRESHOLD]


@nb.njit(**JIT)
def _minus_g(ray, t):
    """``-g`` at ``t`` (exactly: ``T - F`` is ``-(F - T)`` in floating point), so that the
    inside ``g < 0`` is :func:`.illinois.change`'s ``> 0``; ``ray = (par, k, aux, o, d, stack)``."""
    par, k, aux, ox, oy, oz, dx, dy, dz, stack = ray
    return -_g(par, k, aux, ox, oy, oz, dx, dy, dz, t, stack)


@nb.njit(**JIT)
def iso_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, cap, stack):
    """Crossings ``tmin < t < tmax`` of the solid's boundary (see :func:`crossings`), written to
    ``out_t``, ``out_f`` (face), at most ``cap``; returns their count.  ``stack``: (depth, 4)
    scratch of the program's evaluators."""
    t0, t1, f0, f1 = -np.inf, np.inf, 0, 0
    for a in range(3):
        o = ox if a == 0 else (oy if a == 1 else oz)
        d = dx if a == 0 else (dy if a == 1 else dz)
        lo, hi = par[k, Par.BOUNDS_MIN + a], par[k, Par.BOUNDS_MAX + a]
        if d == 0.0:
            if not lo <= o <= hi:
                return 0
            continue
        ta, tb = (lo - o) / d, (hi - o) / d
        fa, fb = 1 + 2 * a, 2 + 2 * a
        if ta > tb:
            ta, tb, fa, fb = tb, ta, fb, fa
        if ta > t0:
            t0, f0 = ta, fa
        if tb < t1:
            t1, f1 = tb, fb
    if not t0 < t1:
        return 0
    L = par[k, Par.MAX_GRADIENT] * math.sqrt(dx * dx + dy * dy + dz * dz)
    h_min = MIN_STEP * (t1 - t0)
    m = 0
    t = t0
    gt = _g(par, k, aux, ox, oy, oz, dx, dy, dz, t, stack)
    status = gt < 0.0
    if status and tmin < t0 < tmax:
        out_t[m], out_f[m] = t0, f0
        m += 1
    while t < t1 and t < tmax and m < cap:
        h = abs(gt) / L if math.isfinite(gt) else h_min
        tn = min(t + max(h, h_min), t1)
        gn = _g(par, k, aux, ox, oy, oz, dx, dy, dz, tn, stack)
        if (gn < 0.0) != status:
            b = change(_minus_g, (par, k, aux, ox, oy, oz, dx, dy, dz, stack), t, -gt, tn, -gn)
            if tmin < b < tmax:
                out_t[m], out_f[m] = b, 0
                m += 1
            status = not status
            tn, gn = b, _g(par, k, aux, ox, oy, oz, dx, dy, dz, b, stack)
        t, gt = tn, gn
    if status and m < cap and tmin < t1 < tmax:
        out_t[m], out_f[m] = t1, f1
        m += 1
    return m


@nb.njit(**JIT)
def first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax``: ``(t, face)``, ``(inf, 0)`` on a miss."""
    if iso_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, np.int64(1), stack) == 1:  # int64: see kernels.walks.LANE
        return out_t[0], out_f[0]
    return np.inf, 0


@nb.njit(**JIT)
def events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    """Interval list along the whole line (entering / leaving alternate); returns the count."""
    return iso_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, -np.inf, np.inf, out_t, out_f, cap, stack)


@nb.njit(**JIT)
def normal(par, k, aux, face, x, y, z, stack):
    """Outward normal at the object-space point (not normalised); ``stack``: (depth, 4)
    scratch of the gradient evaluator."""
    if face >= 1:
        a = (face - 1) // 2
        sgn = 1.0 if (face - 1) % 2 == 1 else -1.0
        return (sgn if a == 0 else 0.0), (sgn if a == 1 else 0.0), (sgn if a == 2 else 0.0)
    _, gx, gy, gz = evaluate_gradient(aux, int(par[k, Par.OFFSET]), int(par[k, Par.LENGTH]), x, y, z, stack)
    if not (math.isfinite(gx) and math.isfinite(gy) and math.isfinite(gz)):
        return 0.0, 0.0, 0.0      # no gradient there (sqrt(0)...): the kernels' zero normal
    return gx, gy, gz


@nb.njit(**JIT)
def inside(par, k, aux, x, y, z, stack):
    """f(x, y, z) < threshold inside the bounds."""
    lo, hi = Par.BOUNDS_MIN, Par.BOUNDS_MAX
    if not (par[k, lo] <= x <= par[k, hi] and par[k, lo + 1] <= y <= par[k, hi + 1]
            and par[k, lo + 2] <= z <= par[k, hi + 2]):
        return False
    return evaluate(aux, int(par[k, Par.OFFSET]), int(par[k, Par.LENGTH]), x, y, z, stack) < par[k, Par.THRESHOLD]
