"""The course's octree ("arbre octal : intersection avec le cube courant") over triangles, laid
out as the ray tracer's 4-wide tree so that :func:`..kernels.walks.bvh_hit` traverses it unchanged.

Build (Glassner, "Space subdivision for fast ray tracing", IEEE CG&A 1984): the root is the cube
of side ``max(extent)`` at the triangles' lower bounds corner (stretched, exactly, to their
upper bounds where rounding leaves it short); a cell with more than ``MAX_LEAF`` triangles
is cut at its centre into eight equal cubes, each of which references every triangle whose
bounding box meets the closed cell, until ``MAX_DEPTH`` or the reference budget
(``REF_FACTOR x T``: a triangle lies in several cells) is reached.  Level by level: all the
cells of a level are cut, or none (the budget would be exceeded) and they all become leaves.

Layout: cell boxes are the cubes themselves (not tightened: the course's octree).  An inner
cell becomes a 4-wide node whose two slots are its lower-x and upper-x halves, each a 4-wide
node over its four octants (empty octants and halves are empty slots); a leaf cell with
triangles becomes a leaf whose range of the reference array lists them.  Sibling cells share
their faces exactly (``mid = (lo + hi) / 2`` is the one value both use), so every point of the
root lies in a leaf cell, and every triangle point in a leaf that references the triangle:
the closest-hit traversal (nearest child first, cells beyond the best hit skipped) finds the
same nearest triangle as the BVH, testing a triangle again in each cell the ray meets it in.
"""
from __future__ import annotations

import numba as nb
import numpy as np

MAX_LEAF = 8
"""A cell with more triangles than this is cut (if depth and budget allow)."""
MAX_DEPTH = 16
"""Deepest cell level (the root is 0).  A level costs the traversal stack at most four pending
children (one half, three octants): ``4 MAX_DEPTH`` stays within ``..kernels.walks.BVH_STACK``."""
REF_FACTOR = 4
"""Triangle references the octree may hold, per triangle: the bound of its memory estimate."""


@nb.njit(cache=True)
def _octant_mask(tb, i, box):
    """Bit ``o`` set for each octant ``o`` (bit 0 of ``o``: upper x half, bit 1: y, bit 2: z)
    of the cell ``box`` (min xyz, max xyz) whose closed cube triangle ``i``'s box meets, given
    that it meets the cell: per axis, the lower half if its min is at most the middle, the
    upper half if its max is at least the middle."""
    m = 0xFF
    for a in range(3):
        mid = 0.5 * (box[a] + box[3 + a])
        if tb[i, a] > mid:  # not in the lower half: clear the octants with bit a = 0
            m &= ~_LOWER[a]
        if tb[i, 3 + a] < mid:
            m &= _LOWER[a]
    return m


_LOWER = (0x55, 0x33, 0x0F)
"""Octants with bit ``a`` clear (x: 0, 2, 4, 6; y: 0, 1, 4, 5; z: 0..3), as bit masks."""


