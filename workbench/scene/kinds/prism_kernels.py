"""Numba kernels of the ``prism`` kind (:mod:`.prism`, whose module docstring gives the method):
its entry points for the ray tracer's dispatch (signatures: :mod:`.crossing_events`).  Apart
from the kind so that reading a scene does not import numba."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .prism import TOL_CUT, Par
from .lathe_kernels import sort_hits

JIT = dict(cache=True, error_model="numpy", **INTERNAL)
"""Every kernel here is called from compiled code only (``INTERNAL``: no numba wrappers)."""


@nb.njit(**JIT)
def _in_polygon_nb(aux, off, n, x, z):
    res = False
    for i in range(n):
        j, jn = off + 2 * i, off + 2 * ((i + 1) % n)
        xa, za, xb, zb = aux[j], aux[j + 1], aux[jn], aux[jn + 1]
        if za != zb and ((za > z) != (zb > z)) and x < xa + (z - za) * (xb - xa) / (zb - za):
            res = not res
    return res


@nb.njit(**JIT)
def inside(par, k, aux, x, y, z, stack):
    return (par[k, Par.Y0] < y < par[k, Par.Y1]
            and _in_polygon_nb(aux, int(par[k, Par.OFFSET]), int(par[k, Par.VERTICES]), x, z))


@nb.njit(**JIT)
def _wall(aux, off, n, i, y0, y1, ox, oy, oz, dx, dy, dz):
    """t of the hit of wall ``i`` (inf when missed)."""
    j, jn = off + 2 * i, off + 2 * ((i + 1) % n)
    ex, ez = aux[jn] - aux[j], aux[jn + 1] - aux[j + 1]
    den = dx * ez - dz * ex
    if den == 0.0:
        return np.inf
    wx, wz = aux[j] - ox, aux[j + 1] - oz
    t = (wx * ez - wz * ex) / den
    s = (wx * dz - wz * dx) / den
    slack = TOL_CUT * (max(abs(ox), abs(oy), abs(oz)) + abs(t) * max(abs(dx), abs(dy), abs(dz)))
    if 0.0 <= s <= 1.0 and y0 - slack <= oy + t * dy <= y1 + slack:
        return t
    return np.inf


@nb.njit(**JIT)
def prism_hits(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, tmin, tmax):
    """Every wall and cap hit ``tmin < t < tmax`` (unsorted), at most ``cap``; returns the count."""
    off, n, y0, y1 = int(par[k, Par.OFFSET]), int(par[k, Par.VERTICES]), par[k, Par.Y0], par[k, Par.Y1]
    m = 0
    if dy != 0.0:
        for face in range(2):
            t = ((y1 if face == 1 else y0) - oy) / dy
            if tmin < t < tmax and m < cap and _in_polygon_nb(aux, off, n, ox + t * dx, oz + t * dz):
                out_t[m], out_f[m] = t, face
                m += 1
    for i in range(n):
        t = _wall(aux, off, n, i, y0, y1, ox, oy, oz, dx, dy, dz)
        if tmin < t < tmax and m < cap:
            out_t[m], out_f[m] = t, 2 + i
            m += 1
    return m


@nb.njit(**JIT)
def first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax``: ``(t, face)``, ``(inf, 0)`` on a miss."""
    off, n, y0, y1 = int(par[k, Par.OFFSET]), int(par[k, Par.VERTICES]), par[k, Par.Y0], par[k, Par.Y1]
    best, bf = tmax, -1
    if dy != 0.0:
        for face in range(2):
            t = ((y1 if face == 1 else y0) - oy) / dy
            if tmin < t < best and _in_polygon_nb(aux, off, n, ox + t * dx, oz + t * dz):
                best, bf = t, face
    for i in range(n):
        t = _wall(aux, off, n, i, y0, y1, ox, oy, oz, dx, dy, dz)
        if tmin < t < best:
            best, bf = t, 2 + i
    if bf < 0:
        return np.inf, 0
    return best, bf


@nb.njit(**JIT)
def events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    """Interval list along the whole line (entering / leaving alternate); returns the count."""
    m = prism_hits(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, -np.inf, np.inf)
    sort_hits(out_t, out_f, m)
    w, status = 0, False
    for i in range(m):
        t = out_t[i]
        nxt = out_t[i + 1] if i + 1 < m else np.inf
        if nxt == t:
            continue
        tm = 0.5 * (t + nxt)
        after = nxt < np.inf and inside(par, k, aux, ox + tm * dx, oy + tm * dy, oz + tm * dz, stack)
        if after != status:
            out_t[w], out_f[w] = t, out_f[i]
            w += 1
            status = after
    return w


@nb.njit(**JIT)
def normal(par, k, aux, face, x, y, z, stack):
    """Unit outward normal of ``face``."""
    if face < 2:
        return 0.0, (1.0 if face == 1 else -1.0), 0.0
    off, n = int(par[k, Par.OFFSET]), int(par[k, Par.VERTICES])
    i = face - 2
    j, jn = off + 2 * i, off + 2 * ((i + 1) % n)
    ex, ez = aux[jn] - aux[j], aux[jn + 1] - aux[j + 1]
    ln = math.hypot(ex, ez)
    o = par[k, Par.ORIENTATION]
    return o * ez / ln, 0.0, -o * ex / ln
