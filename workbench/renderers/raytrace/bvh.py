"""Bounding volume hierarchy over triangles: binned surface-area-heuristic build.

Wald, "On fast construction of SAH-based bounding volume hierarchies" (IEEE RT 2007): at each
node the triangle centroids are binned (``N_BINS`` bins along each axis of the centroids'
box) and the split minimising ``C = A_L N_L + A_R N_R`` (areas of the child boxes, counts of
triangles) over the three axes is taken if it beats a leaf (binning along the longest axis
only traced the mesh scene's rays 3 % slower).  Nodes are stored depth first: an inner
node's left child follows it, ``meta[i] = (right, 0, axis)``; a leaf is
``meta[i] = (first, count, -1)``.
"""
from __future__ import annotations

import numba as nb
import numpy as np

N_BINS = 16
MAX_LEAF = 4
# SAH cost of a traversal step relative to one triangle test (pbrt-v4 uses 1/2 as well).
TRAVERSAL_COST = 0.5


@nb.njit(cache=True)
def _area(b0, b1, b2, b3, b4, b5):
    dx, dy, dz = b3 - b0, b4 - b1, b5 - b2
    if dx < 0.0:
        return 0.0
    return dx * dy + dy * dz + dz * dx


@nb.njit(cache=True)
def _build(tri_v):
    T = tri_v.shape[0]
    tb = np.empty((T, 6))
    cen = np.empty((T, 3))
    for i in range(T):
        for a in range(3):
            lo = min(tri_v[i, a], tri_v[i, 3 + a], tri_v[i, 6 + a])
            hi = max(tri_v[i, a], tri_v[i, 3 + a], tri_v[i, 6 + a])
            tb[i, a], tb[i, 3 + a] = lo, hi
            cen[i, a] = 0.5 * (lo + hi)
    idx = np.arange(T)
    cap = max(2 * T, 1)
    box = np.empty((cap, 6))
    meta = np.zeros((cap, 3), dtype=np.int64)
    stack = np.empty((256, 4), dtype=np.int64)  # start, end, parent, is_right
    sp = 0
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0, T, -1, 0
    sp = 1
    n_nodes = 0
    bin_box = np.empty((N_BINS, 6))
    bin_cnt = np.zeros(N_BINS, dtype=np.int64)
    right_area = np.empty(N_BINS)
    right_cnt = np.empty(N_BINS, dtype=np.int64)
    while sp > 0:
        sp -= 1
        s, e, parent, is_right = stack[sp, 0], stack[sp, 1], stack[sp, 2], stack[sp, 3]
        node = n_nodes
        n_nodes += 1
        if is_right == 1:
            meta[parent, 0] = node
        # node bounds and centroid bounds
        for a in range(3):
            box[node, a], box[node, 3 + a] = np.inf, -np.inf
        cmin = np.full(3, np.inf)
        cmax = np.full(3, -np.inf)
        for k in range(s, e):
            i = idx[k]
            for a in range(3):
                box[node, a] = min(box[node, a], tb[i, a])
                box[node, 3 + a] = max(box[node, 3 + a], tb[i, 3 + a])
                cmin[a] = min(cmin[a], cen[i, a])
                cmax[a] = max(cmax[a], cen[i, a])
        n = e - s
        ext = cmax - cmin
        if n <= MAX_LEAF or not max(ext[0], ext[1], ext[2]) > 0.0:
            meta[node, 0], meta[node, 1], meta[node, 2] = s, n, -1
            continue
        # bin the centroids along each axis, sweep from the right, then from the left
        best, best_b, axis = np.inf, -1, 0
        for ax in range(3):
            if not ext[ax] > 0.0:
                continue
            scale = N_BINS * (1.0 - 1e-9) / ext[ax]
            for b in range(N_BINS):
                bin_cnt[b] = 0
                for a in range(3):
                    bin_box[b, a], bin_box[b, 3 + a] = np.inf, -np.inf
            for k in range(s, e):
                i = idx[k]
                b = int((cen[i, ax] - cmin[ax]) * scale)
                bin_cnt[b] += 1
                for a in range(3):
                    bin_box[b, a] = min(bin_box[b, a], tb[i, a])
                    bin_box[b, 3 + a] = max(bin_box[b, 3 + a], tb[i, 3 + a])
            acc = np.full(6, np.inf)
            for a in range(3):
                acc[3 + a] = -np.inf
            cnt = 0
            for b in range(N_BINS - 1, 0, -1):
                for a in range(3):
                    acc[a] = min(acc[a], bin_box[b, a])
                    acc[3 + a] = max(acc[3 + a], bin_box[b, 3 + a])
                cnt += bin_cnt[b]
                right_area[b] = _area(acc[0], acc[1], acc[2], acc[3], acc[4], acc[5])
                right_cnt[b] = cnt
            for a in range(3):
                acc[a], acc[3 + a] = np.inf, -np.inf
            cnt = 0
            for b in range(N_BINS - 1):
                for a in range(3):
                    acc[a] = min(acc[a], bin_box[b, a])
                    acc[3 + a] = max(acc[3 + a], bin_box[b, 3 + a])
                cnt += bin_cnt[b]
                if cnt == 0 or right_cnt[b + 1] == 0:
                    continue
                c = _area(acc[0], acc[1], acc[2], acc[3], acc[4], acc[5]) * cnt + right_area[b + 1] * right_cnt[b + 1]
                if c < best:
                    best, best_b, axis = c, b, ax
        parent_area = _area(box[node, 0], box[node, 1], box[node, 2], box[node, 3], box[node, 4], box[node, 5])
        leaf_cost = float(n)
        split_cost = TRAVERSAL_COST + best / max(parent_area, 1e-300)
        if best_b < 0 or (split_cost >= leaf_cost and n <= 4 * MAX_LEAF):
            meta[node, 0], meta[node, 1], meta[node, 2] = s, n, -1
            continue
        # partition idx[s:e] by bin
        scale = N_BINS * (1.0 - 1e-9) / ext[axis]
        lo, hi = s, e - 1
        while lo <= hi:
            if int((cen[idx[lo], axis] - cmin[axis]) * scale) <= best_b:
                lo += 1
            else:
                idx[lo], idx[hi] = idx[hi], idx[lo]
                hi -= 1
        mid = lo
        meta[node, 1], meta[node, 2] = 0, axis
        if sp + 2 > stack.shape[0]:  # a degenerate, very deep tree: grow the stack
            grown = np.empty((2 * stack.shape[0], 4), dtype=np.int64)
            grown[:sp] = stack[:sp]
            stack = grown
        # push right then left: the left child is popped next and gets index node + 1
        stack[sp, 0], stack[sp, 1], stack[sp, 2], stack[sp, 3] = mid, e, node, 1
        sp += 1
        stack[sp, 0], stack[sp, 1], stack[sp, 2], stack[sp, 3] = s, mid, node, 0
        sp += 1
    return idx, box[:n_nodes].copy(), meta[:n_nodes].copy()


def build_bvh(tri_v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Build the BVH of triangles.

    Parameters
    ----------
    tri_v : (T, 9) float64 triangle vertices (x0 y0 z0 x1 ... z2).

    Returns
    -------
    order : (T,) permutation: leaf ranges index ``tri_v[order]``.
    box : (Nn, 6) node bounds (min xyz, max xyz).
    meta : (Nn, 3) int64, leaf ``(first, count, -1)``, inner ``(right child, 0, axis)``.
    """
    return _build(np.ascontiguousarray(tri_v, dtype=np.float64))
