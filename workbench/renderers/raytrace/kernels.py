"""Numba kernels of the ray tracer: intersection (closest hit, shadow feelers), the shading and
spawning step of a hit (:func:`shade_hit`), and the two drivers: the fused kernel
(:func:`render_pixels`: each pixel's whole ray tree depth first) and the wavefront kernels
(:func:`trace_batch`, :func:`shade_batch`: each generation of rays is traced, then shaded, then
its reflected and refracted children form the next generation).

Everything is scalar code over flat arrays (:mod:`.flatten`; the geometry as the named record
:class:`..kernels.layout.Geometry`), but for the BVH traversal, which tests four boxes and four
triangles side by side (:func:`bvh_hit`).  The drivers run blocks of pixels or chunks of rays
on several threads: the fused one as ``nogil`` tasks on a thread pool
(:mod:`..kernels.tasks`), the wavefront ones with ``prange``; each task has its own scratch
arrays (BVH stack, CSG interval stacks, ray stack) and hands its work to functions compiled
without reference counting (:data:`NO_REFCOUNT`).  Helpers marked ``inline="always"`` are
inlined into their callers by numba, at the IR level, and are not cached themselves: that
copying is most of a first render's compile time, but making them calls slows warm renders
(``docs/kernels.md``).
The kernels are compiled per set of kinds present (:mod:`..kernels.specialise`): the
geometry's kind marker makes the blob, isosurface, lathe and prism kernels, CSG programs and
the two trees' walks compile only for a scene that has them.  ``error_model="numpy"``: float
divisions follow IEEE (no zero-divisor check and exception path on every division; the
results are the same wherever the default Python model would not raise).  ``cache=True``:
compiled code is kept on disk (``NUMBA_CACHE_DIR``), so a warm cache compiles nothing.

The readable version of the same algorithm is :mod:`.reference`; the two are tested against
each other.  Equations: see the docstrings of the reference's functions.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba import prange
from numba.extending import overload

from ...core.tol import tol
from ...scene.kinds import BOX, CSGNODE, POLYGON, QUADRIC, RECT, SPHERE
from ...scene.kinds import blob, isosurface, lathe, prism
from ...scene.kinds.csg import CSG_DEPTH, CSG_DIFFERENCE, CSG_INTERSECTION, CSG_UNION
from ...scene.kinds.expression import MAX_STACK
from ..kernels.tasks import run_tasks
from ..kernels.specialise import exotic_events, exotic_first, exotic_normal, has
from .bvh import MAX_DEPTH
from .flatten import SHADOW_CROSSINGS

BLOB, ISOSURFACE, LATHE, PRISM = blob.PTYPE, isosurface.PTYPE, lathe.PTYPE, prism.PTYPE
CHUNK = 64
FAST_MATH = {"nsz", "arcp"}
"""The fast-math flags of the hot kernels: signed zeros may be ignored, a division may become a
multiplication by a reciprocal.  Not ``nnan``/``ninf``: misses are ``inf`` and the tests look
for NaN, so the compiler may not assume either away.  Not ``contract``: a fused multiply-add
breaks the watertight triangle test (the two triangles of a shared edge must round its edge
function the same way, or a ray through the edge misses both)."""
NO_REFCOUNT = dict(cache=True, error_model="numpy", _nrt=False, fastmath=FAST_MATH)
"""Options of the kernels that allocate nothing: compiled without numba's reference counting
(no atomic increments and decrements of every array they touch, which cost the fused kernel
40 % of its time); the arrays they use belong to their (reference-counted) callers."""
BVH_STACK = 3 * MAX_DEPTH + 4
"""Rows of the 4-wide traversal's stack: at most three pending children per level (``.bvh.MAX_DEPTH``)."""
CSG_EVENTS = 32
TOL_CUT = tol.cut
"""Relative slack of a cut quadric's bounds test (``tol.cut``; a compile-time constant of the kernels)."""
# Slab exits are enlarged by 1 + 2 gamma_3 (gamma_n = n u / (1 - n u), u = 2^-53) so that
# rounding never culls a box the ray touches (Ize, "Robust BVH ray traversal", JCGT 2013).
BOX_GAMMA = 1.0 + 2.0 * 3.0 * 2.0 ** -53 / (1.0 - 3.0 * 2.0 ** -53)


# ----------------------------------------------------------------------------- small helpers
@nb.njit(error_model="numpy", inline="always")
def _to_object(xf, k, ox, oy, oz, dx, dy, dz):
    return (xf[k, 0] * ox + xf[k, 1] * oy + xf[k, 2] * oz + xf[k, 3], xf[k, 4] * ox + xf[k, 5] * oy + xf[k, 6] * oz + xf[k, 7],
            xf[k, 8] * ox + xf[k, 9] * oy + xf[k, 10] * oz + xf[k, 11],
            xf[k, 0] * dx + xf[k, 1] * dy + xf[k, 2] * dz, xf[k, 4] * dx + xf[k, 5] * dy + xf[k, 6] * dz,
            xf[k, 8] * dx + xf[k, 9] * dy + xf[k, 10] * dz)


@nb.njit(**NO_REFCOUNT)
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


@nb.njit(error_model="numpy", inline="always")
def linear(A, B, C, zero):
    """True when ``A t^2 + B t + C`` is linear for the ray: ``|A C| <= zero B^2``, i.e. the
    second root ``-B/A`` lies beyond ``1/zero`` times the first ``-C/B`` (or ``A = B = 0``).
    Homogeneous in the coefficients and in the unit of ``t``, so a quadric at scale 1e6 (``A``
    of order 1e-12 for a unit direction) is not taken for a plane (as ``|A| <= zero (|A| + |B|
    + |C|)`` took it)."""
    return abs(A * C) <= zero * (B * B)


@nb.njit(error_model="numpy", inline="always")
def sphere_roots(par, k, ox, oy, oz, dx, dy, dz):
    """Roots of the ray / sphere equation in object space (see :func:`sphere_roots_unit`)."""
    inv_s = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return sphere_roots_unit(par, k, ox, oy, oz, dx * inv_s, dy * inv_s, dz * inv_s, inv_s)


@nb.njit(error_model="numpy", inline="always")
def sphere_roots_unit(par, k, ox, oy, oz, ux, uy, uz, inv_s):
    """Roots of the ray / sphere equation in object space, for the unit direction ``u`` of a
    ray direction of length ``1 / inv_s`` (the roots are in units of that direction).

    Errata 1 (B uses O - C) and the cancellation-free discriminant of Haines et al.,
    "Precision improvements for ray/sphere intersection" (Ray Tracing Gems, 2019):
    ``disc = r^2 - |f - (f.d) d|^2`` with ``f = O - C`` and ``d`` the unit direction.  A sphere
    entirely behind the origin reports no roots (no ray or CSG query needs ``t < 0``)."""
    fx, fy, fz = ox - par[k, 0], oy - par[k, 1], oz - par[k, 2]
    r = par[k, 3]
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


@nb.njit(error_model="numpy", inline="always")
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


@nb.njit(error_model="numpy", inline="always")
def quadric_coeffs(par, k, ox, oy, oz, dx, dy, dz):
    """``A = D^T Q D``, ``B = 2 D^T Q P0``, ``C = P0^T Q P0`` with D lifted with w = 0 and P0
    with w = 1 (errata 2: the cross terms of C carry their factor 2)."""
    q00, q01, q02, q03, q11, q12, q13, q22, q23, q33 = (par[k, 0], par[k, 1], par[k, 2], par[k, 3], par[k, 4],
                                                         par[k, 5], par[k, 6], par[k, 7], par[k, 8], par[k, 9])
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


@nb.njit(error_model="numpy", inline="always")
def _in_bounds(par, k, x, y, z, slack):
    return (par[k, 10] - slack <= x <= par[k, 13] + slack and par[k, 11] - slack <= y <= par[k, 14] + slack
            and par[k, 12] - slack <= z <= par[k, 15] + slack)


# ----------------------------------------------------------------------------- primitives
@nb.njit(**NO_REFCOUNT)
def _polygon_hit(k, par, poly_v, ox, oy, oz, dx, dy, dz, tmin, tmax):
    """Planar convex polygon ``k``: plane hit inside every edge.  Not inlined (a rarely used
    path: one compiled copy instead of one per call site of :func:`closest`)."""
    nx, ny, nz = par[k, 0], par[k, 1], par[k, 2]
    den = nx * dx + ny * dy + nz * dz
    if den == 0.0:
        return np.inf, 0
    t = (par[k, 3] - (nx * ox + ny * oy + nz * oz)) / den
    if not (tmin < t < tmax):
        return np.inf, 0
    qx, qy, qz = ox + t * dx, oy + t * dy, oz + t * dz
    s, n = int(par[k, 4]), int(par[k, 5])
    for i in range(n):
        j = s + (i + 1) % n
        ax, ay, az = poly_v[s + i, 0], poly_v[s + i, 1], poly_v[s + i, 2]
        ex, ey, ez = poly_v[j, 0] - ax, poly_v[j, 1] - ay, poly_v[j, 2] - az
        wx, wy, wz = qx - ax, qy - ay, qz - az
        cx, cy, cz = ey * wz - ez * wy, ez * wx - ex * wz, ex * wy - ey * wx
        if cx * nx + cy * ny + cz * nz < 0.0:
            return np.inf, 0
    return t, 0


@nb.njit(**NO_REFCOUNT)
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


