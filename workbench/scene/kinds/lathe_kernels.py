"""Numba kernels of the ``lathe`` kind (:mod:`.lathe`, whose module docstring gives the method):
its entry points for the ray tracer's dispatch (signatures: :mod:`.crossing_events`).  Apart
from the kind so that reading a scene does not import numba."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .illinois import change
from .lathe import TOL_CUT, TOL_ZERO, Par
from .lathe_spline import NEWTON, SEED_MARGIN, SEG_FLOATS, SIGMA, STEEP

JIT = dict(cache=True, error_model="numpy", **INTERNAL)
"""Every kernel here is called from compiled code only (``INTERNAL``: no numba wrappers)."""


@nb.njit(**JIT)
def sort_hits(out_t, out_f, m):
    """Insertion sort of the first ``m`` hits by t (few hits: no allocation)."""
    for i in range(1, m):
        t, f = out_t[i], out_f[i]
        j = i - 1
        while j >= 0 and out_t[j] > t:
            out_t[j + 1], out_f[j + 1] = out_t[j], out_f[j]
            j -= 1
        out_t[j + 1], out_f[j + 1] = t, f


@nb.njit(**JIT)
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


@nb.njit(**JIT)
def first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax``: ``(t, segment)``, ``(inf, 0)`` on a miss."""
    if par[k, Par.SPLINE] != 0.0:
        return _spline_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, stack)
    off, n = int(par[k, Par.OFFSET]), int(par[k, Par.POINTS])
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


@nb.njit(**JIT)
def inside(par, k, aux, x, y, z, stack):
    """Even-odd test of ``(rho, y)`` against the closed profile."""
    if par[k, Par.CLOSED] == 0.0:
        return False
    if par[k, Par.SPLINE] != 0.0:
        return _spline_inside(par, k, aux, x, y, z, stack)
    off, n = int(par[k, Par.OFFSET]), int(par[k, Par.POINTS])
    rho = math.hypot(x, z)
    res = False
    for i in range(n):
        j = off + 2 * i
        jn = off + 2 * ((i + 1) % n)
        ra, ya, rb, yb = aux[j], aux[j + 1], aux[jn], aux[jn + 1]
        if ya != yb and ((ya > y) != (yb > y)) and rho < ra + (y - ya) * (rb - ra) / (yb - ya):
            res = not res
    return res


@nb.njit(**JIT)
def events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    """Interval list of a closed lathe along the whole line (entering / leaving alternate),
    written to ``out_t``, ``out_f`` (segment); returns the count (hits past ``cap`` are
    dropped: a line meets at most two per segment)."""
    off, n = int(par[k, Par.OFFSET]), int(par[k, Par.POINTS])
    m = 0
    if par[k, Par.SPLINE] != 0.0:
        m = _spline_collect(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack)
    else:
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
        after = nxt < np.inf and inside(par, k, aux, ox + tm * dx, oy + tm * dy, oz + tm * dz, stack)
        if after != status:
            out_t[w], out_f[w] = t, out_f[i]
            w += 1
            status = after
    return w


@nb.njit(**JIT)
def normal(par, k, aux, face, x, y, z, stack):
    """Normal of segment ``face`` at the object-space point (unit)."""
    if par[k, Par.SPLINE] != 0.0:
        return _spline_normal(par, k, aux, face, x, y, z, stack)
    j = int(par[k, Par.OFFSET]) + 2 * face
    o = par[k, Par.ORIENTATION]
    nr, ny = o * (aux[j + 3] - aux[j + 1]), -o * (aux[j + 2] - aux[j])
    rho = math.hypot(x, z)
    if rho == 0.0:
        return 0.0, math.copysign(1.0, ny), 0.0
    ln = math.hypot(nr, ny)
    return nr * x / (rho * ln), ny / ln, nr * z / (rho * ln)


# --------------------------------------------------------------------------- smooth profiles
# (.lathe_spline's method; the caller's ``stack`` scratch, (>= 24, 4) float64, holds the
# polynomials and roots: flat slot i is stack[i // 4, i % 4])
_LEVEL = 8          # slots per polynomial of the derivative chain (degree <= 6)
_CRIT = 56          # the roots found at the previous level
_NEW = 64           # the roots of the current level
_HITS_T = 72        # a segment's hits: t
_HITS_S = 84        # and s
_MAX_HITS = 12
C0 = np.int64(0)    # slot 0: a polynomial's constant term
DEG3, DEG6 = np.int64(3), np.int64(6)  # the degrees solved: a profile's cubic, a swept cubic's sextic
# (int64, not literals: numba compiles a callee once per literal argument, kernels.walks.LANE)


@nb.njit(**JIT, forceinline=True)
def _get(st, i):
    return st[i >> 2, i & 3]


@nb.njit(**JIT, forceinline=True)
def _put(st, i, v):
    st[i >> 2, i & 3] = v


@nb.njit(**JIT)
def _peval(st, base, deg, s):
    v = 0.0
    for i in range(deg, -1, -1):
        v = v * s + _get(st, base + i)
    return v


