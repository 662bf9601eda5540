"""The one intersector: the closest (or any) hit of a world ray over every primitive (the
unbounded ones one by one, the analytic primitives' tree, the triangles' BVH), coincident
surfaces resolved by :func:`nearer`, and the surface record of a hit (:func:`surface`).  Used
by the Whitted drivers, the path tracer and the traversal statistics.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic, overload

from ...scene.kinds import CSGNODE
from ...scene.kinds.csg import CSG_DEPTH, Par as CsgPar
from ...scene.kinds.expression import MAX_STACK
from .columns import WalkCount
from .flags import GATE, INLINE
from .shapes import CSG_EVENTS, _normalize, _to_object, csg_hit, object_normal, prim_hit
from .specialise import has
from .walks import BVH_STACK, _bounds_hit, bvh_hit, node_ray, open_node, triangle_normal


@nb.njit(**INLINE)
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
        t, code, f = csg_gate(geo, int(par[k, CsgPar.START]), int(par[k, CsgPar.LENGTH]), ox, oy, oz, dx, dy, dz,
                              tmin, tmax, zero, eps, (st, sp_, sf, sn), stack)
        return t, abs(code) - 1, f + (16 if code < 0 else 0)
    t, f = prim_hit(geo.kinds, k, ptype, par, geo.poly_v, aux, lo[0], lo[1], lo[2], lo[3], lo[4], lo[5],
                    lo[3] * inv_s, lo[4] * inv_s, lo[5] * inv_s, inv_s, tmin, tmax, zero,
                    st[0], sf[0], stack)
    return t, k, f


PRIM_STACK_BASE = max(BVH_STACK, MAX_STACK)
"""First row of the scratch stack used by the analytic primitives' traversal
(:func:`prim_tree_hit`): rows below it stay free for an isosurface's expression evaluator,
which runs inside that traversal."""


@nb.njit(**INLINE)
def prim_tree_hit(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, best, brow, shadow_only, any_hit, zero, eps,
                  stack, st, sp_, sf, sn):
    """Closest hit through the analytic primitives' 4-wide tree (:class:`.accel.PrimTree`;
    traversal as :func:`bvh_hit`'s, one primitive row per leaf item).  ``best``: the nearest
    hit so far (of row ``brow``, ``-1`` for none); a hit replaces it as :func:`nearer`
    says.  Returns ``(t, prim, face, row)``,
    ``row = -1`` if nothing replaced ``best``."""
    return prim_tree_walk(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, best, brow, shadow_only, any_hit, zero,
                          eps, stack, st, sp_, sf, sn, False, sn)


# ----------------------------------------------------------------------------- gates
# The walks below compile only for a scene that needs them (see ..kernels.specialise): CSG
# programs, the analytic primitive rows (their list and their tree), the triangles' tree.  A gate whose feature is absent
# is never reached (its caller tests the same data first) and compiles to a miss.

def csg_gate(geo, start, length, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, levels, stack):
    """:func:`csg_hit` if the scene has CSG nodes."""
    raise TypeError("csg_gate is callable from numba-compiled code only")


@overload(csg_gate, jit_options=GATE)
def _csg_gate(geo, start, length, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, levels, stack):
    on = has(geo.types[-1], "csg")  # geo.kinds' type

    def impl(geo, start, length, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, levels, stack):
        if on:
            return csg_hit(geo, start, length, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, levels, stack)
        return np.inf, 0, 0
    return impl


def analytic_gate(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, shadow_only, any_hit, zero, eps, stack,
                  st, sp_, sf, sn):
    """Nearest hit over the top-level analytic primitive rows if the scene has any (else a
    miss): the unbounded rows one by one, then the bounded ones' tree (:func:`prim_tree_hit`).
    Returns ``(t, prim, face, row)``, ``row = -1`` on a miss; with ``any_hit``, the first hit."""
    raise TypeError("analytic_gate is callable from numba-compiled code only")


@overload(analytic_gate, jit_options=INLINE)
def _analytic_gate(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, shadow_only, any_hit, zero, eps, stack,
                   st, sp_, sf, sn):
    on = has(geo.types[-1], "analytic")  # geo.kinds' type

    def impl(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, shadow_only, any_hit, zero, eps, stack,
             st, sp_, sf, sn):
        if on:
            return analytic_hit(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, shadow_only, any_hit, zero, eps,
                                stack, st, sp_, sf, sn)
        return tmax, -1, 0, np.int64(-1)
    return impl


def analytic_normal_gate(geo, k, f, x, y, z, stack):
    """:func:`.shapes.object_normal` of row ``k`` if the scene has analytic rows (a scene of
    triangles only never asks)."""
    raise TypeError("analytic_normal_gate is callable from numba-compiled code only")


@overload(analytic_normal_gate, jit_options=INLINE)
def _analytic_normal_gate(geo, k, f, x, y, z, stack):
    on = has(geo.types[-1], "analytic")

    def impl(geo, k, f, x, y, z, stack):
        if on:
            return object_normal(geo.kinds, k, f, geo.ptype, geo.par, geo.aux, x, y, z, stack)
        return 0.0, 0.0, 1.0
    return impl


def triangles_gate(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
    """:func:`.walks.bvh_hit` over the scene's triangles if it has any."""
    raise TypeError("triangles_gate is callable from numba-compiled code only")