@nb.njit(error_model="numpy", inline="always")
def prim_hit(kinds, k, ptype, par, poly_v, aux, ox, oy, oz, dx, dy, dz, ux, uy, uz, inv_s, tmin, tmax,
             zero, out_t, out_f, stack):
    """Closest hit ``tmin < t < tmax`` of analytic primitive ``k`` (object-space ray with
    direction ``d``; spheres use its unit direction ``u`` and ``inv_s = 1 / |d|``).  The
    kinds with variable-length data (blob, isosurface, lathe, prism: :mod:`workbench.scene.kinds`)
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
        nx, ny, nz = par[k, 9], par[k, 10], par[k, 11]
        den = nx * dx + ny * dy + nz * dz
        if den == 0.0:
            return np.inf, 0
        t = ((par[k, 0] - ox) * nx + (par[k, 1] - oy) * ny + (par[k, 2] - oz) * nz) / den
        if not (tmin < t < tmax):
            return np.inf, 0
        qx, qy, qz = ox + t * dx - par[k, 0], oy + t * dy - par[k, 1], oz + t * dz - par[k, 2]
        if abs(qx * par[k, 3] + qy * par[k, 4] + qz * par[k, 5]) <= par[k, 12] and abs(qx * par[k, 6] + qy * par[k, 7] + qz * par[k, 8]) <= par[k, 13]:
            return t, 0
        return np.inf, 0
    if kind == BOX:
        ok, tn, fn, tf, ff = slab(par[k, 0], par[k, 1], par[k, 2], par[k, 3], par[k, 4], par[k, 5], ox, oy, oz, dx, dy, dz)
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
    # blob, isosurface, lathe, prism: compiled only for a scene that has them
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
        ok, tn, fn, tf, ff = slab(par[k, 0], par[k, 1], par[k, 2], par[k, 3], par[k, 4], par[k, 5], ox, oy, oz, dx, dy, dz)
        if not ok or not tn < tf:
            return 0
        et[0], et[1] = tn, tf
        ep[0], ep[1] = k + 1, k + 1
        ef[0], ef[1] = fn, ff
        return 2
    if kind == QUADRIC:
        ok, sn, sfn, sf, sff = slab(par[k, 10], par[k, 11], par[k, 12], par[k, 13], par[k, 14], par[k, 15], ox, oy, oz, dx, dy, dz)
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


@nb.njit(error_model="numpy", inline="always")
def _op(op, a, b):
    if op == CSG_UNION:
        return a or b
    if op == CSG_INTERSECTION:
        return a and b
    return a and not b


@nb.njit(**NO_REFCOUNT)
def combine(op, ta, pa, fa, na, tb, pb, fb, nb_, to, po, fo, eps):
    """Combine two interval lists by a boolean ``op`` (the course's ``composite_intersect``):
    sweep the events of both lists in order, grouping events closer than ``eps`` (coincident
    surfaces), and emit an event wherever ``op(inside A, inside B)`` changes; intervals shorter
    than ``eps`` are dropped.  A difference flips the normals of B's surfaces (sign of the code).
    Returns the number of output events."""
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
def csg_hit(kinds, start, length, prog, ptype, xf, par, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, zero,
            eps, st, sp_, sf, sn, stack):
    """Evaluate a CSG postfix program along a ray (the course's recursive ``intersect``, made
    iterative).  Returns ``(t, code, face)`` of the first boundary in ``(tmin, tmax)``."""
    top = 0
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
            m = combine(c, st[a], sp_[a], sf[a], sn[a], st[b], sp_[b], sf[b], sn[b],
                        st[top], sp_[top], sf[top], eps)
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


@nb.njit(error_model="numpy", inline="always")
def _edge_functions(tv4, g, j, pk, okx, oky, okz, sx, sy, sz):
    """The watertight ray / triangle test's edge functions ``U, V, W`` of triangle ``j`` of
    group ``g`` (:func:`.bvh.build_bvh4`) and its vertices' sheared depths (Woop, Benthin &
    Wald, JCGT 2013), in the ray's permuted axes: ``pk`` the rows of vertex 0's ``kx, ky, kz``,
    then vertex 1's and vertex 2's (``kz`` the dominant axis of the direction); ``ok*`` the
    origin along them, ``s*`` the shear."""
    az, bz, cz = tv4[g, pk[2], j] - okz, tv4[g, pk[5], j] - okz, tv4[g, pk[8], j] - okz
    ax = (tv4[g, pk[0], j] - okx) - sx * az
    ay = (tv4[g, pk[1], j] - oky) - sy * az
    bx = (tv4[g, pk[3], j] - okx) - sx * bz
    by = (tv4[g, pk[4], j] - oky) - sy * bz
    cx = (tv4[g, pk[6], j] - okx) - sx * cz
    cy = (tv4[g, pk[7], j] - oky) - sy * cz
    return cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax, az, bz, cz


@nb.njit(error_model="numpy", inline="always")
def tri_lane(tv4, g, j, pk, okx, oky, okz, sx, sy, sz, tmin, tmax):
    """Watertight ray / triangle test of triangle ``j`` of group ``g`` (see
    :func:`_edge_functions`), without branches, so that the four triangles of a group are
    tested side by side.  Returns ``t``, ``inf`` on a miss."""
    U, V, W, az, bz, cz = _edge_functions(tv4, g, j, pk, okx, oky, okz, sx, sy, sz)
    # the edge functions' signs differ: the ray passes outside
    outside = ((U < 0.0) | (V < 0.0) | (W < 0.0)) & ((U > 0.0) | (V > 0.0) | (W > 0.0))
    det = U + V + W
    t = (U * sz * az + V * sz * bz + W * sz * cz) / det
    return t if ((not outside) & (det != 0.0) & (tmin < t) & (t < tmax)) else np.inf


@nb.njit(error_model="numpy", inline="always")
def _slab_interval(nx, ny, nz, fx, fy, fz):
    """Entry and exit distances of a ray in a box from its three slabs' near and far plane
    distances.  A ray parallel to a slab has ``+-inf`` distances (``1 / 0``), and NaN where it
    lies in the slab's plane (``0 * inf``): NaN fails every comparison, so that slab is
    ignored (the ray is inside it), as in pbrt's ray-box test."""
    tn = nx if nx > -np.inf else -np.inf
    tn = ny if ny > tn else tn
    tn = nz if nz > tn else tn
    tf = fx if fx < np.inf else np.inf
    tf = fy if fy < tf else tf
    tf = fz if fz < tf else tf
    return tn, tf


@nb.njit(error_model="numpy", inline="always")
def _bounds_hit(b, ox, oy, oz, dx, dy, dz, tmin, tmax):
    """Whether the ray meets the box ``b`` (min xyz, max xyz) within ``[tmin, tmax]``: the
    test before a BVH traversal (the call, and its set-up, cost more than the test; most
    rays of a scene with a small mesh miss its box)."""
    ix, iy, iz = 1.0 / dx, 1.0 / dy, 1.0 / dz
    cx = 0 if ix >= 0.0 else 3
    cy = 1 if iy >= 0.0 else 4
    cz = 2 if iz >= 0.0 else 5
    tn, tf = _slab_interval((b[cx] - ox) * ix, (b[cy] - oy) * iy, (b[cz] - oz) * iz,
                            (b[3 - cx] - ox) * ix, (b[5 - cy] - oy) * iy, (b[7 - cz] - oz) * iz)
    return tn <= tf * BOX_GAMMA and tf >= tmin and tn <= tmax


@nb.njit(error_model="numpy", inline="always")
def box_lane(node, nd, j, pl, ox, oy, oz, ix, iy, iz, tmin, best):
    """Entry distance of the ray into child ``j``'s box of 4-wide node ``nd``, ``inf`` if it
    misses it or enters beyond ``best``.  ``pl``: the rows of the planes the ray enters by,
    then of those it leaves by (min for a positive direction component, max for a negative
    one: no min / max sorts each slab's two distances; Williams et al., "An efficient and
    robust ray-box intersection algorithm", JGT 2005); exits are enlarged by ``BOX_GAMMA``
    (Ize, JCGT 2013).  Without branches: the four children are tested side by side."""
    tn, tf = _slab_interval((node[nd, pl[0], j] - ox) * ix, (node[nd, pl[1], j] - oy) * iy,
                            (node[nd, pl[2], j] - oz) * iz, (node[nd, pl[3], j] - ox) * ix,
                            (node[nd, pl[4], j] - oy) * iy, (node[nd, pl[5], j] - oz) * iz)
    return tn if ((tn <= tf * BOX_GAMMA) & (tf >= tmin) & (tn <= best)) else np.inf


@nb.njit(error_model="numpy", inline="always")
def _push_sorted(stack, base, sp, t, code):
    """Push ``(t, code)`` on ``stack`` above row ``base``, keeping rows ``base..sp`` sorted
    with the nearest on top.  Returns the new height."""
    j = sp
    while j > base and stack[j - 1, 0] < t:
        stack[j, 0], stack[j, 1] = stack[j - 1, 0], stack[j - 1, 1]
        j -= 1
    stack[j, 0], stack[j, 1] = t, code
    return sp + 1


@nb.njit(error_model="numpy", inline="always")
def _visit_child(stack, base, sp, top, t, code, near, tnear):
    """One hit child of a node: it becomes the node to visit next if it is the nearest so far
    (the previous nearest waits on the stack), else it waits.  Returns ``(sp, near, tnear)``."""
    if t < tnear:
        if near != -1 and sp < top:
            sp = _push_sorted(stack, base, sp, tnear, near)
        return sp, code, t
    if sp < top:
        sp = _push_sorted(stack, base, sp, t, code)
    return sp, near, tnear


@nb.njit(error_model="numpy", inline="always")
def node_ray(ox, oy, oz, dx, dy, dz, tmin):
    """The ray as :func:`open_node` reads it: ``(pl, ox, oy, oz, ix, iy, iz, tmin)``, its
    origin, inverse direction (``+-inf`` for a zero component: see :func:`_slab_interval`),
    the start of its interval and ``pl``, the rows of the planes it enters a box by, then of
    those it leaves by (:func:`box_lane`)."""
    ix, iy, iz = 1.0 / dx, 1.0 / dy, 1.0 / dz
    cx = 0 if ix >= 0.0 else 3
    cy = 1 if iy >= 0.0 else 4
    cz = 2 if iz >= 0.0 else 5
    # unsigned row indices: no negative-index wrap-around per lane (it stops the vectorizer)
    pl = (np.uint64(cx), np.uint64(cy), np.uint64(cz), np.uint64(3 - cx), np.uint64(5 - cy), np.uint64(7 - cz))
    return pl, ox, oy, oz, ix, iy, iz, tmin


