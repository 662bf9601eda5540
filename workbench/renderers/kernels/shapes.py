"""Ray intersection of the analytic primitives: quadratics, slabs, polygons, quadrics, the
dispatch to the kinds with kernels of their own (:mod:`.specialise`), CSG interval programs
(Roth 1982: each leaf's entry/exit events combined by the node's operator) and the object-space
normal of a hit.  The readable twin is :mod:`workbench.renderers.raytrace.reference`.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.tol import tol
from ...scene.kinds import BOX, KERNEL_PTYPES_FROM, POLYGON, QUADRIC, RECT, SPHERE
from ...scene.kinds.box import Par as BoxPar
from ...scene.kinds.csg import CSG_DIFFERENCE, CSG_INTERSECTION, CSG_UNION
from ...scene.kinds.plane import Par as RectPar
from ...scene.kinds.polygon import Par as PolygonPar
from ...scene.kinds.quadric import Par as QuadricPar
from ...scene.kinds.sphere import Par as SpherePar
from .flags import INLINE, NO_REFCOUNT
from .specialise import exotic_events, exotic_first, exotic_normal

CSG_EVENTS = 32
"""Events (entries and exits) a CSG operand's interval list holds."""
TOL_CUT = tol.cut
"""Relative slack of a cut quadric's bounds test (``tol.cut``; a compile-time constant of the kernels)."""


@nb.njit(**INLINE)
def _to_object(xf, k, ox, oy, oz, dx, dy, dz):
    return (xf[k, 0] * ox + xf[k, 1] * oy + xf[k, 2] * oz + xf[k, 3], xf[k, 4] * ox + xf[k, 5] * oy + xf[k, 6] * oz + xf[k, 7],
            xf[k, 8] * ox + xf[k, 9] * oy + xf[k, 10] * oz + xf[k, 11],
            xf[k, 0] * dx + xf[k, 1] * dy + xf[k, 2] * dz, xf[k, 4] * dx + xf[k, 5] * dy + xf[k, 6] * dz,
            xf[k, 8] * dx + xf[k, 9] * dy + xf[k, 10] * dz)


@nb.njit(**INLINE)
def solve_quadratic(A, B, C, zero):
    """Real roots of ``A t^2 + B t + C`` sorted (DESIGN errata 7: ``q = -(B + sign(B) sqrt(disc))/2``,
    roots ``q/A`` and ``C/q``); a negligible ``A`` (:func:`linear`) gives the linear root ``-C/B``.
    Returns ``(n, t0, t1)``; a tangent (double) root counts as no root (the course ignores it)."""
    if linear(A, B, C, zero):
        if B == 0.0:
            return 0, 0.0, 0.0
        t = -C / B
        return 1, t, t
    disc = B * B - 4.0 * A * C
    if not disc > 0.0:
        return 0, 0.0, 0.0
    sq = math.sqrt(disc)
    q = -0.5 * (B + sq) if B >= 0.0 else -0.5 * (B - sq)
    t0 = q / A
    t1 = C / q if q != 0.0 else -t0
    if t0 > t1:
        t0, t1 = t1, t0
    return 2, t0, t1


@nb.njit(**INLINE)
def linear(A, B, C, zero):
    """True when ``A t^2 + B t + C`` is linear for the ray: ``|A C| <= zero B^2``, i.e. the
    second root ``-B/A`` lies beyond ``1/zero`` times the first ``-C/B`` (or ``A = B = 0``).
    Homogeneous in the coefficients and in the unit of ``t``, so a quadric at scale 1e6 (``A``
    of order 1e-12 for a unit direction) is not taken for a plane (as ``|A| <= zero (|A| + |B|
    + |C|)`` took it)."""
    return abs(A * C) <= zero * (B * B)


@nb.njit(**INLINE)
def sphere_roots(par, k, ox, oy, oz, dx, dy, dz):
    """Roots of the ray / sphere equation in object space (see :func:`sphere_roots_unit`)."""
    inv_s = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return sphere_roots_unit(par, k, ox, oy, oz, dx * inv_s, dy * inv_s, dz * inv_s, inv_s)