@nb.njit(cache=True)
def _cells(tb, root_lo, root_hi, max_leaf, max_depth, max_refs):
    """The cell tree, level by level.  Returns each cell's bounds ``(C, 6)``, its eight
    children ``(C, 8)`` (a cell index, ``-1`` for none: a leaf has none), its references'
    range ``(C, 2)`` into the returned reference array (leaves only; ``(0, 0)`` for inner
    cells) and the reference array."""
    T = tb.shape[0]
    cap = 1
    cell_box = np.empty((cap, 6))
    kids = np.full((cap, 8), -1, dtype=np.int64)
    rng = np.zeros((cap, 2), dtype=np.int64)
    for a in range(3):
        cell_box[0, a], cell_box[0, 3 + a] = root_lo[a], root_hi[a]
    out = np.empty(max_refs, dtype=np.int64)  # final references: leaves' lists (max_refs >= T)
    n_out = 0
    level = np.array([0], dtype=np.int64)           # the cells of the current level
    lrefs = np.arange(T)                            # their references, cell after cell
    lrng = np.zeros((1, 2), dtype=np.int64)
    lrng[0, 1] = T
    n_cells = 1
    depth = 0
    while level.shape[0] > 0:
        # each reference's octants, and the next level's counts if every cell above
        # max_leaf is cut
        mask = np.empty(lrefs.shape[0], dtype=np.int64)
        cut = np.zeros(level.shape[0], dtype=np.bool_)
        counts = np.zeros((level.shape[0], 8), dtype=np.int64)
        total_next = 0
        for c in range(level.shape[0]):
            s, e = lrng[c, 0], lrng[c, 1]
            if e - s <= max_leaf or depth >= max_depth:
                continue
            cut[c] = True
            box = cell_box[level[c]]
            for k in range(s, e):
                mk = _octant_mask(tb, lrefs[k], box)
                mask[k] = mk
                for o in range(8):
                    if (mk >> o) & 1:
                        counts[c, o] += 1
            total_next += counts[c].sum()
        leaf_refs = 0
        for c in range(level.shape[0]):
            if not cut[c]:
                leaf_refs += lrng[c, 1] - lrng[c, 0]
        if n_out + leaf_refs + total_next > max_refs:  # over budget: this level is the last
            cut[:] = False
        # leaves of this level keep their lists
        for c in range(level.shape[0]):
            if cut[c]:
                continue
            s, e = lrng[c, 0], lrng[c, 1]
            rng[level[c], 0], rng[level[c], 1] = n_out, n_out + e - s
            out[n_out:n_out + e - s] = lrefs[s:e]
            n_out += e - s
        n_next = 0
        for c in range(level.shape[0]):
            if cut[c]:
                for o in range(8):
                    n_next += counts[c, o] > 0
        if n_next == 0:
            break
        # grow the cell arrays
        if n_cells + n_next > cell_box.shape[0]:
            new_cap = max(2 * cell_box.shape[0], n_cells + n_next)
            nb_ = np.empty((new_cap, 6))
            nk = np.full((new_cap, 8), -1, dtype=np.int64)
            nr = np.zeros((new_cap, 2), dtype=np.int64)
            nb_[:n_cells], nk[:n_cells], nr[:n_cells] = cell_box[:n_cells], kids[:n_cells], rng[:n_cells]
            cell_box, kids, rng = nb_, nk, nr
        nlevel = np.empty(n_next, dtype=np.int64)
        nrefs = np.empty(max(total_next, 1), dtype=np.int64)
        nrng = np.empty((n_next, 2), dtype=np.int64)
        q, w = 0, 0
        for c in range(level.shape[0]):
            if not cut[c]:
                continue
            cb = level[c]
            s, e = lrng[c, 0], lrng[c, 1]
            for o in range(8):
                if counts[c, o] == 0:
                    continue
                nc = n_cells
                n_cells += 1
                kids[cb, o] = nc
                for a in range(3):
                    lo, hi = cell_box[cb, a], cell_box[cb, 3 + a]
                    mid = 0.5 * (lo + hi)
                    if (o >> a) & 1:
                        cell_box[nc, a], cell_box[nc, 3 + a] = mid, hi
                    else:
                        cell_box[nc, a], cell_box[nc, 3 + a] = lo, mid
                nrng[q, 0] = w
                for k in range(s, e):
                    if (mask[k] >> o) & 1:
                        nrefs[w] = lrefs[k]
                        w += 1
                nrng[q, 1] = w
                nlevel[q] = nc
                q += 1
        level, lrefs, lrng = nlevel, nrefs, nrng
        depth += 1
    return cell_box[:n_cells].copy(), kids[:n_cells].copy(), rng[:n_cells].copy(), out[:n_out].copy()