@nb.njit(error_model="numpy", inline="always")
def open_node(tree, code, ray, best, stack, sp, top):
    """Visit of 4-wide node ``code`` of ``tree = (node, child)`` (the layout of
    :func:`.bvh.build_bvh4`: children's boxes ``(N4, 6, 4)``, children ``(N4, 4)``) by
    ``ray`` (:func:`node_ray`): the four children's boxes are tested side by side
    (:func:`box_lane`; an entry beyond ``best`` is a miss), the nearest hit child is visited
    next and the other hit children wait on ``stack`` above row ``sp`` (rows ``(entry
    distance, child)``, nearest on top; of equal entries the lower slot is visited first:
    :func:`_visit_child`), no higher than row ``top``.  The one node visit of the triangles'
    traversal (:func:`bvh_hit`), the analytic primitives' (:func:`prim_tree_walk`) and the
    traversal statistics' (:func:`.traversal_stats.count_hit`).  Returns ``(sp, code)``: the
    new stack height and the child to visit next (``>= 0`` a node, ``<= -2`` a leaf, ``-1``
    none hit)."""
    node, child = tree
    pl, ox, oy, oz, ix, iy, iz, tmin = ray
    nd = np.uint64(code)
    t0 = box_lane(node, nd, 0, pl, ox, oy, oz, ix, iy, iz, tmin, best)
    t1 = box_lane(node, nd, 1, pl, ox, oy, oz, ix, iy, iz, tmin, best)
    t2 = box_lane(node, nd, 2, pl, ox, oy, oz, ix, iy, iz, tmin, best)
    t3 = box_lane(node, nd, 3, pl, ox, oy, oz, ix, iy, iz, tmin, best)
    base, code, tn = sp, -1, np.inf
    if t0 < np.inf:
        code, tn = child[nd, 0], t0
    if t1 < np.inf:
        sp, code, tn = _visit_child(stack, base, sp, top, t1, child[nd, 1], code, tn)
    if t2 < np.inf:
        sp, code, tn = _visit_child(stack, base, sp, top, t2, child[nd, 2], code, tn)
    if t3 < np.inf:
        sp, code, tn = _visit_child(stack, base, sp, top, t3, child[nd, 3], code, tn)
    return sp, code


def _slp_vectorized(dispatcher):
    """Compile ``dispatcher`` with LLVM's superword-level-parallelism vectorizer, which packs
    the four box tests of a 4-wide node, and the four triangle tests of a leaf group, into
    vector instructions (:func:`bvh_hit`).  numba leaves it off by default, and rightly for the
    rest of these kernels: on for everything, it slowed the Whitted scene's trace by 9 %
    (measured).  numba reads the setting when it optimises a function, inside ``compile``, so it
    is on only while this function compiles (under numba's compiler lock, which is re-entrant:
    no other thread compiles meanwhile); callers link the vectorized code.  No result changes:
    each lane rounds as the scalar code would."""
    from numba.core.compiler_lock import global_compiler_lock
    compile_scalar = dispatcher.compile

    def compile_vectorized(sig):
        with global_compiler_lock:
            saved = nb.config.SLP_VECTORIZE
            nb.config.SLP_VECTORIZE = 1
            try:
                return compile_scalar(sig)
            finally:
                nb.config.SLP_VECTORIZE = saved

    dispatcher.compile = compile_vectorized
    return dispatcher


@_slp_vectorized
@nb.njit(**NO_REFCOUNT)
def bvh_hit(bvh, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
    """Closest (or any) triangle hit through the 4-wide BVH (:func:`.bvh.build_bvh4`): at each
    node the four children's boxes are tested together, the nearest hit child is visited next
    and the others wait on ``stack`` (rows ``(entry distance, child)``, nearest on top), skipped
    when popped if the best hit is now nearer than their box; a leaf's triangles are tested four
    at a time.  Returns ``(t, tri, b1, b2)``."""
    node, child, leaf, first, tv4 = bvh
    ray = node_ray(ox, oy, oz, dx, dy, dz, tmin)
    # the watertight test's shear
    ax0, ax1, ax2 = abs(dx), abs(dy), abs(dz)
    kz = 0
    if ax1 > ax0 and ax1 >= ax2:
        kz = 1
    elif ax2 > ax0 and ax2 > ax1:
        kz = 2
    kx = (kz + 1) % 3
    ky = (kx + 1) % 3
    d = (dx, dy, dz)
    if d[kz] < 0.0:
        kx, ky = ky, kx
    sx, sy, sz = d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]
    o = (ox, oy, oz)
    okx, oky, okz = o[kx], o[ky], o[kz]
    pk = (np.uint64(kx), np.uint64(ky), np.uint64(kz), np.uint64(3 + kx), np.uint64(3 + ky),
          np.uint64(3 + kz), np.uint64(6 + kx), np.uint64(6 + ky), np.uint64(6 + kz))
    best, bg, bl = tmax, -1, 0
    top = stack.shape[0] - 1  # never reached (BVH_STACK); a bound all the same
    code, sp = 0, 0
    while True:
        while code >= 0:  # a 4-wide node
            sp, code = open_node((node, child), code, ray, best, stack, sp, top)
        if code < -1:  # a leaf
            lf = -2 - code
            for g in range(leaf[lf, 0], leaf[lf, 0] + leaf[lf, 1]):
                u0 = tri_lane(tv4, g, 0, pk, okx, oky, okz, sx, sy, sz, tmin, best)
                u1 = tri_lane(tv4, g, 1, pk, okx, oky, okz, sx, sy, sz, tmin, best)
                u2 = tri_lane(tv4, g, 2, pk, okx, oky, okz, sx, sy, sz, tmin, best)
                u3 = tri_lane(tv4, g, 3, pk, okx, oky, okz, sx, sy, sz, tmin, best)
                m = min(min(u0, u1), min(u2, u3))
                if m < best:  # the lowest lane of the nearest (a padding lane repeats an earlier one)
                    best, bg = m, g
                    bl = 0 if u0 == m else (1 if u1 == m else (2 if u2 == m else 3))
                    if any_hit:
                        break
            if any_hit and bg >= 0:
                break
        code = -1
        while sp > 0:  # pop, skipping boxes now beyond the best hit
            sp -= 1
            if stack[sp, 0] <= best:
                code = int(stack[sp, 1])
                break
        if code == -1:
            break
    if bg < 0:
        return np.inf, -1, 0.0, 0.0
    # barycentric weights of vertices 1 and 2: the edge functions over their sum
    U, V, W, _, _, _ = _edge_functions(tv4, bg, bl, pk, okx, oky, okz, sx, sy, sz)
    return best, first[bg] + bl, V / (U + V + W), W / (U + V + W)


@nb.njit(error_model="numpy", inline="always")
def row_hit(geo, k, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, zero, eps, stack, st, sp_, sf, sn):
    """Closest hit ``tmin < t < tmax`` of top-level analytic primitive row ``k`` (a CSG node
    evaluates its program) for the world ray.  Returns ``(t, prim, face)``: ``prim`` the row
    hit (a CSG leaf's own row), ``face + 16`` for a flipped CSG normal; ``t = inf`` on a miss."""
    ptype, xf, par, aux = geo.ptype, geo.xf, geo.par, geo.aux
    if geo.ident[k]:  # object space is world space: no transform, the world unit direction
        lo = (ox, oy, oz, dx, dy, dz)
        inv_s = inv_w
    else:
        lo = _to_object(xf, k, ox, oy, oz, dx, dy, dz)
        inv_s = 1.0 / math.sqrt(lo[3] * lo[3] + lo[4] * lo[4] + lo[5] * lo[5])
    if ptype[k] == CSGNODE:
        t, code, f = csg_gate(geo.kinds, int(par[k, 0]), int(par[k, 1]), geo.prog, ptype, xf, par, aux,
                              ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, st, sp_, sf, sn, stack)
        return t, abs(code) - 1, f + (16 if code < 0 else 0)
    t, f = prim_hit(geo.kinds, k, ptype, par, geo.poly_v, aux, lo[0], lo[1], lo[2], lo[3], lo[4], lo[5],
                    lo[3] * inv_s, lo[4] * inv_s, lo[5] * inv_s, inv_s, tmin, tmax, zero,
                    st[0], sf[0], stack)
    return t, k, f


PRIM_STACK_BASE = max(BVH_STACK, MAX_STACK)
"""First row of the scratch stack used by the analytic primitives' traversal
(:func:`prim_tree_hit`): rows below it stay free for an isosurface's expression evaluator,
which runs inside that traversal."""


@nb.njit(**NO_REFCOUNT)
def prim_tree_hit(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, brow, shadow_only, any_hit, zero, eps,
                  stack, st, sp_, sf, sn):
    """Closest hit through the analytic primitives' 4-wide tree (:class:`.accel.PrimTree`;
    traversal as :func:`bvh_hit`'s, one primitive row per leaf item).  ``best``: the nearest
    hit so far (of row ``brow``, ``-1`` for none); a hit replaces it as :func:`nearer`
    says.  Returns ``(t, prim, face, row)``,
    ``row = -1`` if nothing replaced ``best``."""
    return prim_tree_walk(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, brow, shadow_only, any_hit, zero,
                          eps, stack, st, sp_, sf, sn, False, sn)


# ----------------------------------------------------------------------------- gates
# The walks below compile only for a scene that needs them (see ..kernels.specialise): CSG
# programs, the analytic primitives' tree, the triangles' tree.  A gate whose feature is absent
# is never reached (its caller tests the same data first) and compiles to a miss.

def csg_gate(kinds, start, length, prog, ptype, xf, par, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, zero,
             eps, st, sp_, sf, sn, stack):
    """:func:`csg_hit` if the scene has CSG nodes."""
    raise TypeError("csg_gate is callable from numba-compiled code only")


