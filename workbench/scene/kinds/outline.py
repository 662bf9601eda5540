"""Self-intersection of a 2D polyline (a prism's outline, a lathe's linear profile): the pair
of edges that meet where they should not, by exact orientation tests (the sign of the 2D cross
product ``(q - p) x (r - p)``, O'Rourke, "Computational Geometry in C", 1998, section 1.5)."""
from __future__ import annotations

import numpy as np


def _orient(p, q, r) -> float:
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])


def _on(p, q, r) -> bool:
    """r in the bounding box of pq (on the segment, given the three collinear)."""
    return min(p[0], q[0]) <= r[0] <= max(p[0], q[0]) and min(p[1], q[1]) <= r[1] <= max(p[1], q[1])


def segments_meet(a, b, c, d) -> bool:
    """Closed segments ab and cd share a point."""
    o1, o2, o3, o4 = _orient(a, b, c), _orient(a, b, d), _orient(c, d, a), _orient(c, d, b)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return True
    return ((o1 == 0 and _on(a, b, c)) or (o2 == 0 and _on(a, b, d)) or (o3 == 0 and _on(c, d, a))
            or (o4 == 0 and _on(c, d, b)))


def _folds_back(a, b, c) -> bool:
    """Edges ab and bc (sharing b) overlap: c on the line ab, on a's side of b."""
    return _orient(a, b, c) == 0 and (c[0] - b[0]) * (a[0] - b[0]) + (c[1] - b[1]) * (a[1] - b[1]) > 0


def first_crossing(P: np.ndarray, loop: bool) -> tuple[int, int] | None:
    """``(i, j)``, ``i < j``, the first pair of edges of the polyline ``P`` (edge i from P[i] to
    P[i+1]; ``loop``: a polygon, with the closing edge P[-1] -> P[0] as edge ``len(P) - 1``)
    that meet other than at the vertex two consecutive edges share, or two consecutive edges
    that fold back onto each other; None when the polyline is simple.  O(n^2) pairs."""
    n = len(P)
    m = n if loop else n - 1
    ends = [(P[i], P[(i + 1) % n]) for i in range(m)]
    for i in range(m):
        for j in range(i + 1, m):
            adjacent = j == i + 1 or (loop and i == 0 and j == m - 1)
            if adjacent:
                (a, b), (_, c) = (ends[i], ends[j]) if j == i + 1 else (ends[j], ends[i])
                if _folds_back(a, b, c):
                    return i, j
            elif segments_meet(*ends[i], *ends[j]):
                return i, j
    return None