@nb.njit(**INLINE)
def sphere_roots_unit(par, k, ox, oy, oz, ux, uy, uz, inv_s):
    """Roots of the ray / sphere equation in object space, for the unit direction ``u`` of a
    ray direction of length ``1 / inv_s`` (the roots are in units of that direction).

    Errata 1 (B uses O - C) and the cancellation-free discriminant of Haines et al.,
    "Precision improvements for ray/sphere intersection" (Ray Tracing Gems, 2019):
    ``disc = r^2 - |f - (f.d) d|^2`` with ``f = O - C`` and ``d`` the unit direction.  A sphere
    entirely behind the origin reports no roots (no ray or CSG query needs ``t < 0``)."""
    c = SpherePar.CENTER
    fx, fy, fz = ox - par[k, c], oy - par[k, c + 1], oz - par[k, c + 2]
    r = par[k, SpherePar.RADIUS]
    b = fx * ux + fy * uy + fz * uz
    ff = fx * fx + fy * fy + fz * fz
    if b > 0.0 and ff > r * r:  # outside and moving away: both roots behind the origin
        return False, 0.0, 0.0
    px, py, pz = fx - b * ux, fy - b * uy, fz - b * uz
    disc = r * r - (px * px + py * py + pz * pz)
    if not disc > 0.0:
        return False, 0.0, 0.0
    sq = math.sqrt(disc)
    q = -b - sq if b >= 0.0 else -b + sq
    nf = math.sqrt(ff)
    c = (nf - r) * (nf + r)
    t0 = c / q if q != 0.0 else -sq
    t1 = q
    if t0 > t1:
        t0, t1 = t1, t0
    return True, t0 * inv_s, t1 * inv_s


@nb.njit(**INLINE)
def slab(lo0, lo1, lo2, hi0, hi1, hi2, ox, oy, oz, dx, dy, dz):
    """Ray / axis-aligned box (Kay & Kajiya slabs).  Returns ``(ok, t_near, face_near, t_far,
    face_far)``; faces are ``1 + 2 axis + side`` (side 1 = max face)."""
    tn, tf = -np.inf, np.inf
    fn, ff = 0, 0
    for a in range(3):
        if a == 0:
            o, d, lo, hi = ox, dx, lo0, hi0
        elif a == 1:
            o, d, lo, hi = oy, dy, lo1, hi1
        else:
            o, d, lo, hi = oz, dz, lo2, hi2
        if d == 0.0:
            if o < lo or o > hi:
                return False, 0.0, 0, 0.0, 0
            continue
        t0 = (lo - o) / d
        t1 = (hi - o) / d
        f0, f1 = 1 + 2 * a, 2 + 2 * a
        if t0 > t1:
            t0, t1 = t1, t0
            f0, f1 = f1, f0
        if t0 > tn:
            tn, fn = t0, f0
        if t1 < tf:
            tf, ff = t1, f1
    if tn > tf:
        return False, 0.0, 0, 0.0, 0
    return True, tn, fn, tf, ff


@nb.njit(**INLINE)
def quadric_coeffs(par, k, ox, oy, oz, dx, dy, dz):
    """``A = D^T Q D``, ``B = 2 D^T Q P0``, ``C = P0^T Q P0`` with D lifted with w = 0 and P0
    with w = 1 (errata 2: the cross terms of C carry their factor 2)."""
    q = QuadricPar.Q
    q00, q01, q02, q03, q11, q12, q13, q22, q23, q33 = (par[k, q], par[k, q + 1], par[k, q + 2], par[k, q + 3],
                                                         par[k, q + 4], par[k, q + 5], par[k, q + 6], par[k, q + 7],
                                                         par[k, q + 8], par[k, q + 9])
    # Q P0 and Q D (first three rows)
    qp0 = q00 * ox + q01 * oy + q02 * oz + q03
    qp1 = q01 * ox + q11 * oy + q12 * oz + q13
    qp2 = q02 * ox + q12 * oy + q22 * oz + q23
    qp3 = q03 * ox + q13 * oy + q23 * oz + q33
    qd0 = q00 * dx + q01 * dy + q02 * dz
    qd1 = q01 * dx + q11 * dy + q12 * dz
    qd2 = q02 * dx + q12 * dy + q22 * dz
    A = dx * qd0 + dy * qd1 + dz * qd2
    B = 2.0 * (dx * qp0 + dy * qp1 + dz * qp2)
    C = ox * qp0 + oy * qp1 + oz * qp2 + qp3
    return A, B, C


