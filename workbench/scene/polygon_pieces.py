"""Convex pieces of a planar polygon: the one triangulation every method uses.

A convex polygon is its own single piece; a concave (simple) one is cut into triangles by ear
clipping (Meisters, "Polygons have ears", Amer. Math. Monthly 82, 1975: every simple polygon
with more than three vertices has two non-overlapping ears; cutting one off leaves a simple
polygon).  The ray tracers intersect each piece with the convex point-in-polygon test, the
raster methods tessellate each piece, radiosity cuts each piece into patches: all three see
the same surface.
"""
from __future__ import annotations

import numpy as np

from ..core.tol import tol


def _plane_coords(v: np.ndarray) -> np.ndarray:
    """(k, 2) coordinates of the vertices in their plane, counter-clockwise seen from the
    front (the side of the Newell normal ``sum (v_i - v_0) x (v_{i+1} - v_0)``)."""
    n = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
    n = n / np.linalg.norm(n)
    a = np.eye(3)[int(np.argmin(np.abs(n)))]
    e1 = np.cross(n, a)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    d = v - v[0]
    return np.stack([d @ e1, d @ e2], -1)


def _cross2(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """z of ``(a - o) x (b - o)``: positive when ``o, a, b`` turn counter-clockwise."""
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def is_convex(vertices: np.ndarray) -> bool:
    """True when every corner of the planar polygon (k, 3) turns the same way as its normal
    (collinear corners allowed, within ``tol.zero`` of the polygon's squared diameter)."""
    p = _plane_coords(np.asarray(vertices, dtype=np.float64))
    scale = float(np.ptp(p, axis=0).max()) ** 2
    k = len(p)
    return all(_cross2(p[i - 1], p[i], p[(i + 1) % k]) >= -tol.zero * scale for i in range(k))


def ear_triangles(vertices: np.ndarray) -> np.ndarray:
    """Ear-clipping triangulation of a simple planar polygon (k, 3), k >= 3.

    Returns (k - 2, 3) int64 vertex indices, each triangle counter-clockwise seen from the
    polygon's front.  An ear is a convex corner ``(i-1, i, i+1)`` whose triangle holds no
    other remaining vertex (Meisters 1975); when rounding leaves none (a degenerate input),
    the most convex corner is cut, so the function always returns k - 2 triangles.
    """
    p = _plane_coords(np.asarray(vertices, dtype=np.float64))
    scale = float(np.ptp(p, axis=0).max()) ** 2
    eps = tol.zero * scale
    left = list(range(len(p)))
    out = []
    while len(left) > 3:
        k = len(left)
        best, fallback, best_turn = None, 0, -np.inf
        for j in range(k):
            a, b, c = left[j - 1], left[j], left[(j + 1) % k]
            turn = _cross2(p[a], p[b], p[c])
            if turn <= eps:
                continue
            if turn > best_turn:
                best_turn, fallback = turn, j
            inside = any(_cross2(p[a], p[b], p[q]) >= -eps and _cross2(p[b], p[c], p[q]) >= -eps
                         and _cross2(p[c], p[a], p[q]) >= -eps
                         for q in left if q not in (a, b, c) and not np.array_equal(p[q], p[b]))
            if not inside:
                best = j
                break
        if best is None:
            best = fallback
        out.append((left[best - 1], left[best], left[(best + 1) % k]))
        del left[best]
    out.append(tuple(left))
    return np.array(out, dtype=np.int64)


def convex_pieces(vertices: np.ndarray) -> list[np.ndarray]:
    """The polygon (k, 3) itself when convex, else its ear-clipped triangles (each (3, 3)),
    all wound like the polygon."""
    v = np.asarray(vertices, dtype=np.float64)
    if len(v) == 3 or is_convex(v):
        return [v]
    return [v[t] for t in ear_triangles(v)]
