"""Scan conversion into a p-bit integer depth buffer: the course's Z-buffer and its scanline
interpolation ("Lissage de Gouraud"), as numba kernels written to be read.

A polygon arrives in window coordinates (``x`` columns and ``y`` rows from the top-left
corner, pixel ``(i, j)`` covering ``[j, j+1) x [i, i+1)``, ``z`` the window depth in [0, 1])
with K attributes per vertex.  For each pixel row whose centre ``y = i + 1/2`` crosses it, the
two edges it meets give, by linear interpolation along the edge (course, with A the upper and D
the lower end of the left edge)::

    I1 = I_D (Y_A - Y_1) / (Y_A - Y_D) + I_A (Y_1 - Y_D) / (Y_A - Y_D)        (and I2 on the right edge)

and each pixel centre ``x = j + 1/2`` of the span between them gets::

    I_P = I2 (X_P - X_1) / (X_2 - X_1) + I1 (X_2 - X_P) / (X_2 - X_1)

for every attribute and for the depth ``z`` alike: linear in screen space (GLSL
``noperspective``), which is exact for the depth (window z is an affine function of the pixel
position on a plane) and is the course's definition for colours and normals.  The depth is then
the integer ``Z = round(z (2^p - 1))`` and the course's test is applied::

    SI Z < z(x, y) ALORS  z(x, y) <- Z ; couleur(x, y) <- ...        (buffer initialised to 2^p - 1)

Here the "colour" written is the polygon's id and the interpolated attributes (the caller
shades them: :mod:`.zbuffer`).  Which pixels a polygon covers: the centres inside it, with the
half-open rule ``Y_top <= y < Y_bottom`` and ``X_1 <= x < X_2`` (a centre exactly on a shared
edge belongs to one polygon only, as GL's rasterisation rules require; which one may differ
from the GL driver's choice).  Fragments outside ``0 <= z <= 1`` (beyond the far plane) are
dropped.  Polygons must be convex (the course: "polygones convexes dans les deux cas").
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np


class Polygons(NamedTuple):
    """Convex polygons in window coordinates.

    xyz : (M, 3) float64 vertices (x column, y row from the top, z window depth in [0, 1]).
    attrs : (M, K) float64 attributes of each vertex.
    start, count : (Q,) int64 the vertices of polygon q are ``start[q] : start[q] + count[q]``.
    ident : (Q,) int32 the id written to the id buffer for polygon q (>= 0).
    """

    xyz: np.ndarray
    attrs: np.ndarray
    start: np.ndarray
    count: np.ndarray
    ident: np.ndarray


class Frame(NamedTuple):
    """The buffers of one image.

    depth : (H, W) int64, initialised to ``zmax = 2^p - 1``.
    ident : (H, W) int32 id of the polygon seen (-1: background).
    attrs : (H, W, K) float64 interpolated attributes of the polygon seen.
    zmax : (1,) int64 the value ``2^p - 1``.
    counts : (2,) int64 fragments tested and fragments that passed the depth test (summed).
    scratch : (2, K) float64 the current span's end values I1 and I2.
    """

    depth: np.ndarray
    ident: np.ndarray
    attrs: np.ndarray
    zmax: np.ndarray
    counts: np.ndarray
    scratch: np.ndarray


def new_frame(width: int, height: int, n_attrs: int, depth_bits: int) -> Frame:
    """A cleared :class:`Frame`: every depth at the maximum ``2^p - 1`` (course: "initialisée
    au maximum possible"), every id -1."""
    zmax = (1 << depth_bits) - 1
    return Frame(np.full((height, width), zmax, dtype=np.int64), np.full((height, width), -1, dtype=np.int32),
                 np.zeros((height, width, n_attrs)), np.array([zmax], dtype=np.int64),
                 np.zeros(2, dtype=np.int64), np.zeros((2, n_attrs)))


@nb.njit(cache=True)
def scan_polygon(polys, q, frame) -> None:
    """Scan-convert polygon ``q`` of ``polys`` into ``frame`` (see the module docstring)."""
    s0, n = polys.start[q], polys.count[q]
    xyz, A = polys.xyz, polys.attrs
    K = A.shape[1]
    H, W = frame.depth.shape
    I1, I2 = frame.scratch[0], frame.scratch[1]
    y_lo, y_hi = np.inf, -np.inf
    for v in range(s0, s0 + n):
        y_lo, y_hi = min(y_lo, xyz[v, 1]), max(y_hi, xyz[v, 1])
    # rows whose centre i + 1/2 lies in [y_lo, y_hi), clamped to the image
    i_first = max(int(math.ceil(y_lo - 0.5)), 0)
    i_last = min(int(math.ceil(y_hi - 0.5)), H)
    for i in range(i_first, i_last):
        y = i + 0.5
        X1, X2, z1, z2 = np.inf, -np.inf, 0.0, 0.0
        for e in range(n):                       # the edges [a, b] the row crosses
            a, b = s0 + e, s0 + (e + 1) % n
            ya, yb = xyz[a, 1], xyz[b, 1]
            if not ((ya <= y < yb) or (yb <= y < ya)):
                continue
            t = (y - ya) / (yb - ya)             # (Y_1 - Y_A) / (Y_D - Y_A)
            x = xyz[a, 0] + t * (xyz[b, 0] - xyz[a, 0])
            z = xyz[a, 2] + t * (xyz[b, 2] - xyz[a, 2])
            if x < X1:
                X1, z1 = x, z
                for k in range(K):
                    I1[k] = A[a, k] * (1.0 - t) + A[b, k] * t
            if x > X2:
                X2, z2 = x, z
                for k in range(K):
                    I2[k] = A[a, k] * (1.0 - t) + A[b, k] * t
        if not X1 < X2:
            continue
        j_first = max(int(math.ceil(X1 - 0.5)), 0)
        j_last = min(int(math.ceil(X2 - 0.5)), W)
        for j in range(j_first, j_last):
            u = (j + 0.5 - X1) / (X2 - X1)       # (X_P - X_1) / (X_2 - X_1)
            z = z2 * u + z1 * (1.0 - u)
            if not 0.0 <= z <= 1.0:
                continue
            Z = np.int64(z * frame.zmax[0] + 0.5)
            frame.counts[0] += 1
            if Z < frame.depth[i, j]:
                frame.counts[1] += 1
                frame.depth[i, j] = Z
                frame.ident[i, j] = polys.ident[q]
                for k in range(K):
                    frame.attrs[i, j, k] = I2[k] * u + I1[k] * (1.0 - u)


@nb.njit(cache=True)
def scan_polygons(polys, frame) -> None:
    """The course's loop "POUR chaque objet ... POUR chaque pixel sur lequel il se projette":
    every polygon of ``polys``, in order, into ``frame``."""
    for q in range(len(polys.start)):
        scan_polygon(polys, q, frame)