@nb.njit(**INLINE)
def _in_bounds(par, k, x, y, z, slack):
    lo, hi = QuadricPar.BOUNDS_MIN, QuadricPar.BOUNDS_MAX
    return (par[k, lo] - slack <= x <= par[k, hi] + slack and par[k, lo + 1] - slack <= y <= par[k, hi + 1] + slack
            and par[k, lo + 2] - slack <= z <= par[k, hi + 2] + slack)


@nb.njit(**INLINE)
def _polygon_hit(k, par, poly_v, ox, oy, oz, dx, dy, dz, tmin, tmax):
    """Planar convex polygon ``k``: plane hit inside every edge.  Not inlined (a rarely used
    path: one compiled copy instead of one per call site of :func:`closest`)."""
    n_ = PolygonPar.NORMAL
    nx, ny, nz = par[k, n_], par[k, n_ + 1], par[k, n_ + 2]
    den = nx * dx + ny * dy + nz * dz
    if den == 0.0:
        return np.inf, 0
    t = (par[k, PolygonPar.OFFSET] - (nx * ox + ny * oy + nz * oz)) / den
    if not (tmin < t < tmax):
        return np.inf, 0
    qx, qy, qz = ox + t * dx, oy + t * dy, oz + t * dz
    s, n = int(par[k, PolygonPar.FIRST]), int(par[k, PolygonPar.COUNT])
    for i in range(n):
        j = s + (i + 1) % n
        ax, ay, az = poly_v[s + i, 0], poly_v[s + i, 1], poly_v[s + i, 2]
        ex, ey, ez = poly_v[j, 0] - ax, poly_v[j, 1] - ay, poly_v[j, 2] - az
        wx, wy, wz = qx - ax, qy - ay, qz - az
        cx, cy, cz = ey * wz - ez * wy, ez * wx - ex * wz, ex * wy - ey * wx
        if cx * nx + cy * ny + cz * nz < 0.0:
            return np.inf, 0
    return t, 0


@nb.njit(**INLINE)
def _quadric_hit(k, par, ox, oy, oz, dx, dy, dz, tmin, tmax, zero):
    """General quadric ``k`` cut to its bounds: first root in ``(tmin, tmax)`` inside them.
    Not inlined (see :func:`_polygon_hit`)."""
    A, B, C = quadric_coeffs(par, k, ox, oy, oz, dx, dy, dz)
    n, t0, t1 = solve_quadratic(A, B, C, zero)
    for r in range(n):
        t = t0 if r == 0 else t1
        if tmin < t < tmax:
            px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
            # the computed point is off by rounding relative to |O| + |t D|: a ray through a
            # point of the bounds' faces (an ellipsoid's pole) must not fall out of them
            slack = TOL_CUT * (max(abs(ox), abs(oy), abs(oz)) + abs(t) * max(abs(dx), abs(dy), abs(dz)))
            if _in_bounds(par, k, px, py, pz, slack):
                return t, 0
    return np.inf, 0