@overload(csg_gate, jit_options=dict(error_model="numpy"))
def _csg_gate(kinds, start, length, prog, ptype, xf, par, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, zero,
              eps, st, sp_, sf, sn, stack):
    on = has(kinds, "csg")

    def impl(kinds, start, length, prog, ptype, xf, par, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, zero,
             eps, st, sp_, sf, sn, stack):
        if on:
            return csg_hit(kinds, start, length, prog, ptype, xf, par, aux, ox, oy, oz, dx, dy, dz, tmin,
                           tmax, zero, eps, st, sp_, sf, sn, stack)
        return np.inf, 0, 0
    return impl


def prim_tree_gate(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, brow, shadow_only, any_hit, zero, eps,
                   stack, st, sp_, sf, sn):
    """:func:`prim_tree_hit` if the scene has bounded analytic primitives."""
    raise TypeError("prim_tree_gate is callable from numba-compiled code only")


@overload(prim_tree_gate, jit_options=dict(error_model="numpy"))
def _prim_tree_gate(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, brow, shadow_only, any_hit, zero, eps,
                    stack, st, sp_, sf, sn):
    on = has(geo.types[-1], "prim_tree")  # geo.kinds' type

    def impl(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, brow, shadow_only, any_hit, zero, eps,
             stack, st, sp_, sf, sn):
        if on:
            return prim_tree_hit(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, brow, shadow_only,
                                 any_hit, zero, eps, stack, st, sp_, sf, sn)
        return best, -1, 0, -1
    return impl


