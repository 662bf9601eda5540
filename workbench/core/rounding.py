"""Bounds on floating-point rounding error (Higham, *Accuracy and Stability of Numerical
Algorithms*, 2nd ed. 2002, section 3.1).

IEEE double precision rounds every operation to nearest: fl(a op b) = (a op b)(1 + delta) with
|delta| <= u = 2^-53.  A product of k such factors is 1 + theta_k with |theta_k| <= gamma_k =
k u / (1 - k u) (Lemma 3.1), so an inner product of length n computed in ANY order (blocked,
with fused multiply-adds) satisfies |fl(x.y) - x.y| <= gamma_n |x|.|y| (eq. 3.5), and
gamma_j + gamma_k + gamma_j gamma_k <= gamma_(j+k).  Underflow adds at most one
``SMALLEST_SUBNORMAL`` per operation.
"""
from __future__ import annotations

import numpy as np

UNIT_ROUNDOFF = float(np.finfo(np.float64).eps) / 2          # u = 2^-53
SMALLEST_SUBNORMAL = float(np.finfo(np.float64).smallest_subnormal)


def gamma(k: int) -> float:
    """gamma_k = k u / (1 - k u), the bound on |theta_k| for k roundings (Higham Lemma 3.1);
    ``inf`` when k u >= 1 (no bound).  k u is exact; the subtraction and the division round by
    at most half an ulp each, so the value is moved up two ulps to stay an upper bound."""
    ku = k * UNIT_ROUNDOFF
    if ku >= 1:
        return float("inf")
    return float(np.nextafter(np.nextafter(ku / (1 - ku), np.inf), np.inf))
