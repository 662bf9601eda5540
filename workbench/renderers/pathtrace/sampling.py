"""Sampling helpers the path tracer's surface and medium vertices share: the choice of an
emitter triangle and the multiple importance sampling weight (Veach and Guibas 1995)."""
from __future__ import annotations

import numba as nb

from ..kernels.flags import INLINE, NO_REFCOUNT


@nb.njit(**INLINE)
def mis_weight(pa, pb, beta):
    """Power heuristic ``pa^beta / (pa^beta + pb^beta)`` (``beta = 1``: balance heuristic)."""
    if beta == 2.0:
        a, b = pa * pa, pb * pb
    else:
        a, b = pa, pb
    return a / (a + b) if a > 0.0 else 0.0


@nb.njit(**NO_REFCOUNT)
def pick_emitter(cdf, u):
    """Index of the first ``cdf`` entry above ``u`` (binary search)."""
    lo, hi = 0, cdf.shape[0] - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if cdf[mid] > u:
            hi = mid
        else:
            lo = mid + 1
    return lo
