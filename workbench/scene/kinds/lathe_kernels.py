"""Numba kernels of the ``lathe`` kind (:mod:`.lathe`, whose module docstring gives the method):
its entry points for the ray tracer's dispatch (signatures: :mod:`.crossing_events`).  Apart
from the kind so that reading a scene does not import numba."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from .lathe import TOL_CUT, TOL_ZERO


@nb.njit(cache=True, error_model="numpy")
def sort_hits(out_t, out_f, m):
    """Insertion sort of the first ``m`` hits by t (few hits: no allocation)."""
    for i in range(1, m):
        t, f = out_t[i], out_f[i]
        j = i - 1
        while j >= 0 and out_t[j] > t:
            out_t[j + 1], out_f[j + 1] = out_t[j], out_f[j]
            j -= 1
        out_t[j + 1], out_f[j + 1] = t, f


@nb.njit(cache=True, error_model="numpy")
def _segment_roots(aux, j, ox, oy, oz, dx, dy, dz, zero):
    """Up to two hits ``(n, t0, t1)`` of the surface of the segment at aux[j:j+4]."""
    r0, y0, r1, y1 = aux[j], aux[j + 1], aux[j + 2], aux[j + 3]
    if y0 == y1:
        if dy == 0.0:
            return 0, 0.0, 0.0
        t = (y0 - oy) / dy
        rho = math.hypot(ox + t * dx, oz + t * dz)
        if min(r0, r1) <= rho <= max(r0, r1):
            return 1, t, 0.0
        return 0, 0.0, 0.0
    k = (r1 - r0) / (y1 - y0)
    A, B = r0 + (oy - y0) * k, dy * k
    a = dx * dx + dz * dz - B * B
    b = 2.0 * (ox * dx + oz * dz - A * B)
    c = ox * ox + oz * oz - A * A
    n = 0
    ra, rb = 0.0, 0.0
    if abs(a * c) <= zero * b * b:
        if b == 0.0:
            return 0, 0.0, 0.0
        ra, n = -c / b, 1
    else:
        disc = b * b - 4.0 * a * c
        if not disc > 0.0:
            return 0, 0.0, 0.0
        q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
        ra, rb, n = q / a, (c / q if q != 0.0 else -q / a), 2
    m, t0, t1 = 0, 0.0, 0.0
    for i in range(n):
        t = ra if i == 0 else rb
        slack = TOL_CUT * (max(abs(ox), abs(oy), abs(oz)) + abs(t) * max(abs(dx), abs(dy), abs(dz)))
        y = oy + t * dy
        if min(y0, y1) - slack <= y <= max(y0, y1) + slack and A + B * t >= -slack * abs(k):
            if m == 0:
                t0 = t
            else:
                t1 = t
            m += 1
    return m, t0, t1


@nb.njit(cache=True, error_model="numpy")
def lathe_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax``: ``(t, segment)``, ``(inf, 0)`` on a miss."""
    off, n = int(par[k, 0]), int(par[k, 1])
    best, bf = tmax, -1
    for i in range(n - 1):
        cnt, t0, t1 = _segment_roots(aux, off + 2 * i, ox, oy, oz, dx, dy, dz, TOL_ZERO)
        for r in range(cnt):
            t = t0 if r == 0 else t1
            if tmin < t < best:
                best, bf = t, i
    if bf < 0:
        return np.inf, 0
    return best, bf


@nb.njit(cache=True, error_model="numpy")
def lathe_inside(par, k, aux, x, y, z, stack):
    """Even-odd test of ``(rho, y)`` against the closed profile."""
    if par[k, 2] == 0.0:
        return False
    off, n = int(par[k, 0]), int(par[k, 1])
    rho = math.hypot(x, z)
    res = False
    for i in range(n):
        j = off + 2 * i
        jn = off + 2 * ((i + 1) % n)
        ra, ya, rb, yb = aux[j], aux[j + 1], aux[jn], aux[jn + 1]
        if ya != yb and ((ya > y) != (yb > y)) and rho < ra + (y - ya) * (rb - ra) / (yb - ya):
            res = not res
    return res


@nb.njit(cache=True, error_model="numpy")
def lathe_events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    """Interval list of a closed lathe along the whole line (entering / leaving alternate),
    written to ``out_t``, ``out_f`` (segment); returns the count (hits past ``cap`` are
    dropped: a line meets at most two per segment)."""
    off, n = int(par[k, 0]), int(par[k, 1])
    m = 0
    for i in range(n - 1):
        cnt, t0, t1 = _segment_roots(aux, off + 2 * i, ox, oy, oz, dx, dy, dz, TOL_ZERO)
        for r in range(cnt):
            if m < cap:
                out_t[m], out_f[m] = (t0 if r == 0 else t1), i
                m += 1
    sort_hits(out_t, out_f, m)
    w, status = 0, False
    for i in range(m):
        t = out_t[i]
        nxt = out_t[i + 1] if i + 1 < m else np.inf
        if nxt == t:
            continue
        tm = 0.5 * (t + nxt)
        after = nxt < np.inf and lathe_inside(par, k, aux, ox + tm * dx, oy + tm * dy, oz + tm * dz, stack)
        if after != status:
            out_t[w], out_f[w] = t, out_f[i]
            w += 1
            status = after
    return w


@nb.njit(cache=True, error_model="numpy")
def lathe_normal(par, k, aux, face, x, y, z, stack):
    """Normal of segment ``face`` at the object-space point (unit)."""
    j = int(par[k, 0]) + 2 * face
    o = par[k, 3]
    nr, ny = o * (aux[j + 3] - aux[j + 1]), -o * (aux[j + 2] - aux[j])
    rho = math.hypot(x, z)
    if rho == 0.0:
        return 0.0, math.copysign(1.0, ny), 0.0
    ln = math.hypot(nr, ny)
    return nr * x / (rho * ln), ny / ln, nr * z / (rho * ln)