@nb.njit(**INLINE)
def prim_hit(kinds, k, ptype, par, poly_v, aux, ox, oy, oz, dx, dy, dz, ux, uy, uz, inv_s, tmin, tmax,
             zero, out_t, out_f, stack):
    """Closest hit ``tmin < t < tmax`` of analytic primitive ``k`` (object-space ray with
    direction ``d``; spheres use its unit direction ``u`` and ``inv_s = 1 / |d|``).  The
    kinds with kernel modules of their own (``KERNELS``: :mod:`workbench.scene.kinds`)
    read it from ``aux`` and use the scratch ``out_t``, ``out_f``, ``stack``.
    Returns ``(t, face)``, ``t = inf`` on a miss."""
    kind = ptype[k]
    if kind == SPHERE:
        ok, t0, t1 = sphere_roots_unit(par, k, ox, oy, oz, ux, uy, uz, inv_s)
        if ok:
            if tmin < t0 < tmax:
                return t0, 0
            if tmin < t1 < tmax:
                return t1, 0
        return np.inf, 0
    if kind == RECT:
        p0, u, v, n_ = RectPar.POINT, RectPar.U, RectPar.V, RectPar.N
        nx, ny, nz = par[k, n_], par[k, n_ + 1], par[k, n_ + 2]
        den = nx * dx + ny * dy + nz * dz
        if den == 0.0:
            return np.inf, 0
        num = (par[k, p0] - ox) * nx + (par[k, p0 + 1] - oy) * ny + (par[k, p0 + 2] - oz) * nz
        if tmin >= 0.0 and (num <= 0.0 if den > 0.0 else num >= 0.0):
            # t = num / den <= 0 (the signs alone say so: no division): the ray leaves the
            # plane or starts on it, as every shadow feeler and reflected ray from a floor,
            # and every camera ray above the horizon, does.  The same misses as the quotient
            return np.inf, 0
        t = num / den
        if not (tmin < t < tmax):
            return np.inf, 0
        qx, qy, qz = ox + t * dx - par[k, p0], oy + t * dy - par[k, p0 + 1], oz + t * dz - par[k, p0 + 2]
        if (abs(qx * par[k, u] + qy * par[k, u + 1] + qz * par[k, u + 2]) <= par[k, RectPar.HALF_U]
                and abs(qx * par[k, v] + qy * par[k, v + 1] + qz * par[k, v + 2]) <= par[k, RectPar.HALF_V]):
            return t, 0
        return np.inf, 0
    if kind == BOX:
        b0, b1 = BoxPar.MIN, BoxPar.MAX
        ok, tn, fn, tf, ff = slab(par[k, b0], par[k, b0 + 1], par[k, b0 + 2], par[k, b1], par[k, b1 + 1],
                                   par[k, b1 + 2], ox, oy, oz, dx, dy, dz)
        if ok:
            if tmin < tn < tmax:
                return tn, fn
            if tmin < tf < tmax:
                return tf, ff
        return np.inf, 0
    if kind == POLYGON:
        return _polygon_hit(k, par, poly_v, ox, oy, oz, dx, dy, dz, tmin, tmax)
    if kind == QUADRIC:
        return _quadric_hit(k, par, ox, oy, oz, dx, dy, dz, tmin, tmax, zero)
    # the kinds with kernel modules of their own: compiled only for a scene that has them
    return exotic_first(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack)