@nb.njit(**JIT)
def _peval_at(poly, s):
    """:func:`_peval` of ``poly = (st, base, deg)`` (:func:`.illinois.change`'s function)."""
    st, base, deg = poly
    return _peval(st, base, deg, s)


@nb.njit(**JIT)
def _roots_in(st, deg, lo, hi):
    """Sign changes of the polynomial in slots ``0..deg`` in ``(lo, hi]``, isolated by the roots
    of its derivatives (:func:`.lathe_spline.roots_in`); written to slots ``_CRIT..``, returns
    their count."""
    for lev in range(1, deg):
        d = deg - lev
        for i in range(d + 1):
            _put(st, lev * _LEVEL + i, (i + 1) * _get(st, (lev - 1) * _LEVEL + i + 1))
    nc = 0
    for lev in range(deg - 1, -1, -1):
        d = deg - lev
        base = lev * _LEVEL
        nn = 0
        a = lo
        fa = _peval(st, base, d, a) > 0.0
        for j in range(nc + 1):
            b = _get(st, _CRIT + j) if j < nc else hi
            fb = _peval(st, base, d, b) > 0.0
            if b > a and fa != fb:
                poly = (st, base, d)
                _put(st, _NEW + nn, change(_peval_at, poly, a, _peval_at(poly, a), b, _peval_at(poly, b)))
                nn += 1
            a, fa = b, fb
        for j in range(nn):
            _put(st, _CRIT + j, _get(st, _NEW + j))
        nc = nn
    return nc


@nb.njit(**JIT, forceinline=True)
def _cubic(aux, j, s):
    return ((aux[j + 3] * s + aux[j + 2]) * s + aux[j + 1]) * s + aux[j]


@nb.njit(**JIT, forceinline=True)
def _dcubic(aux, j, s):
    return (3.0 * aux[j + 3] * s + 2.0 * aux[j + 2]) * s + aux[j + 1]


@nb.njit(**JIT)
def _polish(aux, j, ox, oy, oz, dx, dy, dz, s, t):
    """Newton steps of :func:`.lathe_spline.polish`."""
    for _ in range(NEWTON):
        rs, ys = _cubic(aux, j, s), _cubic(aux, j + 4, s)
        drs, dys = _dcubic(aux, j, s), _dcubic(aux, j + 4, s)
        px, pz = ox + t * dx, oz + t * dz
        f1 = ys - oy - t * dy
        f2 = px * px + pz * pz - rs * rs
        j11, j12, j21, j22 = dys, -dy, -2.0 * rs * drs, 2.0 * (px * dx + pz * dz)
        det = j11 * j22 - j12 * j21
        if det == 0.0:
            break
        ds = (-f1 * j22 + j12 * f2) / det
        dt = (-j11 * f2 + j21 * f1) / det
        if not (math.isfinite(ds) and math.isfinite(dt)) or abs(ds) > SEED_MARGIN:
            break
        s, t = s + ds, t + dt
    return s, t


@nb.njit(**JIT)
def _in_bounds(aux, j, ox, oy, oz, dx, dy, dz, tmin, tmax):
    """Whether the line within ``(tmin, tmax)`` meets the segment's cylinder ``rho <= rmax``,
    ``ymin <= y <= ymax`` (aux ``j + 8 .. j + 10``)."""
    rmax, ylo, yhi = aux[j + 8], aux[j + 9], aux[j + 10]
    lo, hi = tmin, tmax
    if dy == 0.0:
        if oy < ylo or oy > yhi:
            return False
    else:
        ta, tb = (ylo - oy) / dy, (yhi - oy) / dy
        lo, hi = max(lo, min(ta, tb)), min(hi, max(ta, tb))
    a = dx * dx + dz * dz
    m = ox * dx + oz * dz
    c = ox * ox + oz * oz - rmax * rmax
    if a == 0.0:
        return c <= 0.0 and lo <= hi
    disc = m * m - a * c
    if disc < 0.0:
        return False
    sq = math.sqrt(disc)
    return max(lo, (-m - sq) / a) <= min(hi, (-m + sq) / a)


