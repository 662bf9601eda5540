"""Self-intersection of a 2D polyline (a prism's outline, a lathe's linear profile): the pair
of edges that meet where they should not, by exact orientation tests (the sign of the 2D cross
product ``(q - p) x (r - p)``, O'Rourke, "Computational Geometry in C", 1998, section 1.5)."""
from __future__ import annotations

import numpy as np


def _orient(p, q, r):
    """``(q - p) x (r - p)``: > 0 when r is left of pq (arrays broadcast over the leading axes)."""
    return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])


def _on(p, q, r):
    """r in the bounding box of pq (on the segment, given the three collinear)."""
    return ((np.minimum(p[..., 0], q[..., 0]) <= r[..., 0]) & (r[..., 0] <= np.maximum(p[..., 0], q[..., 0]))
            & (np.minimum(p[..., 1], q[..., 1]) <= r[..., 1]) & (r[..., 1] <= np.maximum(p[..., 1], q[..., 1])))


def segments_meet(a, b, c, d):
    """Closed segments ab and cd share a point (elementwise over the leading axes)."""
    o1, o2, o3, o4 = _orient(a, b, c), _orient(a, b, d), _orient(c, d, a), _orient(c, d, b)
    return (((o1 * o2 < 0) & (o3 * o4 < 0)) | ((o1 == 0) & _on(a, b, c)) | ((o2 == 0) & _on(a, b, d))
            | ((o3 == 0) & _on(c, d, a)) | ((o4 == 0) & _on(c, d, b)))


def _folds_back(a, b, c):
    """Edges ab and bc (sharing b) overlap: c on the line ab, on a's side of b (elementwise)."""
    return (_orient(a, b, c) == 0) & ((c[..., 0] - b[..., 0]) * (a[..., 0] - b[..., 0])
                                      + (c[..., 1] - b[..., 1]) * (a[..., 1] - b[..., 1]) > 0)


def first_crossing(P: np.ndarray, loop: bool) -> tuple[int, int] | None:
    """``(i, j)``, ``i < j``, the first pair (in that order) of edges of the polyline ``P`` (edge
    i from P[i] to P[i+1]; ``loop``: a polygon, with the closing edge P[-1] -> P[0] as edge
    ``len(P) - 1``) that meet other than at the vertex two consecutive edges share, or two
    consecutive edges that fold back onto each other; None when the polyline is simple.  All
    pairs at once: (m, m) arrays, m <= 256 edges for the kinds that call it."""
    P = np.asarray(P, dtype=np.float64)
    n = len(P)
    m = n if loop else n - 1
    A, B = P[:m], P[(np.arange(m) + 1) % n]
    i, j = np.triu_indices(m, 1)
    bad = segments_meet(A[i], B[i], A[j], B[j])
    nxt = j == i + 1
    bad[nxt] = _folds_back(A[i[nxt]], B[i[nxt]], B[j[nxt]])
    if loop:
        wrap = (i == 0) & (j == m - 1)
        bad[wrap] = _folds_back(A[j[wrap]], A[i[wrap]], B[i[wrap]])
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    return int(i[k]), int(j[k])
