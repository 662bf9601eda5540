"""Closed-form values the stress cases check against (independent of every renderer).

Form factors between rectangles (Howell, "A Catalog of Radiation Heat Transfer Configuration
Factors", C-11 and C-14; Siegel & Howell, "Thermal Radiation Heat Transfer"), a Gauss-Legendre
quadrature of the form-factor double integral for separated parallelograms, and the exact
form factors of a cube's faces.
"""
from __future__ import annotations

import numpy as np


def ff_parallel_rectangles(a: float, b: float, c: float) -> float:
    """Form factor between two identical, directly opposed parallel ``a x b`` rectangles at
    distance ``c`` (Howell C-11), with ``X = a/c``, ``Y = b/c``::

        F = 2/(pi X Y) { ln sqrt[(1+X^2)(1+Y^2)/(1+X^2+Y^2)] + X sqrt(1+Y^2) atan(X/sqrt(1+Y^2))
                         + Y sqrt(1+X^2) atan(Y/sqrt(1+X^2)) - X atan X - Y atan Y }
    """
    X, Y = a / c, b / c
    x1, y1 = np.sqrt(1 + X * X), np.sqrt(1 + Y * Y)
    s = (0.5 * np.log((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y)) + X * y1 * np.arctan(X / y1)
         + Y * x1 * np.arctan(Y / x1) - X * np.arctan(X) - Y * np.arctan(Y))
    return float(2.0 / (np.pi * X * Y) * s)


def ff_perpendicular_rectangles(l: float, w: float, h: float) -> float:
    """Form factor from a ``l x w`` rectangle to a ``l x h`` rectangle sharing its edge of
    length ``l`` at a right angle (Howell C-14), ``W = w/l``, ``H = h/l``::

        F = 1/(pi W) { W atan(1/W) + H atan(1/H) - sqrt(H^2+W^2) atan(1/sqrt(H^2+W^2))
            + 1/4 ln( (1+W^2)(1+H^2)/(1+W^2+H^2)
                      * [W^2 (1+W^2+H^2) / ((1+W^2)(W^2+H^2))]^(W^2)
                      * [H^2 (1+W^2+H^2) / ((1+H^2)(W^2+H^2))]^(H^2) ) }
    """
    W, H = w / l, h / l
    r = np.sqrt(H * H + W * W)
    s = 1 + W * W + H * H
    log = (np.log((1 + W * W) * (1 + H * H) / s)
           + W * W * np.log(W * W * s / ((1 + W * W) * (W * W + H * H)))
           + H * H * np.log(H * H * s / ((1 + H * H) * (W * W + H * H))))
    return float((W * np.arctan(1 / W) + H * np.arctan(1 / H) - r * np.arctan(1 / r) + 0.25 * log) / (np.pi * W))


def _parallelogram_points(P: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss-Legendre points (n^2, 3), weights (n^2,) summing to the area, and unit normal."""
    x, w = np.polynomial.legendre.leggauss(order)
    s, ws = 0.5 * (x + 1), 0.5 * w
    e1, e2 = P[1] - P[0], P[3] - P[0]
    if not np.allclose(P[0] + e1 + e2, P[2], rtol=1e-9, atol=1e-12 * np.abs(P).max()):
        raise ValueError("quadrature form factors need parallelograms (4 vertices, p0 + e1 + e2 = p2)")
    cr = np.cross(e1, e2)
    area = np.linalg.norm(cr)
    pts = P[0] + s[:, None, None] * e1 + s[None, :, None] * e2
    return pts.reshape(-1, 3), (ws[:, None] * ws[None, :]).ravel() * area, cr / area


def ff_quadrature(P_i, P_j, order: int = 16) -> float:
    """``F_ij = 1/A_i sum sum cos_i cos_j / (pi r^2) dA_j dA_i`` by tensor Gauss-Legendre over
    two parallelograms (vertices (4, 3), counter-clockwise seen from their front), unoccluded.
    Accurate for patches separated by more than about their size (smooth kernel); not for
    patches in contact (use the closed forms)."""
    pi_, wi, ni = _parallelogram_points(np.asarray(P_i, dtype=np.float64), order)
    pj, wj, nj = _parallelogram_points(np.asarray(P_j, dtype=np.float64), order)
    d = pj[None, :, :] - pi_[:, None, :]
    r2 = np.sum(d * d, -1)
    ci = np.maximum(d @ ni, 0.0) / np.sqrt(r2)
    cj = np.maximum(-(d @ nj), 0.0) / np.sqrt(r2)
    k = ci * cj / (np.pi * r2)
    return float(wi @ k @ wj / wi.sum())


def cube_form_factors() -> np.ndarray:
    """Exact (6, 6) form factors between the inner faces of a cube, faces ordered
    (-x, +x, -y, +y, -z, +z): opposite faces C-11 with a = b = c, adjacent ones C-14 with
    l = w = h; rows sum to 1 (closed enclosure) to rounding."""
    opp, adj = ff_parallel_rectangles(1.0, 1.0, 1.0), ff_perpendicular_rectangles(1.0, 1.0, 1.0)
    F = np.full((6, 6), adj)
    for i in range(6):
        F[i, i] = 0.0
        F[i, i ^ 1] = opp
    return F


def cube_faces(size: float = 1.0, n: int = 1) -> list[np.ndarray]:
    """The inner faces of the cube ``[0, size]^3``, each split into ``n x n`` square patches,
    counter-clockwise seen from inside (normals point into the cube); faces ordered as in
    :func:`cube_form_factors`, patches row-major within a face."""
    out = []
    g = np.linspace(0.0, size, n + 1)
    for axis in range(3):
        for side, inward in ((0.0, 1.0), (size, -1.0)):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            for a in range(n):
                for b in range(n):
                    quad = []
                    for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = np.zeros(3)
                        p[axis], p[u], p[v] = side, g[a + du], g[b + dv]
                        quad.append(p)
                    quad = np.array(quad)
                    normal = np.cross(quad[1] - quad[0], quad[2] - quad[0])
                    out.append(quad if normal[axis] * inward > 0 else quad[::-1].copy())
    return out