@nb.njit(cache=True)
def _layout(cell_box, kids, rng):
    """4-wide nodes of the cell tree (see the module docstring): children's boxes
    ``(N4, 6, 4)``, children ``(N4, 4)`` (node ``>= 0``, leaf ``l`` as ``-2 - l``, empty
    ``-1``) and leaves ``(L, 2)`` ``(first reference, count)``, nodes depth first."""
    C = cell_box.shape[0]
    cap = 3 * C + 1
    nbox = np.empty((cap, 6, 4))
    for q in range(cap):
        for a in range(3):
            for j in range(4):
                nbox[q, a, j], nbox[q, 3 + a, j] = np.inf, -np.inf
    child = np.full((cap, 4), -1, dtype=np.int64)
    leaf = np.empty((C, 2), dtype=np.int64)
    todo = np.empty((C + 1, 2), dtype=np.int64)  # (inner cell, its 4-wide node)
    n4, nl, sp = 1, 0, 0
    if kids[0].max() < 0:  # the root is a leaf: one node, one slot
        for a in range(6):
            nbox[0, a, 0] = cell_box[0, a]
        leaf[0, 0], leaf[0, 1] = rng[0, 0], rng[0, 1] - rng[0, 0]
        child[0, 0] = -2
        return nbox[:1].copy(), child[:1].copy(), leaf[:1].copy()
    todo[0, 0], todo[0, 1] = 0, 0
    sp = 1
    while sp > 0:
        sp -= 1
        c, p = todo[sp, 0], todo[sp, 1]
        for half in range(2):
            if max(kids[c, half], kids[c, 2 + half], kids[c, 4 + half], kids[c, 6 + half]) < 0:
                continue
            h = n4
            n4 += 1
            child[p, half] = h
            for a in range(3):
                lo, hi = cell_box[c, a], cell_box[c, 3 + a]
                mid = 0.5 * (lo + hi)
                if a == 0:
                    lo, hi = (mid, hi) if half == 1 else (lo, mid)
                nbox[p, a, half], nbox[p, 3 + a, half] = lo, hi
            for j in range(4):
                k = kids[c, half + 2 * j]  # octants with this x half: y, z bits from j
                if k < 0:
                    continue
                for a in range(6):
                    nbox[h, a, j] = cell_box[k, a]
                if kids[k].max() < 0:
                    leaf[nl, 0], leaf[nl, 1] = rng[k, 0], rng[k, 1] - rng[k, 0]
                    child[h, j] = -2 - nl
                    nl += 1
                else:
                    child[h, j] = n4
                    todo[sp, 0], todo[sp, 1] = k, n4
                    sp += 1
                    n4 += 1
    return nbox[:n4].copy(), child[:n4].copy(), leaf[:nl].copy()


def build_octree(tri_v: np.ndarray) -> tuple[np.ndarray, tuple]:
    """The octree of triangles as a 4-wide tree.

    Parameters
    ----------
    tri_v : (T, 9) float64 triangle vertices, T >= 1.

    Returns
    -------
    refs : (R,) int64, T <= R <= REF_FACTOR T: the triangle of each reference; leaf ranges
        index ``tri_v[refs]`` (a triangle met by several cells appears once per cell).
    tree : ``(node (N4, 6, 4), child (N4, 4), leaf (L, 2))`` as :func:`.bvh._collapse` makes them
        (leaf ranges over the references).
    """
    tri_v = np.ascontiguousarray(tri_v, dtype=np.float64)
    tb = np.empty((len(tri_v), 6))
    for a in range(3):
        c = tri_v[:, a::3]
        tb[:, a], tb[:, 3 + a] = c.min(1), c.max(1)
    return build_box_octree(tb)


def build_box_octree(tb: np.ndarray) -> tuple[np.ndarray, tuple]:
    """The octree of items given by their boxes ``tb`` (T, 6) (min xyz, max xyz), T >= 1: the
    triangles' boxes, or the analytic primitives' world bounds.  Returns ``refs`` (R,) (the
    item of each reference) and the tree, as :func:`build_octree`."""
    tb = np.ascontiguousarray(tb, dtype=np.float64)
    lo, hi = tb[:, :3].min(0), tb[:, 3:].max(0)
    side = float((hi - lo).max())
    root_hi = np.maximum(lo + side, hi)  # a cube, unless rounding left lo + side short of hi
    cell_box, kids, rng, refs = _cells(tb, lo, root_hi, MAX_LEAF, MAX_DEPTH, REF_FACTOR * len(tb))
    return refs, _layout(cell_box, kids, rng)
