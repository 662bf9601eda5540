"""Numba kernels of the ``blob`` kind (:mod:`.blob`, whose module docstring gives the method):
its entry points for the ray tracer's dispatch (signatures: :mod:`.crossing_events`).  Apart
from the kind so that reading a scene does not import numba."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .blob import Par
from .illinois import change

JIT = dict(cache=True, error_model="numpy", **INTERNAL)
"""Every kernel here is called from compiled code only (``INTERNAL``: no numba wrappers)."""


@nb.njit(**JIT, forceinline=True)
def _poly(p0, p1, p2, p3, p4, v):
    return (((p4 * v + p3) * v + p2) * v + p1) * v + p0


@nb.njit(**JIT)
def _poly_at(p, v):
    """The quartic of coefficients ``p = (p0, ..., p4)`` at ``v`` (:func:`.illinois.change`'s
    function)."""
    return _poly(p[0], p[1], p[2], p[3], p[4], v)


@nb.njit(**JIT)
def _first_change(p0, p1, p2, p3, p4, lo, hi, c1, c2, c3):
    """First point in ``(lo, hi]`` past which ``poly > 0`` differs from its value at ``lo``,
    given the polynomial is monotone between the sorted breakpoints ``c1 <= c2 <= c3``
    (inf when unused); inf when none."""
    s0 = _poly(p0, p1, p2, p3, p4, lo) > 0.0
    a = lo
    for i in range(4):
        c = c1 if i == 0 else (c2 if i == 1 else (c3 if i == 2 else hi))
        if c > hi:
            c = hi
        if c <= a:
            continue
        if (_poly(p0, p1, p2, p3, p4, c) > 0.0) != s0:
            p = (p0, p1, p2, p3, p4)
            return change(_poly_at, p, a, _poly_at(p, a), c, _poly_at(p, c))
        a = c
    return np.inf


@nb.njit(**JIT)
def _quadratic_roots(A, B, C):
    """Sorted real roots of ``A v^2 + B v + C`` (inf when absent); a double root counts as none."""
    if A == 0.0:
        if B == 0.0:
            return np.inf, np.inf
        return -C / B, np.inf
    disc = B * B - 4.0 * A * C
    if not disc > 0.0:
        return np.inf, np.inf
    q = -0.5 * (B + math.copysign(math.sqrt(disc), B))
    r0, r1 = q / A, (C / q if q != 0.0 else -q / A)
    return min(r0, r1), max(r0, r1)


@nb.njit(**JIT)
def _quartic_change(p0, p1, p2, p3, p4, lo, hi):
    """First sign change of ``p0 + p1 v + ... + p4 v^4`` in ``(lo, hi]``: the critical points
    (roots of the cubic ``p'``, each bracketed between the roots of ``p''``) cut it into
    monotone pieces."""
    s1, s2 = _quadratic_roots(12.0 * p4, 6.0 * p3, 2.0 * p2)
    # roots of p' = p1 + 2 p2 v + 3 p3 v^2 + 4 p4 v^3 on its monotone pieces
    c = lo
    r1, r2, r3 = np.inf, np.inf, np.inf
    for i in range(3):
        x = _first_change(p1, 2.0 * p2, 3.0 * p3, 4.0 * p4, 0.0, c, hi, s1, s2, np.inf)
        if x == np.inf:
            break
        if i == 0:
            r1 = x
        elif i == 1:
            r2 = x
        else:
            r3 = x
        c = x
    return _first_change(p0, p1, p2, p3, p4, lo, hi, r1, r2, r3)


@nb.njit(**JIT, forceinline=True)
def _chord_nb(aux, j, ox, oy, oz, ux, uy, uz):
    fx, fy, fz = ox - aux[j], oy - aux[j + 1], oz - aux[j + 2]
    r = aux[j + 3]
    b = fx * ux + fy * uy + fz * uz
    px, py, pz = fx - b * ux, fy - b * uy, fz - b * uz
    disc = r * r - (px * px + py * py + pz * pz)
    if not disc > 0.0:
        return False, 0.0, 0.0
    sq = math.sqrt(disc)
    q = -b - sq if b >= 0.0 else -b + sq
    nf = math.sqrt(fx * fx + fy * fy + fz * fz)
    t0 = (nf - r) * (nf + r) / q if q != 0.0 else -sq
    return True, min(t0, q), max(t0, q)


@nb.njit(**JIT)
def _interval_quartic(aux, off, n, T, ox, oy, oz, ux, uy, uz, tm):
    """Coefficients (in ``v = t - tm``) of the field minus T on the interval containing ``tm``."""
    p0, p1, p2, p3, p4 = -T, 0.0, 0.0, 0.0, 0.0
    for i in range(n):
        j = off + 5 * i
        ok, ta, tb = _chord_nb(aux, j, ox, oy, oz, ux, uy, uz)
        if ok and ta < tm < tb:
            r2 = aux[j + 3] * aux[j + 3]
            s = aux[j + 4]
            gx, gy, gz = ox + tm * ux - aux[j], oy + tm * uy - aux[j + 1], oz + tm * uz - aux[j + 2]
            a = 1.0 - (gx * gx + gy * gy + gz * gz) / r2
            b = -2.0 * (gx * ux + gy * uy + gz * uz) / r2
            c = -1.0 / r2
            p0 += s * a * a
            p1 += s * 2.0 * a * b
            p2 += s * (b * b + 2.0 * a * c)
            p3 += s * 2.0 * b * c
            p4 += s * c * c
    return p0, p1, p2, p3, p4


@nb.njit(**JIT)
def _next_end(aux, off, n, ox, oy, oz, ux, uy, uz, after):
    """Smallest chord endpoint > ``after`` (inf when none)."""
    best = np.inf
    for i in range(n):
        ok, ta, tb = _chord_nb(aux, off + 5 * i, ox, oy, oz, ux, uy, uz)
        if ok:
            if after < ta < best:
                best = ta
            if after < tb < best:
                best = tb
    return best


@nb.njit(**JIT)
def blob_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out, cap):
    """Crossings of the surface by ``O + t D`` with ``tmin < t < tmax``, sorted, written to
    ``out`` (at most ``cap``; ``cap = 1`` gives the first hit).  Returns their count.  The
    intervals between chord endpoints are visited in order without sorting (each next endpoint
    is a minimum search), so nothing is allocated."""
    off, n, T = int(par[k, Par.OFFSET]), int(par[k, Par.COUNT]), par[k, Par.THRESHOLD]
    s = math.sqrt(dx * dx + dy * dy + dz * dz)
    ux, uy, uz = dx / s, dy / s, dz / s
    lo_t, hi_t = tmin * s, tmax * s
    m = 0
    e0 = _next_end(aux, off, n, ox, oy, oz, ux, uy, uz, -np.inf)
    while e0 < hi_t and m < cap:
        e1 = _next_end(aux, off, n, ox, oy, oz, ux, uy, uz, e0)
        if e1 == np.inf:
            break
        if e1 > lo_t:
            tm = 0.5 * (e0 + e1)
            p0, p1, p2, p3, p4 = _interval_quartic(aux, off, n, T, ox, oy, oz, ux, uy, uz, tm)
            # the root search spans the interval up to its chord end whatever tmax is, so that
            # a root does not depend on tmax (the ray tracer's structures test primitives in
            # different orders, with different tmax, and must find the same t)
            a, b = max(e0, lo_t) - tm, e1 - tm
            while m < cap:
                v = _quartic_change(p0, p1, p2, p3, p4, a, b)
                if v == np.inf:
                    break
                t = tm + v
                if not t < hi_t:  # so are the interval's next roots
                    break
                if t > lo_t:
                    out[m] = t / s
                    m += 1
                a = v
        e0 = e1
    return m


@nb.njit(**JIT)
def first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax``: ``(t, 0)``, ``(inf, 0)`` on a miss."""
    if blob_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, np.int64(1)) == 1:  # int64, not a literal: one compile (see kernels.walks.LANE)
        return out_t[0], 0
    return np.inf, 0


