"""Tree walks: the triangles' 4-wide BVH (watertight triangle tests four at a time, Woop,
Benthin & Wald, JCGT 2013) and the node visit shared with the analytic primitives' tree and
the traversal statistics.
"""
from __future__ import annotations

import numba as nb
import numpy as np

from .columns import WalkCount
from .flags import INLINE
from .layout import MAX_DEPTH
from .shapes import _normalize

BVH_STACK = 3 * MAX_DEPTH + 4
"""Rows of the 4-wide traversal's stack: at most three pending children per level (``layout.MAX_DEPTH``)."""
# Slab exits are enlarged by 1 + 2 gamma_3 (gamma_n = n u / (1 - n u), u = 2^-53) so that
# rounding never culls a box the ray touches (Ize, "Robust BVH ray traversal", JCGT 2013).
BOX_GAMMA = 1.0 + 2.0 * 3.0 * 2.0 ** -53 / (1.0 - 3.0 * 2.0 ** -53)
LANE = (np.int64(0), np.int64(1), np.int64(2), np.int64(3))
"""The lane arguments of the 4-wide helpers' calls, and the walks' starting values, are int64, not
Python literals: numba compiles a callee once per value of a literal argument (and, typing a
loop, once more for a literal start value before it widens to int64), for the same machine code
once the helper is inlined."""


@nb.njit(**INLINE)
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


@nb.njit(**INLINE)
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


@nb.njit(**INLINE)
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


@nb.njit(**INLINE)
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


@nb.njit(**INLINE)
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


@nb.njit(**INLINE)
def _push_sorted(stack, base, sp, t, code):
    """Push ``(t, code)`` on ``stack`` above row ``base``, keeping rows ``base..sp`` sorted
    with the nearest on top.  Returns the new height."""
    j = sp
    while j > base and stack[j - 1, 0] < t:
        stack[j, 0], stack[j, 1] = stack[j - 1, 0], stack[j - 1, 1]
        j -= 1
    stack[j, 0], stack[j, 1] = t, code
    return sp + 1


@nb.njit(**INLINE)
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


@nb.njit(**INLINE)
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


@nb.njit(**INLINE)
def open_node(tree, code, ray, best, stack, sp, top):
    """Visit of 4-wide node ``code`` of ``tree = (node, child)`` (the layout of
    :func:`.bvh.build_bvh4`: children's boxes ``(N4, 6, 4)``, children ``(N4, 4)``) by
    ``ray`` (:func:`node_ray`): the four children's boxes are tested side by side
    (:func:`box_lane`; an entry beyond ``best`` is a miss), the nearest hit child is visited
    next and the other hit children wait on ``stack`` above row ``sp`` (rows ``(entry
    distance, child)``, nearest on top; of equal entries the lower slot is visited first:
    :func:`_visit_child`), no higher than row ``top``.  The one node visit of the triangles'
    traversal (:func:`bvh_hit`), the analytic primitives' (:func:`prim_tree_walk`) and the
    traversal statistics' (:func:`bvh_walk` with counting).  Returns ``(sp, code)``: the
    new stack height and the child to visit next (``>= 0`` a node, ``<= -2`` a leaf, ``-1``
    none hit)."""
    node, child = tree
    pl, ox, oy, oz, ix, iy, iz, tmin = ray
    nd = np.uint64(code)
    t0 = box_lane(node, nd, LANE[0], pl, ox, oy, oz, ix, iy, iz, tmin, best)
    t1 = box_lane(node, nd, LANE[1], pl, ox, oy, oz, ix, iy, iz, tmin, best)
    t2 = box_lane(node, nd, LANE[2], pl, ox, oy, oz, ix, iy, iz, tmin, best)
    t3 = box_lane(node, nd, LANE[3], pl, ox, oy, oz, ix, iy, iz, tmin, best)
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
@nb.njit(**INLINE)
def bvh_hit(bvh, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack):
    """Closest (or any) triangle hit through the 4-wide BVH: :func:`bvh_walk` without counting,
    the one walk of the ray tracer, the path tracer and radiosity.  Returns ``(t, tri, b1, b2,
    group, lane)``: with where the hit triangle lies in the packed groups (``group = -1`` on a
    miss), its normal can be read from the group the walk has just tested, in the cache
    (:func:`triangle_normal` of ``tv4[group, :, lane]``), rather than from the triangle table; a
    caller that does not read them has them compiled away."""
    return bvh_walk(bvh, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack, False, stack[0])


@nb.njit(**INLINE)
def triangle_normal(v):
    """Unit normal ``(v1 - v0) x (v2 - v0)`` of the triangle ``v`` (9,) (x0 y0 z0 x1 ... z2):
    a row of the triangle table, or a lane of a packed group (``tv4[g, :, j]``, a copy of the
    row: the same values)."""
    e1x, e1y, e1z = v[3] - v[0], v[4] - v[1], v[5] - v[2]
    e2x, e2y, e2z = v[6] - v[0], v[7] - v[1], v[8] - v[2]
    return _normalize(e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x)


@nb.njit(**INLINE)
def bvh_walk(bvh, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, stack, count, cnt):
    """Closest (or any) triangle hit through the 4-wide BVH (:func:`.bvh.build_bvh4`): at each
    node the four children's boxes are tested together, the nearest hit child is visited next
    and the others wait on ``stack`` (rows ``(entry distance, child)``, nearest on top), skipped
    when popped if the best hit is now nearer than their box; a leaf's triangles are tested four
    at a time.  Returns ``(t, tri, b1, b2, group, lane)`` (the hit triangle's packed group,
    ``-1`` on a miss, and lane).  With ``count`` (the traversal statistics' pass,
    :mod:`..raytrace.traversal_stats`) it adds the 4-wide nodes visited to
    ``cnt[WalkCount.NODES]`` and the triangle tests (four per leaf group) to
    ``cnt[WalkCount.TESTS]`` (:class:`.columns.WalkCount`); :func:`bvh_hit` passes ``False``,
    and the counting compiles away."""
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
    best, bg, bl = tmax, np.int64(-1), LANE[0]
    top = stack.shape[0] - 1  # never reached (BVH_STACK); a bound all the same
    code, sp = LANE[0], LANE[0]  # int64 (see LANE)
    while True:
        while code >= 0:  # a 4-wide node
            if count:
                cnt[WalkCount.NODES] += 1
            sp, code = open_node((node, child), code, ray, best, stack, sp, top)
        if code < -1:  # a leaf
            lf = -2 - code
            for g in range(leaf[lf, 0], leaf[lf, 0] + leaf[lf, 1]):
                if count:
                    cnt[WalkCount.TESTS] += 4
                u0 = tri_lane(tv4, g, LANE[0], pk, okx, oky, okz, sx, sy, sz, tmin, best)
                u1 = tri_lane(tv4, g, LANE[1], pk, okx, oky, okz, sx, sy, sz, tmin, best)
                u2 = tri_lane(tv4, g, LANE[2], pk, okx, oky, okz, sx, sy, sz, tmin, best)
                u3 = tri_lane(tv4, g, LANE[3], pk, okx, oky, okz, sx, sy, sz, tmin, best)
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
        return np.inf, -1, 0.0, 0.0, bg, bl
    # barycentric weights of vertices 1 and 2: the edge functions over their sum
    U, V, W, _, _, _ = _edge_functions(tv4, bg, bl, pk, okx, oky, okz, sx, sy, sz)
    return best, first[bg] + bl, V / (U + V + W), W / (U + V + W), bg, bl
