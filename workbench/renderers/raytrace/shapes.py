"""Ray / primitive intersections, readable version (one ray at a time, course formulas).

Used by the reference tracer (:mod:`.reference`); the numba kernels (:mod:`.kernels`) implement
the same equations and are tested against these.  Every function works in the primitive's
object space (the ray has been taken there: "objet transformé, appliquer la transformation au
rayon") and returns the crossings of the whole line ``O + t D`` as sorted ``(t, face)``; a
solid's crossings alternate entering / leaving (its interval list).
"""
from __future__ import annotations

import numpy as np

from ...core.tol import tol
from ...scene import model as m
from ...scene.polygon_pieces import convex_pieces


def is_linear(A: float, B: float, C: float) -> bool:
    """``|A C| <= tol.zero B^2``: the second root ``-B/A`` lies beyond ``1/tol.zero`` times the
    first ``-C/B`` (or ``A = B = 0``).  Homogeneous in the coefficients and in the unit of
    ``t``: a quadric at scale 1e6 is not taken for a plane."""
    return abs(A * C) <= tol.zero * (B * B)


def solve_quadratic(A: float, B: float, C: float) -> list[float]:
    """Real roots of ``A t^2 + B t + C = 0``, sorted.

    Stable form (DESIGN errata 7): ``q = -(B + sign(B) sqrt(B^2 - 4AC)) / 2``, roots ``q / A``
    and ``C / q``.  A negligible ``A`` (:func:`is_linear`) is linear: ``t = -C / B``.  A
    double root (tangent ray) is no intersection, as the course says ("le cas tangent sera
    ignoré")."""
    if is_linear(A, B, C):
        return [] if B == 0.0 else [-C / B]
    disc = B * B - 4.0 * A * C
    if not disc > 0.0:
        return []
    q = -0.5 * (B + np.copysign(np.sqrt(disc), B if B != 0.0 else 1.0))
    r = sorted([q / A, C / q if q != 0.0 else -q / A])
    return r


def sphere(center, radius, O, D) -> list[tuple[float, int]]:
    """Sphere ``|P - Sc|^2 = Sr^2`` (errata 1: B = 2 D.(O - Sc)).  The discriminant is taken as
    ``r^2 - |f - (f.d) d|^2`` (Haines et al. 2019) to avoid cancellation for small far spheres."""
    s = np.linalg.norm(D)
    d = D / s
    f = O - np.asarray(center)
    b = f @ d
    disc = radius ** 2 - np.sum((f - b * d) ** 2)
    if not disc > 0.0:
        return []
    q = -b - np.sqrt(disc) if b >= 0 else -b + np.sqrt(disc)
    nf = np.linalg.norm(f)
    c = (nf - radius) * (nf + radius)
    roots = sorted([c / q if q != 0.0 else -np.sqrt(disc), q])
    return [(t / s, 0) for t in roots]


def box(lo, hi, O, D) -> list[tuple[float, int]]:
    """Axis-aligned box by slabs (Kay & Kajiya 1986); face = 1 + 2 axis + (1 for the max side)."""
    t_near, t_far, f_near, f_far = -np.inf, np.inf, 0, 0
    for a in range(3):
        if D[a] == 0.0:
            if not lo[a] <= O[a] <= hi[a]:
                return []
            continue
        (t0, f0), (t1, f1) = sorted([((lo[a] - O[a]) / D[a], 1 + 2 * a), ((hi[a] - O[a]) / D[a], 2 + 2 * a)])
        if t0 > t_near:
            t_near, f_near = t0, f0
        if t1 < t_far:
            t_far, f_far = t1, f1
    return [(t_near, f_near), (t_far, f_far)] if t_near < t_far else []


def quadric_coefficients(Q, O, D) -> tuple[float, float, float]:
    """``A = D^T Q D``, ``B = 2 D^T Q P0``, ``C = P0^T Q P0`` with ``D`` lifted with w = 0 and
    ``P0`` with w = 1 (errata 2: every cross term of C carries its factor 2)."""
    Q = np.asarray(Q)
    P0, D4 = np.append(O, 1.0), np.append(D, 0.0)
    return float(D4 @ Q @ D4), float(2.0 * D4 @ Q @ P0), float(P0 @ Q @ P0)