@overload(triangles_gate, jit_options=INLINE)
def _triangles_gate(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
    on = has(geo.types[-1], "triangles")

    def impl(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
        if on:
            return bvh_hit((geo.bvh_node, geo.bvh_child, geo.bvh_leaf, geo.bvh_first, geo.bvh_tv4),
                           ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack)
        return np.inf, -1, 0.0, 0.0, np.int64(-1), np.int64(0)
    return impl


@nb.njit(**INLINE)
def prim_tree_walk(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, best, brow, shadow_only, any_hit, zero, eps,
                   stack, st, sp_, sf, sn, count, cnt):
    """:func:`prim_tree_hit`; with ``count`` (the traversal statistics' pass,
    :mod:`.traversal_stats`) it adds the 4-wide nodes visited to ``cnt[WalkCount.NODES]`` and
    the primitive tests to ``cnt[WalkCount.TESTS]`` (:class:`.columns.WalkCount`; the
    rendering kernels pass ``False``: no counting)."""
    shadow, pnode, pchild, pleaf, pref = geo.shadow, geo.pnode, geo.pchild, geo.pleaf, geo.pref
    # the ray as the box tests read it (three divisions) is made at the first node opened: a
    # tree of one leaf opens none (Whitted's scene: see _one_small_leaf)
    ray = node_ray(ox, oy, oz, 1.0, 1.0, 1.0, tmin)
    ready = False
    w = eps * inv_w  # coincidence window in ray parameter units (see :func:`nearer`)
    lim = reach(best, brow, w, tmax)
    lim_up = next_up(lim)  # a row's search reaches lim itself (once per change of lim)
    bp, bf, found = -1, 0, -1
    base = PRIM_STACK_BASE
    top_ = stack.shape[0] - 1
    code, sp = np.int64(0), np.int64(base)  # int64, not literals (see walks.LANE)
    if not count and pchild[0, 1] == -1 and pchild[0, 2] == -1 and pchild[0, 3] == -1:
        # a root of one child (a scene of at most a leaf of primitives): start at that child.
        # The root's box test would repeat the caller's test of the tree's box (and a box test
        # only culls: skipping one never changes a hit, each row is tested all the same)
        code = pchild[0, 0]
    while True:
        while code >= 0:
            if count:
                cnt[WalkCount.NODES] += 1
            if not ready:
                ray, ready = node_ray(ox, oy, oz, dx, dy, dz, tmin), True
            sp, code = open_node((pnode, pchild), code, ray, lim, stack, sp, top_)
        if code < -1:
            lf = -2 - code
            for q in range(pleaf[lf, 0], pleaf[lf, 0] + pleaf[lf, 1]):
                k = pref[q]
                if shadow_only and not shadow[k]:
                    continue
                if count:
                    cnt[WalkCount.TESTS] += 1
                # up to best and its window: a coincident surface of a lower row wins
                t, p, f = row_hit(geo, k, ox, oy, oz, dx, dy, dz, inv_w, tmin, lim_up,
                                  zero, eps, stack, st, sp_, sf, sn)
                if nearer(t, k, best, brow, w, tmax):
                    best, bp, bf, brow, found = t, p, f, k, k
                    lim = reach(best, brow, w, tmax)
                    lim_up = next_up(lim)
                    if any_hit:
                        return best, bp, bf, found
        code = -1
        while sp > base:
            sp -= 1
            if stack[sp, 0] <= lim:
                code = int(stack[sp, 1])
                break
        if code == -1:
            break
    return best, bp, bf, found


@intrinsic
def _bits(typingctx, x):
    """The bits of a float64 as an int64 (a register move; no libm call)."""
    def codegen(context, builder, sig, args):
        return builder.bitcast(args[0], ir.IntType(64))
    return types.int64(types.float64), codegen


@intrinsic
def _from_bits(typingctx, b):
    """The float64 of the bits ``b`` (inverse of :func:`_bits`)."""
    def codegen(context, builder, sig, args):
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.int64), codegen


@nb.njit(**INLINE)
def next_up(x):
    """``np.nextafter(x, inf)``, the next float64 above ``x``, without its libm call (once a
    ray, it cost the Whitted scene's trace 2 %): IEEE 754 orders the bit patterns of floats
    of one sign as integers."""
    if x != x or x == np.inf:
        return x
    if x == 0.0:
        return 5e-324
    b = _bits(x)
    return _from_bits(b + 1 if x > 0.0 else b - 1)


@nb.njit(**INLINE)
def nearer(t, k, best, brow, w, tmax):
    """Whether a hit at ``t < tmax`` of row ``k`` replaces the nearest so far (``best`` of row
    ``brow``, ``-1`` for none).  Two surfaces closer along the ray than ``w`` (the secondary
    rays' offset, relative to the scene's size: no ray can tell them apart) are coincident,
    such as a box's face resting on a floor: the lower row wins whatever the rounding says,
    so that the choice of one of two such surfaces does not change with the scene's scale or
    the traversal's order.  (Three surfaces within ``2 w`` of each other, or two coincident
    meshes, whose triangles the BVH walk compares by distance alone, are still decided by
    the order of the tests.)"""
    if brow < 0:
        return t < best
    return t < tmax and (t < best - w or (t <= best + w and k < brow))


@nb.njit(**INLINE)
def reach(best, brow, w, tmax):
    """How far a search must look past the nearest hit so far for a coincident surface of a
    lower row (:func:`nearer`), within ``tmax``."""
    return min(best + w, tmax) if brow >= 0 else best


SMALL_LEAF = 4
"""Rows of a primitives' tree made of one leaf (:func:`_one_small_leaf`) tested without the
tree's box test."""


@nb.njit(**INLINE)
def _one_small_leaf(pchild, pleaf):
    """Whether the analytic primitives' tree is one leaf of at most :data:`SMALL_LEAF` rows (a
    scene of a few primitives, as Whitted's): its box test, three divisions a ray, then costs
    more than it saves (it culls only rays that miss the whole scene, never a shadow feeler
    leaving a surface of the tree's), and a box test only culls, so skipping it changes no hit.
    :func:`prim_tree_walk` then opens no node, and makes no inverse direction for the box tests
    (three divisions more)."""
    return (pchild[0, 0] <= -2 and pchild[0, 1] == -1 and pchild[0, 2] == -1 and pchild[0, 3] == -1
            and pleaf[-2 - pchild[0, 0], 1] <= SMALL_LEAF)


@nb.njit(**INLINE)
def analytic_hit(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, shadow_only, any_hit, zero, eps, stack,
                 st, sp_, sf, sn):
    """:func:`analytic_gate`'s search: the unbounded rows one by one, then the analytic
    primitives' tree, coincident surfaces resolved by :func:`nearer`."""
    pfree, shadow = geo.pfree, geo.shadow
    best, bp, bf = tmax, -1, 0
    brow = np.int64(-1)  # int64, not a literal (see walks.LANE)
    w = eps * inv_w
    for q in range(pfree.shape[0]):
        k = pfree[q]
        if shadow_only and not shadow[k]:
            continue
        t, p, f = row_hit(geo, k, ox, oy, oz, dx, dy, dz, inv_w, tmin, reach(best, brow, w, tmax),
                          zero, eps, stack, st, sp_, sf, sn)
        if nearer(t, k, best, brow, w, tmax):
            best, bp, bf, brow = t, p, f, k
        if any_hit and bp >= 0:
            return best, bp, bf, brow
    if geo.pref.shape[0] > 0 and (_one_small_leaf(geo.pchild, geo.pleaf)
                                  or _bounds_hit(geo.pbounds, ox, oy, oz, dx, dy, dz, tmin, reach(best, brow, w, tmax))):
        t, p, f, row = prim_tree_hit(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, best, brow, shadow_only,
                                     any_hit, zero, eps, stack, st, sp_, sf, sn)
        if row >= 0:
            best, bp, bf, brow = t, p, f, row
    return best, bp, bf, brow


@nb.njit(**INLINE)
def closest(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, shadow_only, any_hit, unit, zero, eps, stack,
            st, sp_, sf, sn):
    """Nearest hit of a world ray over all primitives: the list of analytic primitives tested
    one by one, then the analytic primitives' structure, then the triangles' (see
    :mod:`.accel`).  Returns ``(t, prim, face, tri, b1, b2, nx, ny, nz)``; ``prim = -1`` on a
    miss, negative ``face`` is never returned (a flipped CSG normal is ``face + 16``); ``n`` a
    triangle hit's unit geometric normal (:func:`geometric_normal`'s), read from the packed
    group the walk has just tested (:func:`.walks.bvh_hit`), zero for other hits (a
    caller that does not read it has it compiled away).  One function, not a wrapper without
    the normal: each level of calls is linked and compiled again in its callers.

    ``unit``: the caller has just normalised the direction (the Whitted rays and their shadow
    feelers), so its length is taken as 1 rather than computed again: the square root and the
    division of ``1 / |d|`` head the dependent chain of every test, and the ray tracer's
    renormalisation cost its Whitted scene trace about 5 % (perf).  Else (a batch of rays of
    any length, the path tracer) ``1 / |d|`` is computed."""
    btri, bb1, bb2 = -1, 0.0, 0.0
    gx, gy, gz = 0.0, 0.0, 0.0
    inv_w = 1.0 if unit else 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    w = eps * inv_w
    best, bp, bf, brow = analytic_gate(geo, ox, oy, oz, dx, dy, dz, inv_w, tmin, tmax, np.bool_(shadow_only),
                                       np.bool_(any_hit), zero, eps, stack, st, sp_, sf, sn)
    if any_hit and bp >= 0:
        return best, bp, bf, btri, bb1, bb2, gx, gy, gz
    lim = reach(best, brow, w, tmax)
    if geo.tri_v.shape[0] > 0 and _bounds_hit(geo.bvh_bounds, ox, oy, oz, dx, dy, dz, tmin, lim):
        t, tri, b1, b2, g, lane = triangles_gate(geo, ox, oy, oz, dx, dy, dz, tmin, lim, np.bool_(any_hit), stack)
        if tri >= 0 and nearer(t, geo.tri_prim[tri], best, brow, w, tmax):
            best, bp, bf, btri, bb1, bb2 = t, geo.tri_prim[tri], 0, tri, b1, b2
            gx, gy, gz = triangle_normal(geo.bvh_tv4[g, :, lane])
    if bp < 0:
        return np.inf, -1, 0, -1, 0.0, 0.0, 0.0, 0.0, 0.0
    return best, bp, bf, btri, bb1, bb2, gx, gy, gz


@nb.njit(**INLINE)
def object_point(geo, k, px, py, pz):
    """The world point ``(px, py, pz)`` in row ``k``'s object space."""
    xf = geo.xf
    x = xf[k, 0] * px + xf[k, 1] * py + xf[k, 2] * pz + xf[k, 3]
    y = xf[k, 4] * px + xf[k, 5] * py + xf[k, 6] * pz + xf[k, 7]
    z = xf[k, 8] * px + xf[k, 9] * py + xf[k, 10] * pz + xf[k, 11]
    return x, y, z


@nb.njit(**INLINE)
def geometric_normal(geo, k, face, tri, x, y, z, stack):
    """Unit outward geometric normal (world space) at a hit of row ``k``: of triangle ``tri``
    (its edges' cross product), or of the analytic primitive's ``face`` at the object-space
    point ``(x, y, z)`` (:func:`object_point`; the inverse transpose ``nm`` takes it to world
    space; a flipped CSG face, ``face + 16``, turns it round).  ``stack``: scratch of an
    isosurface's gradient."""
    if tri >= 0:
        return triangle_normal(geo.tri_v[tri])
    nm = geo.nm
    f = face - 16 if face >= 16 else face
    sgn = -1.0 if face >= 16 else 1.0
    ux, uy, uz = analytic_normal_gate(geo, k, f, x, y, z, stack)
    if not geo.ident[k]:  # (an identity row's nm is the identity too: the same values without it)
        ux, uy, uz = (nm[k, 0] * ux + nm[k, 1] * uy + nm[k, 2] * uz, nm[k, 3] * ux + nm[k, 4] * uy + nm[k, 5] * uz,
                      nm[k, 6] * ux + nm[k, 7] * uy + nm[k, 8] * uz)
    return _normalize(sgn * ux, sgn * uy, sgn * uz)


@nb.njit(**INLINE)
def surface(geo, k, face, tri, b1, b2, px, py, pz, ncancel, out_ng, out_ns, out_uv, out_po, out_e, i,
            stack):
    """Geometric (outward) normal (:func:`geometric_normal`), shading normal, uv (meshes;
    analytic primitives leave the mapping to the texturing module), object-space point and
    vertex emission at a hit, written to row ``i`` of the output arrays (``stack``: scratch
    of an isosurface's gradient)."""
    tri_n, tri_uv, tri_e = geo.tri_n, geo.tri_uv, geo.tri_e
    x, y, z = object_point(geo, k, px, py, pz)
    out_po[i, 0], out_po[i, 1], out_po[i, 2] = x, y, z
    out_uv[i, 0], out_uv[i, 1] = 0.0, 0.0
    out_e[i, 0], out_e[i, 1], out_e[i, 2] = 0.0, 0.0, 0.0
    gx, gy, gz = geometric_normal(geo, k, face, tri, x, y, z, stack)
    out_ng[i, 0], out_ng[i, 1], out_ng[i, 2] = gx, gy, gz
    if tri >= 0:
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
        out_ns[i, 0], out_ns[i, 1], out_ns[i, 2] = sx, sy, sz
        return
    out_ns[i, 0], out_ns[i, 1], out_ns[i, 2] = gx, gy, gz


@nb.njit(cache=True, error_model="numpy")
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