@nb.njit(**NO_REFCOUNT)
def leaf_events(kinds, k, ptype, par, aux, ox, oy, oz, dx, dy, dz, zero, et, ep, ef, stack):
    """Interval list (entering / leaving events along the whole line) of solid leaf ``k``:
    sphere, box, or quadric inside ``P^T Q P < 0`` intersected with its bounds box.
    Writes ``et`` (t), ``ep`` (signed primitive code ``k + 1``), ``ef`` (face); returns the count."""
    kind = ptype[k]
    if kind == SPHERE:
        ok, t0, t1 = sphere_roots(par, k, ox, oy, oz, dx, dy, dz)
        if not ok:
            return 0
        et[0], et[1] = t0, t1
        ep[0], ep[1] = k + 1, k + 1
        ef[0], ef[1] = 0, 0
        return 2
    if kind == BOX:
        b0, b1 = BoxPar.MIN, BoxPar.MAX
        ok, tn, fn, tf, ff = slab(par[k, b0], par[k, b0 + 1], par[k, b0 + 2], par[k, b1], par[k, b1 + 1],
                                   par[k, b1 + 2], ox, oy, oz, dx, dy, dz)
        if not ok or not tn < tf:
            return 0
        et[0], et[1] = tn, tf
        ep[0], ep[1] = k + 1, k + 1
        ef[0], ef[1] = fn, ff
        return 2
    if kind == QUADRIC:
        q0, q1 = QuadricPar.BOUNDS_MIN, QuadricPar.BOUNDS_MAX
        ok, sn, sfn, sf, sff = slab(par[k, q0], par[k, q0 + 1], par[k, q0 + 2], par[k, q1], par[k, q1 + 1],
                                     par[k, q1 + 2], ox, oy, oz, dx, dy, dz)
        if not ok or not sn < sf:
            return 0
        A, B, C = quadric_coeffs(par, k, ox, oy, oz, dx, dy, dz)
        n, r0, r1 = solve_quadratic(A, B, C, zero)
        # the inside {t : A t^2 + B t + C < 0} as up to two intervals (a, b)
        cnt = 0
        ia0, ib0, ia1, ib1 = 0.0, 0.0, 0.0, 0.0
        if linear(A, B, C, zero):
            if n == 1:
                if B > 0.0:
                    ia0, ib0, cnt = -np.inf, r0, 1
                else:
                    ia0, ib0, cnt = r0, np.inf, 1
            elif C < 0.0:
                ia0, ib0, cnt = -np.inf, np.inf, 1
        elif A > 0.0:
            if n == 2:
                ia0, ib0, cnt = r0, r1, 1
        else:
            if n == 2:
                ia0, ib0, ia1, ib1, cnt = -np.inf, r0, r1, np.inf, 2
            else:
                ia0, ib0, cnt = -np.inf, np.inf, 1
        m = 0
        for i in range(cnt):
            a = ia0 if i == 0 else ia1
            b = ib0 if i == 0 else ib1
            fa, fb = 0, 0
            if sn > a:
                a, fa = sn, sfn
            if sf < b:
                b, fb = sf, sff
            if a < b:
                et[m], et[m + 1] = a, b
                ep[m], ep[m + 1] = k + 1, k + 1
                ef[m], ef[m + 1] = fa, fb
                m += 2
        return m
    m = 0
    cap = et.shape[0]
    m = exotic_events(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack)
    m -= m % 2            # a list cut at the capacity ends inside: close the last interval
    for i in range(m):
        ep[i] = k + 1
    return m


@nb.njit(**INLINE)
def _op(op, a, b):
    if op == CSG_UNION:
        return a or b
    if op == CSG_INTERSECTION:
        return a and b
    return a and not b


@nb.njit(**NO_REFCOUNT)
def combine(op, st, sp_, sf, sn, a, b, out, eps):
    """Combine two interval lists by a boolean ``op`` (the course's ``composite_intersect``):
    sweep the events of both lists in order, grouping events closer than ``eps`` (coincident
    surfaces), and emit an event wherever ``op(inside A, inside B)`` changes; intervals shorter
    than ``eps`` are dropped.  A difference flips the normals of B's surfaces (sign of the code).
    The lists are levels ``a`` and ``b`` of the interval stack (``st`` t, ``sp_`` signed
    primitive code, ``sf`` face, ``sn`` count per level); the result goes to level ``out``.
    Returns the number of output events."""
    ta, pa, fa, na = st[a], sp_[a], sf[a], sn[a]
    tb, pb, fb, nb_ = st[b], sp_[b], sf[b], sn[b]
    to, po, fo = st[out], sp_[out], sf[out]
    i, j, m = 0, 0, 0
    ina, inb, state = False, False, False
    flip = -1 if op == CSG_DIFFERENCE else 1
    cap = to.shape[0]
    while i < na or j < nb_:
        t = np.inf
        if i < na:
            t = ta[i]
        if j < nb_ and tb[j] < t:
            t = tb[j]
        ct, cp, cf = t, 0, 0
        a_moved = False
        while i < na and ta[i] <= t + eps:
            ina = not ina
            ct, cp, cf = ta[i], pa[i], fa[i]
            a_moved = True
            i += 1
        while j < nb_ and tb[j] <= t + eps:
            inb = not inb
            if not a_moved:
                ct, cp, cf = tb[j], flip * pb[j], fb[j]
            j += 1
        new = _op(op, ina, inb)
        if new != state:
            state = new
            if not new and m > 0 and ct - to[m - 1] <= eps:
                m -= 1  # zero-length interval: drop it
            elif m < cap:
                to[m], po[m], fo[m] = ct, cp, cf
                m += 1
    if m % 2 == 1:  # truncated by the capacity: close the last interval
        m -= 1
    return m