@nb.njit(**JIT)
def _spline_segment_hits(aux, j, ox, oy, oz, dx, dy, dz, st):
    """Every crossing of the line with the surface of the segment at aux[j:]: ``(t, s)`` in
    slots ``_HITS_T..``, ``_HITS_S..``; returns the count (:func:`.lathe_spline.segment_hits`)."""
    a = dx * dx + dz * dz
    m = ox * dx + oz * dz
    q = ox * ox + oz * oz
    n = 0
    if abs(dy) > STEEP * math.sqrt(a):
        # P(s) = a u^2 + 2 dy m u + dy^2 (q - r^2), u = y(s) - oy, in slots 0..6
        for i in range(7):
            _put(st, i, 0.0)
        for i in range(4):
            ui = aux[j + 4 + i] - (oy if i == 0 else 0.0)
            _put(st, i, _get(st, i) + 2.0 * dy * m * ui)
            for k in range(4):
                uk = aux[j + 4 + k] - (oy if k == 0 else 0.0)
                _put(st, i + k, _get(st, i + k) + a * ui * uk - dy * dy * aux[j + i] * aux[j + k])
        _put(st, C0, _get(st, C0) + dy * dy * q)
        nr = _roots_in(st, DEG6, -SIGMA, 1.0 + SIGMA)
        for r in range(nr):
            s = _get(st, _CRIT + r)
            s, t = _polish(aux, j, ox, oy, oz, dx, dy, dz, s, (_cubic(aux, j + 4, s) - oy) / dy)
            if -SIGMA <= s <= 1.0 + SIGMA and n < _MAX_HITS:
                _put(st, _HITS_T + n, t)
                _put(st, _HITS_S + n, s)
                n += 1
        return n
    tc = -m / a
    for i in range(4):
        _put(st, i, aux[j + 4 + i])
    _put(st, C0, aux[j + 4] - (oy + dy * tc))
    nr = _roots_in(st, DEG3, -SEED_MARGIN, 1.0 + SEED_MARGIN)
    for r in range(nr):
        s0 = _get(st, _CRIT + r)
        R = _cubic(aux, j, s0)
        b, c = 2.0 * m, q - R * R
        disc = b * b - 4.0 * a * c
        if not disc > 0.0:
            continue
        qq = -0.5 * (b + math.copysign(math.sqrt(disc), b))
        for w in range(2):
            s, t = _polish(aux, j, ox, oy, oz, dx, dy, dz, s0, qq / a if w == 0 else c / qq)
            if -SIGMA <= s <= 1.0 + SIGMA and n < _MAX_HITS:
                _put(st, _HITS_T + n, t)
                _put(st, _HITS_S + n, s)
                n += 1
    return n


@nb.njit(**JIT)
def _spline_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, st):
    off, nseg = int(par[k, Par.OFFSET]), int(par[k, Par.SEGMENTS])
    best, bf = tmax, -1
    for i in range(nseg):
        j = off + SEG_FLOATS * i
        if not _in_bounds(aux, j, ox, oy, oz, dx, dy, dz, tmin, best):
            continue
        n = _spline_segment_hits(aux, j, ox, oy, oz, dx, dy, dz, st)
        for r in range(n):
            t = _get(st, _HITS_T + r)
            if tmin < t < best:
                best, bf = t, i
    if bf < 0:
        return np.inf, 0
    return best, bf


@nb.njit(**JIT)
def _spline_collect(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, st):
    off, nseg = int(par[k, Par.OFFSET]), int(par[k, Par.SEGMENTS])
    m = 0
    for i in range(nseg):
        j = off + SEG_FLOATS * i
        if not _in_bounds(aux, j, ox, oy, oz, dx, dy, dz, -np.inf, np.inf):
            continue
        n = _spline_segment_hits(aux, j, ox, oy, oz, dx, dy, dz, st)
        for r in range(n):
            if m < cap:
                out_t[m], out_f[m] = _get(st, _HITS_T + r), i
                m += 1
    return m


@nb.njit(**JIT)
def _spline_inside(par, k, aux, x, y, z, st):
    """Even-odd count of :func:`.lathe_spline.inside`."""
    off, nseg = int(par[k, Par.OFFSET]), int(par[k, Par.SEGMENTS])
    rho = math.hypot(x, z)
    res = False
    for i in range(nseg):
        j = off + SEG_FLOATS * i
        if y < aux[j + 9] or y > aux[j + 10] or rho >= aux[j + 8]:
            continue
        for c in range(4):
            _put(st, c, aux[j + 4 + c])
        _put(st, C0, aux[j + 4] - y)
        nr = _roots_in(st, DEG3, 0.0, 1.0)
        for r in range(nr):
            if _cubic(aux, j, _get(st, _CRIT + r)) > rho:
                res = not res
    return res


@nb.njit(**JIT)
def _spline_param(aux, j, x, y, z, st):
    """:func:`.lathe_spline.param_at`."""
    rho = math.hypot(x, z)
    best, bd = 0.0, np.inf
    for which in range(3):
        nr = 2
        if which < 2:
            for c in range(4):
                _put(st, c, aux[j + (4 if which == 0 else 0) + c])
            _put(st, C0, _get(st, C0) - (y if which == 0 else rho))
            nr = _roots_in(st, DEG3, -SEED_MARGIN, 1.0 + SEED_MARGIN)
        for r in range(nr):
            s = _get(st, _CRIT + r) if which < 2 else float(r)
            d = math.hypot(_cubic(aux, j, s) - rho, _cubic(aux, j + 4, s) - y)
            if d < bd:
                best, bd = s, d
    return best


@nb.njit(**JIT)
def _spline_normal(par, k, aux, face, x, y, z, st):
    j = int(par[k, Par.OFFSET]) + SEG_FLOATS * face
    o = par[k, Par.ORIENTATION]
    s = _spline_param(aux, j, x, y, z, st)
    nr, ny = o * _dcubic(aux, j + 4, s), -o * _dcubic(aux, j, s)
    rho = math.hypot(x, z)
    ln = math.hypot(nr, ny)
    if rho == 0.0 or ln == 0.0:
        return 0.0, math.copysign(1.0, ny), 0.0
    return nr * x / (rho * ln), ny / ln, nr * z / (rho * ln)