def triangles_gate(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
    """:func:`bvh_hit` over the scene's triangles if it has any."""
    raise TypeError("triangles_gate is callable from numba-compiled code only")


@overload(triangles_gate, jit_options=dict(error_model="numpy"))
def _triangles_gate(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
    on = has(geo.types[-1], "triangles")

    def impl(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
        if on:
            return bvh_hit((geo.bvh_node, geo.bvh_child, geo.bvh_leaf, geo.bvh_first, geo.bvh_tv4),
                           ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack)
        return np.inf, -1, 0.0, 0.0
    return impl


@nb.njit(error_model="numpy", inline="always")
def prim_tree_walk(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, brow, shadow_only, any_hit, zero, eps,
                   stack, st, sp_, sf, sn, count, cnt):
    """:func:`prim_tree_hit`; with ``count`` (the traversal statistics' pass,
    :mod:`.traversal_stats`) it adds the 4-wide nodes visited to ``cnt[0]`` and the primitive
    tests to ``cnt[1]`` (the rendering kernels pass ``False``: no counting)."""
    shadow, pnode, pchild, pleaf, pref = geo.shadow, geo.pnode, geo.pchild, geo.pleaf, geo.pref
    ray = node_ray(ox, oy, oz, dx, dy, dz, tmin)
    w = eps * inv_w  # coincidence window in ray parameter units (see :func:`nearer`)
    reach = best + w if brow >= 0 else best
    bp, bf, found = -1, 0, -1
    base = PRIM_STACK_BASE
    top_ = stack.shape[0] - 1
    code, sp = 0, base
    while True:
        while code >= 0:
            if count:
                cnt[0] += 1
            sp, code = open_node((pnode, pchild), code, ray, reach, stack, sp, top_)
        if code < -1:
            lf = -2 - code
            for q in range(pleaf[lf, 0], pleaf[lf, 0] + pleaf[lf, 1]):
                k = pref[q]
                if shadow_only and not shadow[k]:
                    continue
                if count:
                    cnt[1] += 1
                # up to best and its window: a coincident surface of a lower row wins
                t, p, f = row_hit(geo, k, ox, oy, oz, dx, dy, dz, inv_w, tmin, np.nextafter(reach, np.inf),
                                  zero, eps, stack, st, sp_, sf, sn)
                if nearer(t, k, best, brow, w):
                    best, bp, bf, brow, found = t, p, f, k, k
                    reach = best + w
                    if any_hit:
                        return best, bp, bf, found
        code = -1
        while sp > base:
            sp -= 1
            if stack[sp, 0] <= reach:
                code = int(stack[sp, 1])
                break
        if code == -1:
            break
    return best, bp, bf, found


@nb.njit(error_model="numpy", inline="always")
def nearer(t, k, best, brow, w):
    """Whether a hit at ``t`` of row ``k`` replaces the nearest so far (``best`` of row
    ``brow``, ``-1`` for none).  Two surfaces closer along the ray than ``w`` (the secondary
    rays' offset, relative to the scene's size: no ray can tell them apart) are coincident,
    such as a box's face resting on a floor: the lower row wins whatever the rounding says,
    so that the choice does not change with the scene's scale or the traversal's order."""
    if brow < 0:
        return t < best
    return t < best - w or (t <= best + w and k < brow)


@nb.njit(error_model="numpy", inline="always")
def closest(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, shadow_only, any_hit, zero, eps, stack,
            st, sp_, sf, sn):
    """Nearest hit of a world ray over all primitives: the list of analytic primitives tested
    one by one, then the analytic primitives' structure, then the triangles' (see
    :mod:`.accel`).  Returns ``(t, prim, face, tri, b1, b2)``; ``prim = -1`` on a miss,
    negative ``face`` is never returned (a flipped CSG normal is ``face + 16``)."""
    pfree, shadow = geo.pfree, geo.shadow
    best, bp, bf, btri, bb1, bb2 = tmax, -1, 0, -1, 0.0, 0.0
    brow = -1
    inv_w = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    w = eps * inv_w
    for q in range(pfree.shape[0]):
        k = pfree[q]
        if shadow_only and not shadow[k]:
            continue
        t, p, f = row_hit(geo, k, ox, oy, oz, dx, dy, dz, inv_w, tmin, best + w if brow >= 0 else best,
                          zero, eps, stack, st, sp_, sf, sn)
        if nearer(t, k, best, brow, w):
            best, bp, bf, brow = t, p, f, k
        if any_hit and bp >= 0:
            return best, bp, bf, btri, bb1, bb2
    if geo.pref.shape[0] > 0 and _bounds_hit(geo.pbounds, ox, oy, oz, dx, dy, dz, tmin, best):
        t, p, f, row = prim_tree_gate(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, best, np.int64(brow),
                                      np.bool_(shadow_only), np.bool_(any_hit), zero, eps, stack, st,
                                      sp_, sf, sn)
        if row >= 0:
            best, bp, bf, brow = t, p, f, row
            if any_hit:
                return best, bp, bf, btri, bb1, bb2
    if geo.tri_v.shape[0] > 0 and _bounds_hit(geo.bvh_bounds, ox, oy, oz, dx, dy, dz, tmin, best):
        t, tri, b1, b2 = triangles_gate(geo, ox, oy, oz, dx, dy, dz, tmin, best + w if brow >= 0 else best,
                                        np.bool_(any_hit), stack)
        if tri >= 0 and nearer(t, geo.tri_prim[tri], best, brow, w):
            best, bp, bf, btri, bb1, bb2 = t, geo.tri_prim[tri], 0, tri, b1, b2
    if bp < 0:
        return np.inf, -1, 0, -1, 0.0, 0.0
    return best, bp, bf, btri, bb1, bb2


@nb.njit(error_model="numpy", inline="always")
def object_normal(kinds, k, face, ptype, par, aux, x, y, z, stack):
    """Outward normal (unnormalised) of primitive ``k`` at object-space point, by face."""
    kind = ptype[k]
    if kind == BLOB or kind == ISOSURFACE or kind == LATHE or kind == PRISM:
        return exotic_normal(kinds, kind, par, k, aux, face, x, y, z, stack)
    if face >= 1 and (kind == BOX or kind == QUADRIC):
        a = (face - 1) // 2
        s = 1.0 if (face - 1) % 2 == 1 else -1.0
        return (s if a == 0 else 0.0), (s if a == 1 else 0.0), (s if a == 2 else 0.0)
    if kind == SPHERE:
        return x - par[k, 0], y - par[k, 1], z - par[k, 2]
    if kind == RECT:
        return par[k, 9], par[k, 10], par[k, 11]
    if kind == POLYGON:
        return par[k, 0], par[k, 1], par[k, 2]
    if kind == QUADRIC:  # gradient of P^T Q P (halved)
        return (par[k, 0] * x + par[k, 1] * y + par[k, 2] * z + par[k, 3], par[k, 1] * x + par[k, 4] * y + par[k, 5] * z + par[k, 6],
                par[k, 2] * x + par[k, 5] * y + par[k, 7] * z + par[k, 8])
    return 0.0, 1.0, 0.0


@nb.njit(error_model="numpy", inline="always")
def _normalize(x, y, z):
    n = math.sqrt(x * x + y * y + z * z)
    if n > 0.0:
        return x / n, y / n, z / n
    return 0.0, 0.0, 0.0


@nb.njit(error_model="numpy", inline="always")
def surface(geo, k, face, tri, b1, b2, px, py, pz, ncancel, out_ng, out_ns, out_uv, out_po, out_e, i,
            stack):
    """Geometric (outward) normal, shading normal, uv (meshes; analytic primitives leave the
    mapping to the texturing module), object-space point and vertex emission at a hit, written
    to row ``i`` of the output arrays (``stack``: scratch of an isosurface's gradient)."""
    xf, nm, tri_v, tri_n, tri_uv, tri_e = geo.xf, geo.nm, geo.tri_v, geo.tri_n, geo.tri_uv, geo.tri_e
    x = xf[k, 0] * px + xf[k, 1] * py + xf[k, 2] * pz + xf[k, 3]
    y = xf[k, 4] * px + xf[k, 5] * py + xf[k, 6] * pz + xf[k, 7]
    z = xf[k, 8] * px + xf[k, 9] * py + xf[k, 10] * pz + xf[k, 11]
    out_po[i, 0], out_po[i, 1], out_po[i, 2] = x, y, z
    out_uv[i, 0], out_uv[i, 1] = 0.0, 0.0
    out_e[i, 0], out_e[i, 1], out_e[i, 2] = 0.0, 0.0, 0.0
    if tri >= 0:
        e1x, e1y, e1z = tri_v[tri, 3] - tri_v[tri, 0], tri_v[tri, 4] - tri_v[tri, 1], tri_v[tri, 5] - tri_v[tri, 2]
        e2x, e2y, e2z = tri_v[tri, 6] - tri_v[tri, 0], tri_v[tri, 7] - tri_v[tri, 1], tri_v[tri, 8] - tri_v[tri, 2]
        gx, gy, gz = _normalize(e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x)
        b0 = 1.0 - b1 - b2
        sx = b0 * tri_n[tri, 0] + b1 * tri_n[tri, 3] + b2 * tri_n[tri, 6]
        sy = b0 * tri_n[tri, 1] + b1 * tri_n[tri, 4] + b2 * tri_n[tri, 7]
        sz = b0 * tri_n[tri, 2] + b1 * tri_n[tri, 5] + b2 * tri_n[tri, 8]
        ln = math.sqrt(sx * sx + sy * sy + sz * sz)
        if ln > ncancel:  # a cancelled interpolated normal falls back to Ng
            sx, sy, sz = sx / ln, sy / ln, sz / ln
        else:
            sx, sy, sz = gx, gy, gz
        out_uv[i, 0] = b0 * tri_uv[tri, 0] + b1 * tri_uv[tri, 2] + b2 * tri_uv[tri, 4]
        out_uv[i, 1] = b0 * tri_uv[tri, 1] + b1 * tri_uv[tri, 3] + b2 * tri_uv[tri, 5]
        for c in range(3):
            out_e[i, c] = b0 * tri_e[tri, c] + b1 * tri_e[tri, 3 + c] + b2 * tri_e[tri, 6 + c]
        out_ng[i, 0], out_ng[i, 1], out_ng[i, 2] = gx, gy, gz
        out_ns[i, 0], out_ns[i, 1], out_ns[i, 2] = sx, sy, sz
        return
    f = face - 16 if face >= 16 else face
    sgn = -1.0 if face >= 16 else 1.0
    ux, uy, uz = object_normal(geo.kinds, k, f, geo.ptype, geo.par, geo.aux, x, y, z, stack)
    wx = sgn * (nm[k, 0] * ux + nm[k, 1] * uy + nm[k, 2] * uz)
    wy = sgn * (nm[k, 3] * ux + nm[k, 4] * uy + nm[k, 5] * uz)
    wz = sgn * (nm[k, 6] * ux + nm[k, 7] * uy + nm[k, 8] * uz)
    gx, gy, gz = _normalize(wx, wy, wz)
    out_ng[i, 0], out_ng[i, 1], out_ng[i, 2] = gx, gy, gz
    out_ns[i, 0], out_ns[i, 1], out_ns[i, 2] = gx, gy, gz


# ----------------------------------------------------------------------------- batch kernels
@nb.njit(error_model="numpy")
def scratch():
    """Per-thread work arrays of :func:`closest`: the traversal stack (rows: entry distance,
    child code: a 4-wide node or a leaf; the triangles' traversal uses it from row 0, the
    analytic primitives' from row :data:`PRIM_STACK_BASE`, and the rows below that are also
    the operand stack (rows: value, gradient) of an isosurface's expression, evaluated inside
    the primitives' traversal, never inside the triangles') and the CSG stack of interval
    lists (times, signed primitive codes, faces, counts)."""
    return (np.empty((PRIM_STACK_BASE + BVH_STACK, 4)), np.empty((CSG_DEPTH, CSG_EVENTS)),
            np.empty((CSG_DEPTH, CSG_EVENTS), dtype=np.int64),
            np.empty((CSG_DEPTH, CSG_EVENTS), dtype=np.int64), np.empty(CSG_DEPTH, dtype=np.int64))


MAX_TASKS = 64
"""``prange`` tasks of a kernel call: each takes every ``MAX_TASKS``-th chunk of rays or block
of pixels and allocates its scratch arrays once (an allocation per chunk cost more than the
chunk's rays).  Enough for a fair split between threads; a constant, because a kernel that
asks numba for its thread count cannot be cached."""


@nb.njit(error_model="numpy", inline="always")
def _tasks(nchunks):
    return max(1, min(nchunks, MAX_TASKS))


@nb.njit(cache=True, error_model="numpy", parallel=True)
def trace_batch(geo, O, D, tmin, tmax, zero, rel_eps, extent, ncancel, shadow_only,
                t_out, prim_out, ng, ns, uv, po, ev):
    """Closest hits of N rays and their surface data (``prim_out = -1``, ``t = inf`` on a miss);
    with ``shadow_only``, of the primitives that cast shadows (shadow feelers)."""
    n = O.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    nit = _tasks(nchunks)
    for c in prange(nit):
        scr = scratch()
        for q in range(c, nchunks, nit):
            trace_chunk(geo, O, D, tmin, tmax, zero, rel_eps, extent, ncancel, shadow_only, t_out,
                        prim_out, ng, ns, uv, po, ev, q * CHUNK, min(n, (q + 1) * CHUNK), scr)


@nb.njit(**NO_REFCOUNT)
def trace_chunk(geo, O, D, tmin, tmax, zero, rel_eps, extent, ncancel, shadow_only, t_out, prim_out,
                ng, ns, uv, po, ev, i0, i1, scr):
    """Rays ``i0 .. i1 - 1`` of :func:`trace_batch` (``scr``: :func:`scratch`)."""
    stack, st, sp_, sf, sn = scr
    for i in range(i0, i1):
        ox, oy, oz = O[i, 0], O[i, 1], O[i, 2]
        eps = rel_eps * max(max(abs(ox), abs(oy), abs(oz)), extent)
        t, k, f, tri, b1, b2 = closest(geo, ox, oy, oz, D[i, 0], D[i, 1], D[i, 2], tmin[i],
                                       tmax[i], np.bool_(shadow_only), np.bool_(False), zero, eps, stack, st,
                                       sp_, sf, sn)
        t_out[i], prim_out[i] = t, k
        if k >= 0:
            surface(geo, k, f, tri, b1, b2, ox + t * D[i, 0], oy + t * D[i, 1],
                    oz + t * D[i, 2], ncancel, ng, ns, uv, po, ev, i, stack)


@nb.njit(error_model="numpy", inline="always")
def _transmittance(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmin, tmax, transmissive, zero,
                   eps, stack, st, sp_, sf, sn):
    """Shadow feeler: 1 if nothing blocks the segment, 0 if blocked (any hit ends the search);
    with ``transmissive``, the product of the ``kt`` of every surface crossed (at most
    ``SHADOW_CROSSINGS``)."""
    v = 1.0
    t0 = tmin
    for _ in range(SHADOW_CROSSINGS):
        t, k, f, tri, b1, b2 = closest(geo, ox, oy, oz, dx, dy, dz, t0, tmax, np.bool_(True), np.bool_(not transmissive),
                                       zero, eps, stack, st, sp_, sf, sn)
        if k < 0:
            return v
        if not transmissive:
            return 0.0
        v *= mat_tab[mat_of[k], 8]
        if v <= 0.0:
            return 0.0
        t0 = t + eps
    return v


@nb.njit(cache=True, error_model="numpy")
def accumulate(acc, pix, contrib):
    """``acc[pix[i]] += contrib[i]`` (serial: several rays may share a pixel)."""
    for i in range(pix.shape[0]):
        for c in range(3):
            acc[pix[i], c] += contrib[i, c]


@nb.njit(error_model="numpy", inline="always")
def _pow(base, n):
    if n == 0.0:
        return 1.0
    return base ** n


@nb.njit(error_model="numpy", inline="always")
def _ior(mat_tab, stk, ns_):
    return mat_tab[stk[ns_ - 1], 9] if ns_ > 0 else 1.0


@nb.njit(error_model="numpy", inline="always")
def fresnel_reflectance(fres, n1, n2, cosi, cost):
    """Reflected share F of light crossing from index ``n1`` to ``n2`` (``cosi``, ``cost``: the
    cosines of incidence and refraction): Schlick's approximation for ``fres == 1`` (cosine on the
    lower-index side; Schlick 1994), else the exact unpolarised Fresnel equations (mean of the
    s and p reflectances)."""
    if fres == 1:
        r0 = (n1 - n2) / (n1 + n2)
        r0 *= r0
        cc = cosi if n1 <= n2 else cost
        return r0 + (1.0 - r0) * (1.0 - cc) ** 5
    rs = (n1 * cosi - n2 * cost) / (n1 * cosi + n2 * cost)
    rp = (n2 * cosi - n1 * cost) / (n2 * cosi + n1 * cost)
    return 0.5 * (rs * rs + rp * rp)


@nb.njit(error_model="numpy", inline="always")
def _facing(nsh, i, dx, dy, dz):
    """The shading normal of hit ``i``, turned to face the viewer (two-sided shading)."""
    nx, ny, nz = nsh[i, 0], nsh[i, 1], nsh[i, 2]
    if nx * dx + ny * dy + nz * dz > 0.0:
        return -nx, -ny, -nz
    return nx, ny, nz


@nb.njit(error_model="numpy", inline="always")
def _light_dir(lights, li, px, py, pz):
    """Unit direction ``l`` from ``P`` to light ``li``, its distance (``inf`` for a directional
    light) and the light's factor there (1, ``1 / d^2`` when attenuated, times the spot
    factor).  Returns ``(lx, ly, lz, dist, scale)``."""
    if lights[li, 0] > 0.5:
        return -lights[li, 1], -lights[li, 2], -lights[li, 3], np.inf, 1.0
    vx, vy, vz = lights[li, 1] - px, lights[li, 2] - py, lights[li, 3] - pz
    dist = math.sqrt(vx * vx + vy * vy + vz * vz)
    lx, ly, lz = _normalize(vx, vy, vz)
    scale = 1.0
    if lights[li, 7] > 0.5:
        scale = 1.0 / max(dist * dist, 1e-300)
    if lights[li, 8] > 0.5:
        scale *= max(0.0, -(lx * lights[li, 9] + ly * lights[li, 10] + lz * lights[li, 11]))
    return lx, ly, lz, dist, scale


@nb.njit(error_model="numpy", inline="always")
def _feeler(px, py, pz, gx, gy, gz, lx, ly, lz, dist, off):
    """The shadow feeler towards ``l``: origin pushed ``off`` off the surface (geometric normal
    ``g``) on the light's side, and its end short of the light.  Returns ``(qx, qy, qz, tmax)``."""
    side = 1.0 if gx * lx + gy * ly + gz * lz >= 0.0 else -1.0
    tmx = dist - 2.0 * off if dist < np.inf else np.inf
    return px + side * off * gx, py + side * off * gy, pz + side * off * gz, tmx


@nb.njit(cache=True, error_model="numpy")
def feeler_batch(lights, O, D, t, prim, ng, nsh, opts, fo, fd, ftmin, ftmax, want):
    """The shadow feelers :func:`shade_hit` traces at each hit, one row per (hit ``i``, light
    ``li``): row ``i L + li`` of ``fo, fd, ftmin, ftmax``; ``want`` is False where it traces
    none (a miss, the light behind the shading normal, a zero light factor).  For a caller that
    traces them itself (opacity maps) and passes their visibility to :func:`shade_batch`."""
    nl = lights.shape[0]
    ray_off, t_min, extent = opts[8], opts[9], opts[11]
    for i in range(O.shape[0]):
        dx, dy, dz = D[i, 0], D[i, 1], D[i, 2]
        px, py, pz = O[i, 0] + t[i] * dx, O[i, 1] + t[i] * dy, O[i, 2] + t[i] * dz
        nx, ny, nz = _facing(nsh, i, dx, dy, dz)
        pm = max(abs(px), abs(py), abs(pz))
        off = ray_off * max(pm, extent)
        for li in range(nl):
            r = i * nl + li
            want[r] = False
            if prim[i] < 0:
                continue
            lx, ly, lz, dist, scale = _light_dir(lights, li, px, py, pz)
            if nx * lx + ny * ly + nz * lz <= 0.0 or scale == 0.0:
                continue
            qx, qy, qz, tmx = _feeler(px, py, pz, ng[i, 0], ng[i, 1], ng[i, 2], lx, ly, lz, dist, off)
            fo[r, 0], fo[r, 1], fo[r, 2] = qx, qy, qz
            fd[r, 0], fd[r, 1], fd[r, 2] = lx, ly, lz
            ftmin[r], ftmax[r] = t_min * max(pm, extent), tmx
            want[r] = True


@nb.njit(error_model="numpy", inline="always")
def shade_hit(geo, mat_of, mat_tab, lights, ambient, background, opts, rays, i, hits, contrib,
              out, s0, counts, scr):
    """Local model with shadow feelers at the hit of ray ``i``, then its reflected and refracted
    children (one step of the course's ``shade``).  Inlined into both drivers (a call with this
    many arrays cost more than the shading of a ray); the arrays come in tuples because Python
    passes a call of more than 30 arguments as ``*args``, which numba cannot inline.

    The ray is row ``i`` of ``rays = (O, D, w, depth, stk, nstk)`` and its hit row ``i`` of
    ``hits = (t, prim, ng, nsh, col, ev, vis)`` (``vis``: the lights' visibility through the
    shadow feelers, traced by the caller, or an empty table: traced here by
    :func:`_transmittance`); ``out = (out_o, out_d, out_w, out_stk, out_nstk,
    out_kind, out_tmin, out_gen)``; ``scr``: :func:`scratch`.  The local colour times the ray's weight goes to ``contrib[i]``, the
    children to slots ``s0`` (reflection) and ``s0 + 1`` (refraction) of the ``out_*`` arrays
    (``out_kind`` 0 = none, 1 reflected, 2 refracted), the counts to ``counts[i]``: shadow
    rays, ended by depth, ended by threshold, total internal reflections, reflected and
    refracted children, escaped (missed everything).

    ``opts``: max_depth, threshold, fresnel (0 none, 1 Schlick, 2 exact), transmissive shadows,
    blinn, shadows on, reflection on, refraction on, tol.ray_offset, tol.t_min, tol.zero,
    extent, misses see ``background`` (else they contribute nothing here: an environment map
    is evaluated by the caller), then (read by :func:`pixel_block`) the number of media around
    the camera and their materials, outermost first (4).
    """
    O, D, w, depth, stk, nstk = rays
    t, prim, ng, nsh, col, ev, vis_in = hits
    out_o, out_d, out_w, out_stk, out_nstk, out_kind, out_tmin, out_gen = out
    stack, st, sp_, sf, sn = scr
    max_depth, threshold, fres = int(opts[0]), opts[1], int(opts[2])
    transmissive, blinn = opts[3] > 0.5, opts[4] > 0.5
    do_shadow, do_refl, do_refr = opts[5] > 0.5, opts[6] > 0.5, opts[7] > 0.5
    ray_off, t_min, zero, extent = opts[8], opts[9], opts[10], opts[11]
    add_bg = opts[12] > 0.5
    nl = lights.shape[0]
    solid = geo.solid
    out_kind[s0], out_kind[s0 + 1] = 0, 0
    for q in range(7):
        counts[i, q] = 0
    k = prim[i]
    if k < 0:
        counts[i, 6] = 1
        for q in range(3):
            contrib[i, q] = w[i, q] * background[q] if add_bg else 0.0
        return
    mi = mat_of[k]
    dx, dy, dz = D[i, 0], D[i, 1], D[i, 2]
    px, py, pz = O[i, 0] + t[i] * dx, O[i, 1] + t[i] * dy, O[i, 2] + t[i] * dz
    # Beer-Lambert absorption by the medium the ray travelled through
    w0, w1, w2 = w[i, 0], w[i, 1], w[i, 2]
    if nstk[i] > 0:
        ma = stk[i, nstk[i] - 1]
        w0 *= math.exp(-mat_tab[ma, 10] * t[i])
        w1 *= math.exp(-mat_tab[ma, 11] * t[i])
        w2 *= math.exp(-mat_tab[ma, 12] * t[i])
    sx, sy, sz = -dx, -dy, -dz
    gx, gy, gz = ng[i, 0], ng[i, 1], ng[i, 2]
    nx, ny, nz = _facing(nsh, i, dx, dy, dz)
    front = gx * sx + gy * sy + gz * sz > 0.0
    # side of the surface the ray came from
    fx, fy, fz = (gx, gy, gz) if front else (-gx, -gy, -gz)
    if mat_tab[mi, 17] > 0.5:  # textured: the caller's colour
        cr, cg, cb = col[i, 0], col[i, 1], col[i, 2]
    else:
        cr, cg, cb = mat_tab[mi, 0], mat_tab[mi, 1], mat_tab[mi, 2]
    ka, kd, ks, shin = mat_tab[mi, 3], mat_tab[mi, 4], mat_tab[mi, 5], mat_tab[mi, 6]
    # vertex emission (radiosity patches of the hybrid method) leaves the front side only: the
    # back of a one-sided patch received no light (Mesh.vertex_emission)
    er, eg, eb = (ev[i, 0], ev[i, 1], ev[i, 2]) if front else (0.0, 0.0, 0.0)
    if mat_tab[mi, 16] < 0.5 or front:
        er, eg, eb = er + mat_tab[mi, 13], eg + mat_tab[mi, 14], eb + mat_tab[mi, 15]
    lr = ka * cr * ambient[0] + er
    lg = ka * cg * ambient[1] + eg
    lb = ka * cb * ambient[2] + eb
    pm = max(abs(px), abs(py), abs(pz))
    off = ray_off * max(pm, extent)
    eps = off
    nshadow = 0
    for li in range(nl):
        lx, ly, lz, dist, scale = _light_dir(lights, li, px, py, pz)
        ndl = nx * lx + ny * ly + nz * lz
        if ndl <= 0.0 or scale == 0.0:
            continue
        vis = 1.0
        if do_shadow:
            nshadow += 1
            if vis_in.shape[0] > 0:  # traced by the caller (opacity maps)
                vis = vis_in[i, li]
            else:
                qx, qy, qz, tmx = _feeler(px, py, pz, gx, gy, gz, lx, ly, lz, dist, off)
                vis = _transmittance(geo, mat_of, mat_tab, qx, qy, qz, lx, ly, lz,
                                     t_min * max(pm, extent), tmx, transmissive, zero, eps,
                                     stack, st, sp_, sf, sn)
            if vis <= 0.0:
                continue
        spec = 0.0
        if ks > 0.0:
            if blinn:
                hx, hy, hz = _normalize(lx + sx, ly + sy, lz + sz)
                base = nx * hx + ny * hy + nz * hz
            else:
                rx, ry, rz = 2.0 * ndl * nx - lx, 2.0 * ndl * ny - ly, 2.0 * ndl * nz - lz
                base = rx * sx + ry * sy + rz * sz
            base = min(1.0, max(0.0, base))
            spec = ks * _pow(base, shin)
        f = vis * scale
        lr += lights[li, 4] * f * (kd * cr * ndl + spec)
        lg += lights[li, 5] * f * (kd * cg * ndl + spec)
        lb += lights[li, 6] * f * (kd * cb * ndl + spec)
    contrib[i, 0], contrib[i, 1], contrib[i, 2] = w0 * lr, w1 * lg, w2 * lb
    counts[i, 0] = nshadow
    # ---- reflection / transmission weights (Whitted 1980; Fresnel optional)
    kr, kt = mat_tab[mi, 7], mat_tab[mi, 8]
    if not do_refl:
        kr = 0.0
    if not do_refr:
        kt = 0.0
    if kr <= 0.0 and kt <= 0.0:
        return
    cosi = -(dx * fx + dy * fy + dz * fz)  # >= 0
    ns_ = nstk[i]
    is_solid = solid[k]
    wr, wt = kr, kt
    tx, ty, tz = dx, dy, dz
    new_n = ns_
    if kt > 0.0 and is_solid:
        # media on both sides (nested dielectrics: a small stack of materials)
        if front:
            n1 = _ior(mat_tab, stk[i], ns_)
            n2 = mat_tab[mi, 9]
        else:
            n1 = mat_tab[mi, 9]
            # the medium beyond: the stack without its topmost entry of this material
            j = ns_ - 1
            while j >= 0 and stk[i, j] != mi:
                j -= 1
            n2 = 1.0
            if j >= 0:
                new_n = ns_ - 1
                top_ = -1
                for q in range(ns_ - 1, -1, -1):
                    if q != j:
                        top_ = stk[i, q]
                        break
                n2 = mat_tab[top_, 9] if top_ >= 0 else 1.0
            elif ns_ > 0:
                n2 = _ior(mat_tab, stk[i], ns_)
        eta = n1 / n2
        kk = 1.0 - eta * eta * (1.0 - cosi * cosi)
        if kk <= 0.0:  # total internal reflection (or exactly critical): all to reflection
            wr, wt = kr + kt, 0.0
            counts[i, 3] = 1
        else:
            cost = math.sqrt(kk)
            tx, ty, tz = _normalize(eta * dx + (eta * cosi - cost) * fx,
                                    eta * dy + (eta * cosi - cost) * fy,
                                    eta * dz + (eta * cosi - cost) * fz)
            if fres > 0:
                F = fresnel_reflectance(fres, n1, n2, cosi, cost)
                wr, wt = kr + kt * F, kt * (1.0 - F)
    for branch in range(2):
        kb = wr if branch == 0 else wt
        if kb <= 0.0:
            continue
        if depth[i] + 1 >= max_depth:
            counts[i, 1] += 1
            continue
        b0, b1_, b2_ = w0 * kb, w1 * kb, w2 * kb
        if max(b0, b1_, b2_) <= threshold:
            counts[i, 2] += 1
            continue
        s = s0 + branch
        if branch == 0:
            # R = I - 2 (I.N) N with the shading normal on the incident side
            mx, my, mz = nx, ny, nz
            dn = dx * mx + dy * my + dz * mz
            rx, ry, rz = dx - 2.0 * dn * mx, dy - 2.0 * dn * my, dz - 2.0 * dn * mz
            if rx * fx + ry * fy + rz * fz <= 0.0:  # below the surface: use Ng
                dn = dx * fx + dy * fy + dz * fz
                rx, ry, rz = dx - 2.0 * dn * fx, dy - 2.0 * dn * fy, dz - 2.0 * dn * fz
            rx, ry, rz = _normalize(rx, ry, rz)
            out_o[s, 0], out_o[s, 1], out_o[s, 2] = px + off * fx, py + off * fy, pz + off * fz
            out_d[s, 0], out_d[s, 1], out_d[s, 2] = rx, ry, rz
            for q in range(4):
                out_stk[s, q] = stk[i, q]
            out_nstk[s] = ns_
            out_kind[s] = 1
            counts[i, 4] += 1
        else:
            out_o[s, 0], out_o[s, 1], out_o[s, 2] = px - off * fx, py - off * fy, pz - off * fz
            out_d[s, 0], out_d[s, 1], out_d[s, 2] = tx, ty, tz
            for q in range(4):
                out_stk[s, q] = stk[i, q]
            out_nstk[s] = ns_
            if is_solid:
                if front:
                    if ns_ < 4:
                        out_stk[s, ns_] = mi
                        out_nstk[s] = ns_ + 1
                elif new_n < ns_:
                    # remove the topmost entry of this material
                    j = ns_ - 1
                    while stk[i, j] != mi:
                        j -= 1
                    q2 = 0
                    for q in range(ns_):
                        if q != j:
                            out_stk[s, q2] = stk[i, q]
                            q2 += 1
                    out_nstk[s] = ns_ - 1
            out_kind[s] = 2
            counts[i, 5] += 1
        out_w[s, 0], out_w[s, 1], out_w[s, 2] = b0, b1_, b2_
        out_tmin[s] = t_min * max(max(abs(out_o[s, 0]), abs(out_o[s, 1]), abs(out_o[s, 2])), extent)
        out_gen[s] = depth[i] + 1


@nb.njit(cache=True, error_model="numpy", parallel=True)
def shade_batch(geo, mat_of, mat_tab, lights, ambient, background, O, D, t, prim, ng, nsh, col, ev,
                vis, w, depth, stk, nstk, pix, opts, contrib, out_o, out_d, out_w, out_stk, out_nstk,
                out_kind, out_tmin, out_pix, out_gen, counts):
    """:func:`shade_hit` on every ray of a generation (the wavefront path).  Child slots:
    ``2 i`` (reflection), ``2 i + 1`` (refraction), with the parent's pixel ``out_pix``.
    ``vis``: (N, L) visibility of each light through the shadow feelers, traced by the caller
    (:func:`feeler_batch`), or (0, L): traced here."""
    n = O.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    nit = _tasks(nchunks)
    for c in prange(nit):
        scr = scratch()
        for q in range(c, nchunks, nit):
            shade_chunk(geo, mat_of, mat_tab, lights, ambient, background, O, D, t, prim, ng, nsh,
                        col, ev, vis, w, depth, stk, nstk, pix, opts, contrib, out_o, out_d, out_w,
                        out_stk, out_nstk, out_kind, out_tmin, out_pix, out_gen, counts, q * CHUNK,
                        min(n, (q + 1) * CHUNK), scr)


@nb.njit(**NO_REFCOUNT)
def shade_chunk(geo, mat_of, mat_tab, lights, ambient, background, O, D, t, prim, ng, nsh, col, ev,
                vis, w, depth, stk, nstk, pix, opts, contrib, out_o, out_d, out_w, out_stk, out_nstk,
                out_kind, out_tmin, out_pix, out_gen, counts, i0, i1, scr):
    """Rays ``i0 .. i1 - 1`` of :func:`shade_batch` (``scr``: :func:`scratch`)."""
    rays, hits = (O, D, w, depth, stk, nstk), (t, prim, ng, nsh, col, ev, vis)
    out = (out_o, out_d, out_w, out_stk, out_nstk, out_kind, out_tmin, out_gen)
    for i in range(i0, i1):
        shade_hit(geo, mat_of, mat_tab, lights, ambient, background, opts, rays, i, hits, contrib,
                  out, 2 * i, counts, scr)
        out_pix[2 * i] = pix[i]
        out_pix[2 * i + 1] = pix[i]


# ----------------------------------------------------------------------------- fused path
CHECKER_PLANAR, CHECKER_SOLID = 1, 2
"""``tex_tab`` kinds of the procedural textures the fused kernel evaluates itself."""
PIXEL_BLOCK = 64


@nb.njit(error_model="numpy", inline="always")
def checker_color(tex_tab, mi, x, y, z):
    """Texture factor of material ``mi`` at object-space point ``(x, y, z)``: the
    ``checker`` pattern of :func:`workbench.renderers.texturing.pattern_value` with the
    ``planar`` (``s = scale (d.Se, d.W)``) or ``solid`` (``s = scale d``) projection,
    ``d = P - center``.  ``tex_tab`` row: kind, scale, center (3), Se (3), W (3), colors (6)."""
    cx, cy, cz = x - tex_tab[mi, 2], y - tex_tab[mi, 3], z - tex_tab[mi, 4]
    sc = tex_tab[mi, 1]
    if tex_tab[mi, 0] == CHECKER_PLANAR:
        parity = (math.floor(sc * (cx * tex_tab[mi, 5] + cy * tex_tab[mi, 6] + cz * tex_tab[mi, 7]))
                  + math.floor(sc * (cx * tex_tab[mi, 8] + cy * tex_tab[mi, 9] + cz * tex_tab[mi, 10])))
    else:
        parity = math.floor(sc * cx) + math.floor(sc * cy) + math.floor(sc * cz)
    a = parity - 2.0 * math.floor(parity / 2.0)
    return (tex_tab[mi, 11] * (1.0 - a) + tex_tab[mi, 14] * a,
            tex_tab[mi, 12] * (1.0 - a) + tex_tab[mi, 15] * a,
            tex_tab[mi, 13] * (1.0 - a) + tex_tab[mi, 16] * a)


def render_pixels(geo, mat_of, mat_tab, tex_tab, lights, ambient, background, opts, O, D, spp,
                  fwd, cam, first, ncancel, image, depth_map, counts):
    """Whole ray trees of every pixel (the fused path): each pixel's ``spp`` primary rays
    (``O, D`` rows ``p spp ... p spp + spp - 1``; with ``O`` empty and ``spp = 1``, the centre
    ray of image pixel ``first + p`` of the camera ``cam``, see ``whitted.camera_frame``) and
    their reflected and refracted descendants are traced depth first (:func:`pixel_block`), so
    no array crosses back to Python between ray generations.

    Writes ``image[p]`` (mean over the samples), ``depth_map[p]`` (camera-space depth of the
    first sample's primary hit, ``fwd`` the unit view axis, ``inf`` on a miss) and adds the
    ray counts of :func:`shade_hit` to ``counts`` (7,).  Blocks of ``PIXEL_BLOCK`` pixels are
    dealt to a few tasks per thread in a scrambled order (:func:`pixels_task`, run on threads
    by :func:`..kernels.tasks.run_tasks`), so that each thread gets a fair share of the
    expensive parts of the image.
    """
    nblocks = (image.shape[0] + PIXEL_BLOCK - 1) // PIXEL_BLOCK
    stride = 1
    if nblocks > 2:  # a stride coprime with nblocks: c -> c * stride % nblocks is a permutation
        stride = nblocks // 2 + 1
        while math.gcd(stride, nblocks) != 1:
            stride += 1
    nit = max(1, min(nblocks, MAX_TASKS))
    part = np.zeros((nit, 8), np.int64)  # a row per task (8: rows a cache line apart)
    run_tasks(pixels_task, nit, geo, mat_of, mat_tab, tex_tab, lights, ambient, background, opts, O, D,
              spp, fwd, cam, first, ncancel, image, depth_map, part, stride)
    counts += part[:, :7].sum(axis=0)


@nb.njit(cache=True, error_model="numpy", nogil=True)
def pixels_task(geo, mat_of, mat_tab, tex_tab, lights, ambient, background, opts, O, D, spp, fwd, cam,
                first, ncancel, image, depth_map, part, stride, c, nit):
    """Task ``c`` of ``nit`` of :func:`render_pixels`: blocks ``c, c + nit, ...`` in the
    scrambled order ``b = k stride mod nblocks``; its ray counts go to ``part[c]``."""
    npix = image.shape[0]
    nblocks = (npix + PIXEL_BLOCK - 1) // PIXEL_BLOCK
    cap = 2 * int(opts[0]) + 2
    scr, bufs = scratch(), ray_stack(cap)
    for k in range(c, nblocks, nit):
        b = (k * stride) % nblocks
        pixel_block(geo, mat_of, mat_tab, tex_tab, lights, ambient, background, opts, O, D, spp,
                    fwd, cam, first, ncancel, image, depth_map, part[c], b * PIXEL_BLOCK,
                    min(npix, (b + 1) * PIXEL_BLOCK), scr, bufs)


@nb.njit(error_model="numpy", inline="always")
def camera_ray(cam, q, o, d):
    """Row 0 of ``o, d``: the centre ray of image pixel ``q`` (row-major) of the camera ``cam``
    (``whitted.camera_frame``: position, rotation, tan(fov_y / 2), aspect, width, height)."""
    width = int(cam[14])
    i, j = q // width, q % width
    x = ((j + 0.5) / cam[14] * 2.0 - 1.0) * cam[12] * cam[13]
    y = (1.0 - (i + 0.5) / cam[15] * 2.0) * cam[12]
    dx = x * cam[3] + y * cam[4] - cam[5]
    dy = x * cam[6] + y * cam[7] - cam[8]
    dz = x * cam[9] + y * cam[10] - cam[11]
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    o[0, 0], o[0, 1], o[0, 2] = cam[0], cam[1], cam[2]
    d[0, 0], d[0, 1], d[0, 2] = dx / n, dy / n, dz / n


@nb.njit(cache=True, error_model="numpy")
def ray_stack(cap):
    """Work arrays of :func:`pixel_block`: ``cap`` pending rays (origin, direction, weight,
    media stack and its size, kind, tmin, generation), then the current ray and its hit (one
    row each: origin, direction, weight, media stack and size, generation, t, primitive,
    normals, uv, object-space point, emission, colour, contribution, counts), the block's
    ray counts (summed here, written once: the threads' count rows share cache lines) and an
    empty visibility table (:func:`shade_hit` traces the shadow feelers itself)."""
    return (np.empty((cap, 3)), np.empty((cap, 3)), np.empty((cap, 3)), np.zeros((cap, 4), np.int64),
            np.zeros(cap, np.int64), np.zeros(cap, np.int64), np.empty(cap), np.zeros(cap, np.int64),
            np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 3)), np.zeros((1, 4), np.int64),
            np.zeros(1, np.int64), np.zeros(1, np.int64), np.empty(1), np.empty(1, np.int64),
            np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 2)), np.empty((1, 3)), np.empty((1, 3)),
            np.zeros((1, 3)), np.empty((1, 3)), np.zeros((1, 7), np.int64), np.zeros(7, np.int64),
            np.empty((0, 1)))


