"""Bounding volume hierarchy over triangles: binned surface-area-heuristic build, then a
4-wide tree for the ray tracer's traversal.

Wald, "On fast construction of SAH-based bounding volume hierarchies" (IEEE RT 2007): at each
node the triangle centroids are binned (``N_BINS`` bins along each axis of the centroids'
box) and the split minimising ``C = A_L N_L + A_R N_R`` (areas of the child boxes, counts of
triangles, in groups of four for the triangles' tree: :data:`TRI_LEAF`) over the three axes
is taken if it beats a leaf (binning along the longest axis
only traced the mesh scene's rays 3 % slower).  Nodes are stored depth first: an inner
node's left child follows it, ``meta[i] = (right, 0, axis)``; a leaf is
``meta[i] = (first, count, -1)``.

The ray tracer traverses a 4-wide tree collapsed from the binary one (:func:`build_bvh4`:
Dammertz, Hanika & Keller, "Shallow bounding volume hierarchies for fast SIMD ray tracing of
incoherent rays", EGSR 2008; Wald, Benthin & Boulos, "Getting rid of packets", RT 2008): each
4-wide node holds its children's boxes side by side (``(N4, 6, 4)``: plane, then child), so
that one node visit tests four boxes in one vector instruction per plane, and each leaf's
triangles are packed by four in the same way (``(G, 9, 4)``).
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from contextlib import nullcontext
from typing import NamedTuple

import numba as nb
import numpy as np

from ..kernels.layout import MAX_DEPTH

N_BINS = 16
SMALL_NODE = 16
"""Items up to which a node bins its centroids into :data:`SMALL_NODE_BINS` bins only: such a
node holds at most four leaves' worth (``4 MAX_LEAF``; two of the triangles' ``TRI_LEAF``), its items fall into few of sixteen bins,
and clearing and sweeping the empty ones was most of its cost; the trees differ in a few small
nodes and their SAH cost hardly at all (``bench/accel.py`` gives the tree's SAH cost)."""
SMALL_NODE_BINS = 8
BIN_SAMPLES = 256
"""Items binned per node, about: a node of more bins a regular sample of them (see :func:`_build`)."""
MAX_LEAF = 4
"""Items up to which a node of the analytic primitives' tree (:func:`build_box_tree`) is a leaf
(its items are tested one by one)."""
GROUP = 4
"""Triangles tested side by side: the packed groups of :func:`build_bvh4`'s leaves."""
TRI_LEAF = 2 * GROUP
"""Triangles up to which a node of the triangles' tree is a leaf (two packed groups).  The
triangles' SAH counts a side's triangles in groups of :data:`GROUP` (rounded up: a group of
one triangle costs a test of four), so that the splits fill the groups: on the mesh scene
21,469 groups of 81,920 triangles (3.8 a group) instead of 26,209 (3.1) with the plain count
and leaves of four, 5,912 4-wide nodes instead of 14,148, the same camera-ray time (within
1 %) and a fifth less build time (measured, medians of 11)."""
# SAH cost of a traversal step relative to one triangle test (pbrt-v4 uses 1/2 as well).
TRAVERSAL_COST = 0.5


@nb.njit(cache=True)
def _area(b0, b1, b2, b3, b4, b5):
    dx, dy, dz = b3 - b0, b4 - b1, b5 - b2
    if dx < 0.0:
        return 0.0
    return dx * dy + dy * dz + dz * dx


@nb.njit(cache=True)
def _grow(acc, o, tb, k):
    """Grow the box ``acc[o:o + 6]`` by row ``k`` of ``tb`` and the centroid bounds
    ``acc[o + 6:o + 12]`` by that box's centre."""
    for a in range(3):
        lo, hi = tb[k, a], tb[k, 3 + a]
        c = 0.5 * (lo + hi)
        acc[o + a] = min(acc[o + a], lo)
        acc[o + 3 + a] = max(acc[o + 3 + a], hi)
        acc[o + 6 + a] = min(acc[o + 6 + a], c)
        acc[o + 9 + a] = max(acc[o + 9 + a], c)


@nb.njit(cache=True)
def _boxes_and_bounds(tri_v):
    """Each triangle's box ``(T, 6)`` (min xyz, max xyz) of the triangles ``tri_v`` (T, 9) and
    the boxes' box and centroid bounds (12,) (:func:`_root_bounds`), in one pass."""
    T = tri_v.shape[0]
    tb = np.empty((T, 6))
    acc = np.empty(12)
    for a in range(3):
        acc[a], acc[3 + a], acc[6 + a], acc[9 + a] = np.inf, -np.inf, np.inf, -np.inf
    for i in range(T):
        for a in range(3):
            tb[i, a] = min(tri_v[i, a], tri_v[i, 3 + a], tri_v[i, 6 + a])
            tb[i, 3 + a] = max(tri_v[i, a], tri_v[i, 3 + a], tri_v[i, 6 + a])
        _grow(acc, 0, tb, i)
    return tb, acc


def triangle_boxes(tri_v):
    """Each triangle's box ``(T, 6)`` (min xyz, max xyz) of the triangles ``tri_v`` (T, 9)."""
    return _boxes_and_bounds(tri_v)[0]


@nb.njit(cache=True)
def _root_bounds(tb):
    """(12,) box and centroid bounds of all the boxes ``tb`` (T, 6)."""
    acc = np.empty(12)
    for a in range(3):
        acc[a], acc[3 + a], acc[6 + a], acc[9 + a] = np.inf, -np.inf, np.inf, -np.inf
    for k in range(tb.shape[0]):
        _grow(acc, 0, tb, k)
    return acc


@nb.njit(cache=True, forceinline=True)
def _bin_item(bin_box, bin_cnt, ax, b, l0, l1, l2, h0, h1, h2):
    """Add the box ``(l0, l1, l2, h0, h1, h2)`` to bin ``b`` of axis ``ax`` (:func:`_build_nodes`)."""
    bin_cnt[ax, b] += 1
    bin_box[ax, b, 0] = min(bin_box[ax, b, 0], l0)
    bin_box[ax, b, 1] = min(bin_box[ax, b, 1], l1)
    bin_box[ax, b, 2] = min(bin_box[ax, b, 2], l2)
    bin_box[ax, b, 3] = max(bin_box[ax, b, 3], h0)
    bin_box[ax, b, 4] = max(bin_box[ax, b, 4], h1)
    bin_box[ax, b, 5] = max(bin_box[ax, b, 5], h2)


@nb.njit(cache=True, nogil=True)
def _build_nodes(tb, idx, s0, e0, depth0, bounds0, limit, leaf_max, block):
    """The binned SAH build (module docstring) of the items ``[s0, e0)`` of ``tb`` (T, 6) and
    ``idx`` (T,), reordered in place, from a node at depth ``depth0`` with box and centroid
    bounds ``bounds0`` (12,); at most ``limit`` nodes are made.  A node of at most ``leaf_max``
    items is a leaf; the SAH counts items in blocks of ``block`` (rounded up: 1 for items tested
    one by one, :data:`GROUP` for the packed triangles), and a node of at most ``4 leaf_max``
    items is a leaf where the SAH says a split costs as much.  Returns the nodes' boxes
    (n, 6) and meta (n, 3) (numbered from 0 at this range's root; leaves' ``first`` index
    ``tb``; views of the arrays allocated for ``limit`` nodes, not copied: the caller's
    concatenation or collapse copies them) and the nodes still pending (k, 5) ``(start, end,
    parent, is_right, depth)`` with their bounds (k, 12), right child first: none unless the
    limit was reached.
    The boxes are kept in the order of ``idx`` (swapped with it), so that every pass over a
    node's range reads memory in sequence; a box's centroid (its centre) is recomputed where
    needed rather than stored and swapped beside it (less memory traffic, the same values); a
    node's box and centroid bounds come from its parent's partition, and one pass bins the
    centroids along the three axes at once (into :data:`SMALL_NODE_BINS` bins for a node of at most
    :data:`SMALL_NODE` items).  A node of more than ``2 BIN_SAMPLES`` items bins
    every ``(n // BIN_SAMPLES)``-th of them only (the SAH estimated from a regular sample,
    Wald 2007; the partition is exact): on the mesh scene the binary tree's SAH cost rises
    0.1 % and the build's CPU time falls by about a sixth."""
    cap = min(max(2 * (e0 - s0), 1), max(limit, 1))
    box = np.empty((cap, 6))
    meta = np.zeros((cap, 3), dtype=np.int64)
    stack = np.empty((MAX_DEPTH + 2, 5), dtype=np.int64)  # start, end, parent, is_right, depth
    bounds = np.empty((MAX_DEPTH + 2, 12))  # each pending node's box and centroid bounds
    acc = np.empty(24)  # two running boxes and centroid bounds (left at 0, right at 12)
    bounds[0, :] = bounds0
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3], stack[0, 4] = s0, e0, -1, 0, depth0
    sp = 1
    n_nodes = 0
    bin_box = np.empty((3, N_BINS, 6))
    bin_cnt = np.zeros((3, N_BINS), dtype=np.int64)
    right_area = np.empty(N_BINS)
    right_cnt = np.empty(N_BINS, dtype=np.int64)
    sweep = np.empty(6)  # running box of the sweeps
    cmin = np.empty(3)
    ext = np.empty(3)
    scale = np.zeros(3)
    while sp > 0 and n_nodes < cap:
        sp -= 1
        s, e, parent, is_right, depth = stack[sp, 0], stack[sp, 1], stack[sp, 2], stack[sp, 3], stack[sp, 4]
        node = n_nodes
        n_nodes += 1
        if is_right == 1:
            meta[parent, 0] = node
        for a in range(6):
            box[node, a] = bounds[sp, a]
        for a in range(3):
            cmin[a] = bounds[sp, 6 + a]
            ext[a] = bounds[sp, 9 + a] - cmin[a]
        n = e - s
        if n <= leaf_max or not max(ext[0], ext[1], ext[2]) > 0.0 or depth >= MAX_DEPTH:
            meta[node, 0], meta[node, 1], meta[node, 2] = s, n, -1
            continue
        # bin the centroids along the three axes in one pass
        nb_ = N_BINS if n > SMALL_NODE else SMALL_NODE_BINS
        for ax in range(3):
            scale[ax] = nb_ * (1.0 - 1e-9) / ext[ax] if ext[ax] > 0.0 else 0.0
            for b in range(nb_):
                bin_cnt[ax, b] = 0
                for a in range(3):
                    bin_box[ax, b, a], bin_box[ax, b, 3 + a] = np.inf, -np.inf
        # (the box, origins and scales in local variables: the compiler cannot keep them in
        # registers across the stores into the bins, which might alias them)
        m0, m1, m2, q0, q1, q2 = cmin[0], cmin[1], cmin[2], scale[0], scale[1], scale[2]
        for k in range(s, e, max(1, n // BIN_SAMPLES)):
            l0, l1, l2, h0, h1, h2 = tb[k, 0], tb[k, 1], tb[k, 2], tb[k, 3], tb[k, 4], tb[k, 5]
            if q0 != 0.0:
                _bin_item(bin_box, bin_cnt, 0, int((0.5 * (l0 + h0) - m0) * q0), l0, l1, l2, h0, h1, h2)
            if q1 != 0.0:
                _bin_item(bin_box, bin_cnt, 1, int((0.5 * (l1 + h1) - m1) * q1), l0, l1, l2, h0, h1, h2)
            if q2 != 0.0:
                _bin_item(bin_box, bin_cnt, 2, int((0.5 * (l2 + h2) - m2) * q2), l0, l1, l2, h0, h1, h2)
        # sweep each axis from the right, then from the left
        best, best_b, axis = np.inf, -1, 0
        for ax in range(3):
            if not ext[ax] > 0.0:
                continue
            for a in range(3):
                sweep[a], sweep[3 + a] = np.inf, -np.inf
            cnt = 0
            for b in range(nb_ - 1, 0, -1):
                if bin_cnt[ax, b] == 0 and b < nb_ - 1:  # an empty bin changes nothing
                    right_area[b], right_cnt[b] = right_area[b + 1], cnt
                    continue
                for a in range(3):
                    sweep[a] = min(sweep[a], bin_box[ax, b, a])
                    sweep[3 + a] = max(sweep[3 + a], bin_box[ax, b, 3 + a])
                cnt += bin_cnt[ax, b]
                right_area[b] = _area(sweep[0], sweep[1], sweep[2], sweep[3], sweep[4], sweep[5])
                right_cnt[b] = cnt
            for a in range(3):
                sweep[a], sweep[3 + a] = np.inf, -np.inf
            cnt = 0
            for b in range(nb_ - 1):
                if bin_cnt[ax, b] == 0:  # the split of the bin before, at the same cost: not a new one
                    continue
                for a in range(3):
                    sweep[a] = min(sweep[a], bin_box[ax, b, a])
                    sweep[3 + a] = max(sweep[3 + a], bin_box[ax, b, 3 + a])
                cnt += bin_cnt[ax, b]
                if cnt == 0 or right_cnt[b + 1] == 0:
                    continue
                c = (_area(sweep[0], sweep[1], sweep[2], sweep[3], sweep[4], sweep[5]) * ((cnt + block - 1) // block)
                     + right_area[b + 1] * ((right_cnt[b + 1] + block - 1) // block))
                if c < best:
                    best, best_b, axis = c, b, ax
        parent_area = _area(box[node, 0], box[node, 1], box[node, 2], box[node, 3], box[node, 4], box[node, 5])
        leaf_cost = float((n + block - 1) // block)
        split_cost = TRAVERSAL_COST + best / max(parent_area, 1e-300)
        if best_b < 0 or (split_cost >= leaf_cost and n <= 4 * leaf_max):
            meta[node, 0], meta[node, 1], meta[node, 2] = s, n, -1
            continue
        # partition [s, e) by bin (idx and boxes swapped together), growing each
        # side's box and centroid bounds as its triangles are placed
        # (the two running boxes and centroid bounds in local variables, as the bins above)
        sc, cm = scale[axis], cmin[axis]
        La0 = La1 = La2 = Lc0 = Lc1 = Lc2 = Ra0 = Ra1 = Ra2 = Rc0 = Rc1 = Rc2 = np.inf
        Lb0 = Lb1 = Lb2 = Ld0 = Ld1 = Ld2 = Rb0 = Rb1 = Rb2 = Rd0 = Rd1 = Rd2 = -np.inf
        lo, hi = s, e - 1
        while lo <= hi:
            l0, l1, l2, h0, h1, h2 = tb[lo, 0], tb[lo, 1], tb[lo, 2], tb[lo, 3], tb[lo, 4], tb[lo, 5]
            c0, c1, c2 = 0.5 * (l0 + h0), 0.5 * (l1 + h1), 0.5 * (l2 + h2)
            c = c0 if axis == 0 else (c1 if axis == 1 else c2)
            if int((c - cm) * sc) <= best_b:
                La0, La1, La2, Lb0, Lb1, Lb2 = min(La0, l0), min(La1, l1), min(La2, l2), max(Lb0, h0), max(Lb1, h1), max(Lb2, h2)
                Lc0, Lc1, Lc2, Ld0, Ld1, Ld2 = min(Lc0, c0), min(Lc1, c1), min(Lc2, c2), max(Ld0, c0), max(Ld1, c1), max(Ld2, c2)
                lo += 1
            else:  # to the right end: the item there comes here and is tested next
                idx[lo], idx[hi] = idx[hi], idx[lo]
                for a in range(6):
                    tb[lo, a] = tb[hi, a]
                tb[hi, 0], tb[hi, 1], tb[hi, 2], tb[hi, 3], tb[hi, 4], tb[hi, 5] = l0, l1, l2, h0, h1, h2
                Ra0, Ra1, Ra2, Rb0, Rb1, Rb2 = min(Ra0, l0), min(Ra1, l1), min(Ra2, l2), max(Rb0, h0), max(Rb1, h1), max(Rb2, h2)
                Rc0, Rc1, Rc2, Rd0, Rd1, Rd2 = min(Rc0, c0), min(Rc1, c1), min(Rc2, c2), max(Rd0, c0), max(Rd1, c1), max(Rd2, c2)
                hi -= 1
        mid = lo
        acc[0], acc[1], acc[2], acc[3], acc[4], acc[5] = La0, La1, La2, Lb0, Lb1, Lb2
        acc[6], acc[7], acc[8], acc[9], acc[10], acc[11] = Lc0, Lc1, Lc2, Ld0, Ld1, Ld2
        acc[12], acc[13], acc[14], acc[15], acc[16], acc[17] = Ra0, Ra1, Ra2, Rb0, Rb1, Rb2
        acc[18], acc[19], acc[20], acc[21], acc[22], acc[23] = Rc0, Rc1, Rc2, Rd0, Rd1, Rd2
        meta[node, 1], meta[node, 2] = 0, axis
        # push right then left: the left child is popped next and gets index node + 1 (at most
        # one pending right child per level: the stack holds MAX_DEPTH + 2)
        stack[sp, 0], stack[sp, 1], stack[sp, 2], stack[sp, 3], stack[sp, 4] = mid, e, node, 1, depth + 1
        bounds[sp, :] = acc[12:]
        sp += 1
        stack[sp, 0], stack[sp, 1], stack[sp, 2], stack[sp, 3], stack[sp, 4] = s, mid, node, 0, depth + 1
        bounds[sp, :] = acc[:12]
        sp += 1
    return box[:n_nodes], meta[:n_nodes], stack[:sp].copy(), bounds[:sp].copy()


PARALLEL_MIN = 4096
"""Items from which the root's two subtrees are built at once (two threads; numba ``nogil``)."""
SMALL_BUILD = 128
"""Items up to which :func:`_build` and :func:`_collapse` run as plain Python (the numba
dispatchers' ``py_func``: the same code, so the same tree): a scene of a few primitives
(the Cornell box's boxes and rectangles) builds its tree in milliseconds without compiling
the builder, which costs seconds on an empty numba cache."""


def _kernel(fn, n: int):
    """``fn`` itself, or its Python function for at most :data:`SMALL_BUILD` items."""
    return fn.py_func if n <= SMALL_BUILD else fn


def _build(tb: np.ndarray, b0: np.ndarray | None = None, pool: ThreadPoolExecutor | None = None,
           leaf_max: int = MAX_LEAF, block: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The binned SAH build over boxes ``tb`` (T, 6), reordered in place, whose box and centroid
    bounds are ``b0`` (12,) (computed here if ``None``), leaves and SAH counts as ``leaf_max``
    and ``block`` say (:func:`_build_nodes`): ``(order (T,), box (n, 6), meta (n, 3))`` as
    :func:`build_bvh`.  From :data:`PARALLEL_MIN` items the root
    is split alone and its two subtrees are built at once, the left one by ``pool``'s thread (a
    new one if ``None``), the right one by the calling thread; their nodes are renumbered
    into the depth-first order one thread gives (left subtree after the root, then the right),
    so the tree is the same node for node."""
    T = tb.shape[0]
    idx = np.arange(T)
    if b0 is None:
        b0 = _kernel(_root_bounds, T)(tb)
    if T < PARALLEL_MIN:
        box, meta, _, _ = _kernel(_build_nodes, T)(tb, idx, 0, T, 0, b0, 2 * T, leaf_max, block)
        return idx, box, meta
    rbox, rmeta, pending, pbounds = _build_nodes(tb, idx, 0, T, 0, b0, 1, leaf_max, block)
    if len(pending) == 0:  # the root is a leaf
        return idx, rbox, rmeta
    (s_r, e_r, _, _, d_r), (s_l, e_l, _, _, d_l) = pending
    with ThreadPoolExecutor(max_workers=1) if pool is None else nullcontext(pool) as ex:
        left = ex.submit(_build_nodes, tb, idx, s_l, e_l, d_l, pbounds[1], 2 * (e_l - s_l), leaf_max, block)
        rbox_, rmeta_, _, _ = _build_nodes(tb, idx, s_r, e_r, d_r, pbounds[0], 2 * (e_r - s_r), leaf_max,
                                            block)
        lbox, lmeta, _, _ = left.result()
    n_left = len(lbox)
    lmeta[lmeta[:, 2] != -1, 0] += 1               # inner nodes' right children: renumbered
    rmeta_[rmeta_[:, 2] != -1, 0] += 1 + n_left    # (leaves' first items index tb already)
    rmeta[0, 0] = 1 + n_left
    return idx, np.concatenate([rbox, lbox, rbox_]), np.concatenate([rmeta, lmeta, rmeta_])


def build_bvh(tri_v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Build the BVH of triangles (leaves of up to :data:`TRI_LEAF`, the SAH counting in groups
    of :data:`GROUP`).

    Parameters
    ----------
    tri_v : (T, 9) float64 triangle vertices (x0 y0 z0 x1 ... z2).

    Returns
    -------
    order : (T,) permutation: leaf ranges index ``tri_v[order]``.
    box : (Nn, 6) node bounds (min xyz, max xyz).
    meta : (Nn, 3) int64, leaf ``(first, count, -1)``, inner ``(right child, 0, axis)``.
    """
    tb, b0 = _boxes_and_bounds(np.ascontiguousarray(tri_v, dtype=np.float64))
    return _build(tb, b0, leaf_max=TRI_LEAF, block=GROUP)


@nb.njit(cache=True)
def _collapse(box, meta):
    """4-wide nodes from the binary tree: a node takes its binary node's two children and opens
    the inner child of largest surface area until it has four (or only leaves).  Returns the
    children's boxes ``(N4, 6, 4)`` (empty slots: min ``+inf``, max ``-inf``, never hit),
    the children ``(N4, 4)`` (a 4-wide node ``>= 0``, leaf ``l`` as ``-2 - l``, an empty slot
    ``-1``) and the leaves ``(L, 2)`` ``(first triangle, count)``; nodes in depth-first order."""
    n2 = box.shape[0]
    cap = max(1, n2 // 2)  # inner nodes: (n2 - 1) / 2, each 4-wide node uses at least one
    nbox = np.empty((cap, 6, 4))
    child = np.full((cap, 4), -1, dtype=np.int64)
    leaf = np.empty((n2, 2), dtype=np.int64)
    todo = np.empty((cap, 2), dtype=np.int64)  # (binary node, its 4-wide node)
    todo[0, 0], todo[0, 1] = 0, 0
    sp, n4, nl = 1, 1, 0
    ch = np.empty(4, dtype=np.int64)
    while sp > 0:
        sp -= 1
        b, q = todo[sp, 0], todo[sp, 1]
        if meta[b, 2] == -1:  # the root is a leaf
            ch[0], nch = b, 1
        else:
            ch[0], ch[1], nch = b + 1, meta[b, 0], 2
        while nch < 4:
            widest, wa = -1, -1.0
            for j in range(nch):
                c = ch[j]
                if meta[c, 2] != -1:
                    a = _area(box[c, 0], box[c, 1], box[c, 2], box[c, 3], box[c, 4], box[c, 5])
                    if a > wa:
                        widest, wa = j, a
            if widest < 0:
                break
            c = ch[widest]
            ch[widest], ch[nch] = c + 1, meta[c, 0]
            nch += 1
        for j in range(4):
            if j >= nch:
                for a in range(3):
                    nbox[q, a, j], nbox[q, 3 + a, j] = np.inf, -np.inf
                continue
            c = ch[j]
            for a in range(6):
                nbox[q, a, j] = box[c, a]
            if meta[c, 2] == -1:
                leaf[nl, 0], leaf[nl, 1] = meta[c, 0], meta[c, 1]
                child[q, j] = -2 - nl
                nl += 1
            else:
                child[q, j] = n4
                todo[sp, 0], todo[sp, 1] = c, n4
                sp += 1
                n4 += 1
    return nbox[:n4].copy(), child[:n4].copy(), leaf[:nl].copy()


@nb.njit(cache=True, nogil=True)
def _pack_range(tri_v, order, leaf, groups, l0, l1, tv4, first):
    """Leaves ``l0 .. l1 - 1`` of :func:`_pack_leaves` into their groups (``groups[l, 0]``
    onwards) of ``tv4`` and ``first``."""
    for l in range(l0, l1):
        s0, cnt, g = leaf[l, 0], leaf[l, 1], groups[l, 0]
        for s in range(s0, s0 + cnt, 4):
            c = min(4, s0 + cnt - s)
            for j in range(4):
                i = order[s + min(j, c - 1)]
                for a in range(9):
                    tv4[g, a, j] = tri_v[i, a]
            first[g] = s
            g += 1


def _pack_leaves(tri_v, order, leaf, pool: ThreadPoolExecutor | None = None):
    """Each leaf's triangles (``tri_v[order[first:first + count]]``) by groups of four,
    coordinates side by side: ``(G, 9, 4)``; a group of fewer than four repeats its last
    triangle (the same hit, never a new one).  Returns the groups, each group's first triangle
    (BVH order) ``(G,)`` and each leaf's ``(first group, group count)`` ``(L, 2)``.  With
    ``pool``, its thread packs the second half of the groups while the calling thread packs
    the first."""
    counts = (leaf[:, 1] + 3) // 4
    groups = np.empty((len(leaf), 2), dtype=np.int64)
    groups[:, 1] = counts
    groups[:, 0] = np.cumsum(counts) - counts
    G = int(counts.sum())
    tv4 = np.empty((G, 9, 4))
    first = np.empty(G, dtype=np.int64)
    pack = _kernel(_pack_range, len(tri_v))
    if pool is None:
        pack(tri_v, order, leaf, groups, 0, len(leaf), tv4, first)
    else:
        half = int(np.searchsorted(groups[:, 0], G // 2))
        rest = pool.submit(pack, tri_v, order, leaf, groups, half, len(leaf), tv4, first)
        pack(tri_v, order, leaf, groups, 0, half, tv4, first)
        rest.result()
    return tv4, first, groups


class Bvh4(NamedTuple):
    """The ray tracer's 4-wide BVH over triangles in BVH order (see :func:`build_bvh4`)."""
    node: np.ndarray    # (N4, 6, 4) children's boxes: plane (min xyz, max xyz), child
    child: np.ndarray   # (N4, 4) int64: 4-wide node >= 0, leaf l as -2 - l, empty -1
    leaf: np.ndarray    # (L, 2) int64: (first group, group count)
    first: np.ndarray   # (G,) int64: first triangle of each group
    tv4: np.ndarray     # (G, 9, 4) group vertices: coordinate, triangle
    bounds: np.ndarray  # (6,) the whole tree's box (min xyz, max xyz)


def build_bvh4(tri_v: np.ndarray) -> tuple[np.ndarray, Bvh4]:
    """The binned SAH tree of :func:`build_bvh`, collapsed to 4-wide nodes, with the leaves'
    triangles packed by four.

    Parameters
    ----------
    tri_v : (T, 9) float64 triangle vertices.

    Returns
    -------
    order : (T,) permutation: the BVH's triangle ``i`` is ``tri_v[order[i]]``.
    bvh : :class:`Bvh4` over ``tri_v[order]``.
    """
    tri_v = np.ascontiguousarray(tri_v, dtype=np.float64)
    T = len(tri_v)
    with ThreadPoolExecutor(max_workers=1) if T >= PARALLEL_MIN else nullcontext() as pool:
        order, box, meta = _build(*_kernel(_boxes_and_bounds, T)(tri_v), pool=pool, leaf_max=TRI_LEAF, block=GROUP)
        node, child, leaf = _kernel(_collapse, len(box))(box, meta)
        bounds = box[0].copy()
        del box, meta
        tv4, first, groups = _pack_leaves(tri_v, order, leaf, pool)
    return order, Bvh4(node, child, groups, first, tv4, bounds)


def build_box_tree(boxes: np.ndarray) -> tuple[np.ndarray, tuple]:
    """The same 4-wide tree over boxes (the analytic primitives' world bounds), leaves
    without packing.

    Parameters
    ----------
    boxes : (P, 6) float64 boxes (min xyz, max xyz), P >= 1.

    Returns
    -------
    order : (P,) permutation: leaf ranges index ``boxes[order]``.
    tree : ``(node (N4, 6, 4), child (N4, 4), leaf (L, 2))`` as :func:`_collapse` makes them.
    """
    boxes = np.array(boxes, dtype=np.float64, order="C")
    if len(boxes) <= MAX_LEAF:
        return np.arange(len(boxes), dtype=np.int64), _root_leaf(boxes)
    order, box, meta = _build(boxes)
    return order, _kernel(_collapse, len(box))(box, meta)


def _root_leaf(boxes: np.ndarray) -> tuple:
    """The tree :func:`build_box_tree` makes of at most :data:`MAX_LEAF` boxes (one leaf at the
    root, the items in their order), built without compiling the builder's kernels: a scene
    of a few spheres pays no compile for them."""
    node = np.empty((1, 6, 4))
    node[0, :3, :], node[0, 3:, :] = np.inf, -np.inf  # empty slots
    node[0, :3, 0], node[0, 3:, 0] = boxes[:, :3].min(axis=0), boxes[:, 3:].max(axis=0)
    child = np.array([[-2, -1, -1, -1]], dtype=np.int64)
    return node, child, np.array([[0, len(boxes)]], dtype=np.int64)


def empty_bvh4() -> Bvh4:
    """Arrays of the right types for a scene without triangles (never traversed)."""
    return Bvh4(np.zeros((1, 6, 4)), np.full((1, 4), -1, dtype=np.int64), np.zeros((1, 2), dtype=np.int64),
                np.zeros(1, dtype=np.int64), np.zeros((1, 9, 4)), np.array([np.inf] * 3 + [-np.inf] * 3))