@nb.njit(**NO_REFCOUNT)
def csg_hit(geo, start, length, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, levels, stack):
    """Evaluate a CSG postfix program (``geo.prog[start:start + length]``) along a ray (the
    course's recursive ``intersect``, made iterative).  ``levels``: the interval stack
    ``(st, sp_, sf, sn)`` (see :func:`combine`).  Returns ``(t, code, face)`` of the first
    boundary in ``(tmin, tmax)``."""
    kinds, prog, ptype, xf, par, aux = geo.kinds, geo.prog, geo.ptype, geo.xf, geo.par, geo.aux
    st, sp_, sf, sn = levels
    top = np.int64(0)  # int64, not a literal: one compile of combine (see walks.LANE)
    for q in range(start, start + length):
        c = prog[q]
        if c >= 0:
            lo = _to_object(xf, c, ox, oy, oz, dx, dy, dz)
            sn[top] = leaf_events(kinds, c, ptype, par, aux, lo[0], lo[1], lo[2], lo[3], lo[4], lo[5], zero,
                                  st[top], sp_[top], sf[top], stack)
            top += 1
        else:
            a, b = top - 2, top - 1
            # write into the spare level, then move down
            m = combine(c, st, sp_, sf, sn, a, b, top, eps)
            for e in range(m):
                st[a, e], sp_[a, e], sf[a, e] = st[top, e], sp_[top, e], sf[top, e]
            sn[a] = m
            top -= 1
    for e in range(sn[0]):
        if st[0, e] > tmin:
            if st[0, e] < tmax:
                return st[0, e], sp_[0, e], sf[0, e]
            break
    return np.inf, 0, 0


@nb.njit(**INLINE)
def object_normal(kinds, k, face, ptype, par, aux, x, y, z, stack):
    """Outward normal (unnormalised) of primitive ``k`` at object-space point, by face."""
    kind = ptype[k]
    if kind >= KERNEL_PTYPES_FROM:
        return exotic_normal(kinds, kind, par, k, aux, face, x, y, z, stack)
    if face >= 1 and (kind == BOX or kind == QUADRIC):
        a = (face - 1) // 2
        s = 1.0 if (face - 1) % 2 == 1 else -1.0
        return (s if a == 0 else 0.0), (s if a == 1 else 0.0), (s if a == 2 else 0.0)
    if kind == SPHERE:
        c = SpherePar.CENTER
        return x - par[k, c], y - par[k, c + 1], z - par[k, c + 2]
    if kind == RECT:
        return par[k, RectPar.N], par[k, RectPar.N + 1], par[k, RectPar.N + 2]
    if kind == POLYGON:
        return par[k, PolygonPar.NORMAL], par[k, PolygonPar.NORMAL + 1], par[k, PolygonPar.NORMAL + 2]
    if kind == QUADRIC:  # gradient of P^T Q P (halved): rows of Q (upper triangle in QuadricPar.Q)
        q = QuadricPar.Q
        return (par[k, q] * x + par[k, q + 1] * y + par[k, q + 2] * z + par[k, q + 3],
                par[k, q + 1] * x + par[k, q + 4] * y + par[k, q + 5] * z + par[k, q + 6],
                par[k, q + 2] * x + par[k, q + 5] * y + par[k, q + 7] * z + par[k, q + 8])
    return 0.0, 1.0, 0.0


@nb.njit(**INLINE)
def _normalize(x, y, z):
    n = math.sqrt(x * x + y * y + z * z)
    if n > 0.0:
        return x / n, y / n, z / n
    return 0.0, 0.0, 0.0