@nb.njit(**NO_REFCOUNT)
def pixel_block(geo, mat_of, mat_tab, tex_tab, lights, ambient, background, opts, O, D, spp, fwd,
                cam, first, ncancel, image, depth_map, counts, p0, p1, scr, bufs):
    """Pixels ``p0 .. p1 - 1`` of :func:`render_pixels`: each primary ray and its descendants
    depth first with an explicit stack of pending rays (the course's ``raytrace`` recursion),
    shaded by :func:`shade_hit`; textured colours from the ``tex_tab`` checkers
    (:func:`checker_color`).  Adds the ray counts to ``counts`` (7,).  ``scr``:
    :func:`scratch`; ``bufs``: :func:`ray_stack`."""
    zero, rel_eps, extent = opts[10], opts[8], opts[11]
    stack, st, sp_, sf, sn = scr
    (r_o, r_d, r_w, r_stk, r_n, r_kind, r_tmin, r_gen, c_o, c_d, c_w, c_stk, c_n, c_gen, h_t, h_p,
     h_ng, h_ns, h_uv, h_po, h_ev, h_col, contrib, cnt, tot, h_vis) = bufs
    row = 0  # the current ray's row
    cur = (c_o, c_d, c_w, c_gen, c_stk, c_n)
    hits = (h_t, h_p, h_ng, h_ns, h_col, h_ev, h_vis)
    pending = (r_o, r_d, r_w, r_stk, r_n, r_kind, r_tmin, r_gen)
    for p in range(p0, p1):
        ar, ag, ab = 0.0, 0.0, 0.0
        for s in range(spp):
            i = p * spp + s
            if O.shape[0] > 0:
                for q in range(3):
                    r_o[0, q], r_d[0, q] = O[i, q], D[i, q]
            else:
                camera_ray(cam, first + p, r_o, r_d)
            for q in range(3):
                r_w[0, q] = 1.0
            r_n[0], r_tmin[0], r_gen[0] = int(opts[13]), 0.0, 0  # the media around the camera
            for q in range(4):
                r_stk[0, q] = int(opts[14 + q])
            top = 1
            while top > 0:
                top -= 1
                for q in range(3):
                    c_o[0, q], c_d[0, q], c_w[0, q] = r_o[top, q], r_d[top, q], r_w[top, q]
                for q in range(4):
                    c_stk[0, q] = r_stk[top, q]
                c_n[0], c_gen[0] = r_n[top], r_gen[top]
                ox, oy, oz = c_o[0, 0], c_o[0, 1], c_o[0, 2]
                dx, dy, dz = c_d[0, 0], c_d[0, 1], c_d[0, 2]
                eps = rel_eps * max(max(abs(ox), abs(oy), abs(oz)), extent)
                t, k, f, tri, b1, b2 = closest(geo, ox, oy, oz, dx, dy, dz, r_tmin[top], np.inf,
                                               np.bool_(False), np.bool_(False), zero, eps, stack, st, sp_, sf, sn)
                h_t[0], h_p[0] = t, k
                if c_gen[0] == 0 and s == 0:
                    depth_map[p] = t * (dx * fwd[0] + dy * fwd[1] + dz * fwd[2]) if k >= 0 else np.inf
                if k >= 0:
                    surface(geo, k, f, tri, b1, b2, ox + t * dx, oy + t * dy, oz + t * dz, ncancel,
                            h_ng, h_ns, h_uv, h_po, h_ev, 0, stack)
                    mi = mat_of[k]
                    if mat_tab[mi, 17] > 0.5:
                        tr_, tg_, tb_ = checker_color(tex_tab, mi, h_po[0, 0], h_po[0, 1], h_po[0, 2])
                        h_col[0, 0] = mat_tab[mi, 0] * tr_
                        h_col[0, 1] = mat_tab[mi, 1] * tg_
                        h_col[0, 2] = mat_tab[mi, 2] * tb_
                shade_hit(geo, mat_of, mat_tab, lights, ambient, background, opts, cur, row, hits,
                          contrib, pending, top, cnt, scr)
                ar += contrib[0, 0]
                ag += contrib[0, 1]
                ab += contrib[0, 2]
                for q in range(7):
                    tot[q] += cnt[0, q]
                # keep the children that exist on the stack
                if r_kind[top] != 0:
                    top += 1
                    if r_kind[top] != 0:
                        top += 1
                elif r_kind[top + 1] != 0:
                    for q in range(3):
                        r_o[top, q], r_d[top, q], r_w[top, q] = r_o[top + 1, q], r_d[top + 1, q], r_w[top + 1, q]
                    for q in range(4):
                        r_stk[top, q] = r_stk[top + 1, q]
                    r_n[top], r_tmin[top], r_gen[top] = r_n[top + 1], r_tmin[top + 1], r_gen[top + 1]
                    top += 1
        image[p, 0], image[p, 1], image[p, 2] = ar / spp, ag / spp, ab / spp
    for q in range(7):
        counts[q] += tot[q]
        tot[q] = 0