@nb.njit(**JIT)
def events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    """Interval list along the whole line (entering / leaving alternate); returns the count."""
    m = blob_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, -np.inf, np.inf, out_t, cap)
    for i in range(m):
        out_f[i] = 0
    return m


@nb.njit(**JIT)
def normal(par, k, aux, face, x, y, z, stack):
    """Outward normal -grad F at the object-space point (not normalised)."""
    off, n = int(par[k, Par.OFFSET]), int(par[k, Par.COUNT])
    nx, ny, nz = 0.0, 0.0, 0.0
    for i in range(n):
        j = off + 5 * i
        r2 = aux[j + 3] * aux[j + 3]
        gx, gy, gz = x - aux[j], y - aux[j + 1], z - aux[j + 2]
        q = 1.0 - (gx * gx + gy * gy + gz * gz) / r2
        if q > 0.0:
            w = 4.0 * aux[j + 4] * q / r2
            nx += w * gx
            ny += w * gy
            nz += w * gz
    return nx, ny, nz


@nb.njit(**JIT)
def inside(par, k, aux, x, y, z, stack):
    """F(x, y, z) > T."""
    off, n = int(par[k, Par.OFFSET]), int(par[k, Par.COUNT])
    F = 0.0
    for i in range(n):
        j = off + 5 * i
        q = 1.0 - ((x - aux[j]) ** 2 + (y - aux[j + 1]) ** 2 + (z - aux[j + 2]) ** 2) / (aux[j + 3] * aux[j + 3])
        if q > 0.0:
            F += aux[j + 4] * q * q
    return F > par[k, Par.THRESHOLD]