def quadric_surface(q: m.Quadric, O, D) -> list[tuple[float, int]]:
    """Roots of a quadric whose point lies in the object-space bounds (an open, cut surface)."""
    A, B, C = quadric_coefficients(q.Q, O, D)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    out = []
    for t in solve_quadratic(A, B, C):
        P = O + t * D
        slack = tol.cut * (np.abs(O).max() + abs(t) * np.abs(D).max())  # rounding of O + t D
        if np.all((lo - slack <= P) & (P <= hi + slack)):
            out.append((t, 0))
    return out


def quadric_solid(q: m.Quadric, O, D) -> list[tuple[float, int]]:
    """Interval list of the solid ``P^T Q P < 0`` intersected with its bounds box (CSG leaf)."""
    slab = box(q.bounds_min, q.bounds_max, O, D)
    if not slab:
        return []
    A, B, C = quadric_coefficients(q.Q, O, D)
    roots = solve_quadratic(A, B, C)
    inf = np.inf
    if is_linear(A, B, C):
        inside = ([(-inf, roots[0])] if B > 0 else [(roots[0], inf)]) if roots else ([(-inf, inf)] if C < 0 else [])
    elif A > 0:
        inside = [(roots[0], roots[1])] if roots else []
    else:
        inside = [(-inf, roots[0]), (roots[1], inf)] if roots else [(-inf, inf)]
    (s0, fs0), (s1, fs1) = slab
    out = []
    for a, b in inside:
        (a, fa) = (s0, fs0) if s0 > a else (a, 0)
        (b, fb) = (s1, fs1) if s1 < b else (b, 0)
        if a < b:
            out += [(a, fa), (b, fb)]
    return out


def rectangle(p: m.Plane, O, D) -> list[tuple[float, int]]:
    """Finite rectangle: plane ``(P - P0).n = 0``, then ``|(P - P0).u| <= w/2``, same for v."""
    u, v, n = p.frame()
    den = D @ n
    if den == 0.0:
        return []
    t = ((np.asarray(p.point) - O) @ n) / den
    q = O + t * D - np.asarray(p.point)
    return [(t, 0)] if abs(q @ u) <= p.size[0] / 2 and abs(q @ v) <= p.size[1] / 2 else []


def polygon(vertices, O, D) -> list[tuple[float, int]]:
    """Planar polygon: the closest hit of its convex pieces (the polygon itself, or the
    triangles of a concave one, :func:`~workbench.scene.polygon_pieces.convex_pieces`)."""
    hits = [h for piece in convex_pieces(vertices) for h in _convex_polygon(piece, O, D)]
    return [min(hits)] if hits else []


def _convex_polygon(v, O, D) -> list[tuple[float, int]]:
    """Convex planar polygon (k, 3): plane hit, then the point is left of every edge (seen
    from the front, vertices counter-clockwise)."""
    n = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
    n = n / np.linalg.norm(n)
    den = D @ n
    if den == 0.0:
        return []
    t = (n @ v.mean(0) - n @ O) / den
    q = O + t * D
    for a, b in zip(v, np.roll(v, -1, axis=0)):
        if np.cross(b - a, q - a) @ n < 0.0:
            return []
    return [(t, 0)]


def triangles(tri, O, D) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All triangles at once (Moller & Trumbore 1997).  ``tri`` (T, 3, 3).  Returns ``t`` (T,)
    (inf where missed) and the barycentric weights ``b1``, ``b2`` of vertices 1 and 2."""
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p = np.cross(D, e2)
    det = np.sum(e1 * p, -1)
    ok = det != 0.0
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = O - tri[:, 0]
    b1 = np.sum(s * p, -1) * inv
    q = np.cross(s, e1)
    b2 = (q @ D) * inv
    t = np.sum(e2 * q, -1) * inv
    hit = ok & (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1)
    return np.where(hit, t, np.inf), b1, b2


def object_normal(obj: m.SceneObject, face: int, P) -> np.ndarray:
    """Outward normal (object space, not normalised) at object-space point ``P``: the gradient
    of the implicit function for spheres and quadrics (``Q P`` for ``P^T Q P``), the face
    normal for boxes, polygons and rectangles (and the cut faces of quadric solids)."""
    if face >= 1:
        nrm = np.zeros(3)
        nrm[(face - 1) // 2] = 1.0 if (face - 1) % 2 else -1.0
        return nrm
    if isinstance(obj, m.Sphere):
        return P - np.asarray(obj.center)
    if isinstance(obj, m.Quadric):
        return (np.asarray(obj.Q) @ np.append(P, 1.0))[:3]
    if isinstance(obj, m.Plane):
        return obj.frame()[2]
    if isinstance(obj, m.Polygon):
        return np.asarray(obj.normal)
    raise TypeError(obj.kind)