@nb.njit(cache=True, error_model="numpy")
def compact(kind, o, d, w, stk, nstk, tmin, pix, gen):
    """The child rays that exist (``kind != 0``), in slot order, as new contiguous arrays
    (the next generation): ``(o, d, w, stk, nstk, tmin, pix, gen)``."""
    m = 0
    for s in range(kind.shape[0]):
        if kind[s] != 0:
            m += 1
    O, D, W = np.empty((m, 3)), np.empty((m, 3)), np.empty((m, 3))
    STK = np.empty((m, stk.shape[1]), np.int64)
    NSTK, TMIN = np.empty(m, np.int64), np.empty(m)
    PIX, GEN = np.empty(m, np.int64), np.empty(m, np.int64)
    j = 0
    for s in range(kind.shape[0]):
        if kind[s] == 0:
            continue
        for c in range(3):
            O[j, c], D[j, c], W[j, c] = o[s, c], d[s, c], w[s, c]
        for c in range(stk.shape[1]):
            STK[j, c] = stk[s, c]
        NSTK[j], TMIN[j], PIX[j], GEN[j] = nstk[s], tmin[s], pix[s], gen[s]
        j += 1
    return O, D, W, STK, NSTK, TMIN, PIX, GEN


@nb.njit(cache=True, error_model="numpy")
def column_sums(counts):
    """``counts.sum(0)`` of an (n, m) int64 array, row by row."""
    out = np.zeros(counts.shape[1], np.int64)
    for i in range(counts.shape[0]):
        for q in range(counts.shape[1]):
            out[q] += counts[i, q]
    return out
