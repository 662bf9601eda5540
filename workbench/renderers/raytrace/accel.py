"""The ray tracer's acceleration structure over triangles, a method option (``accel``):

* ``bvh``: the binned-SAH bounding volume hierarchy collapsed to 4-wide nodes (:mod:`.bvh`);
* ``octree``: the course's octree of equal cubes (:mod:`.octree`);
* ``none``: brute force, every triangle tested by every ray that meets the triangles' box
  (one leaf holding them all).

All three are laid out as :class:`.bvh.Bvh4` (4-wide nodes, leaves of triangles packed by
four), so the one traversal :func:`..kernels.walks.bvh_hit` serves them: they differ only in which
boxes a ray tests and which triangles it tests.  They find the same closest hit; where two
triangles have exactly the same ``t`` (a ray through a shared edge or vertex), the first
tested wins, and the order of the tests is the structure's.  The octree references a triangle
once per cell it meets: the triangle arrays of the flattened scene then hold one row per
reference (``order`` repeats triangles), so that a hit's row is its triangle's data.

Analytic primitives (spheres, boxes, quadrics, CSG nodes, ...) with ``bvh`` or ``octree``:
every top-level primitive with finite world bounds is an item of a second tree of the same
kind (:class:`PrimTree`, built over their padded world boxes: :func:`build_prim_tree`), its
leaves listing primitive rows; the unbounded ones (a quadric without bounds, a CSG node with
one among its operands) stay in a short list tested by every ray.  With ``none`` every
primitive is in that list (the brute force of before).  :func:`..kernels.intersect.closest` tests the
list, then the primitives' tree, then the triangles' tree: all three find the closest hit,
and two surfaces closer along the ray than the ray offset go to the lower primitive row
(:func:`..kernels.intersect.nearer`), whatever the order of the tests, so the images are the same.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...core.tol import tol
from .bvh import Bvh4, _pack_leaves, build_box_tree, build_bvh4

ACCELS = ("bvh", "octree", "none")
"""The values of the ``accel`` option, the default first."""

_BYTES_PER_REFERENCE = 512
"""One more reference to a triangle (octree): its rows of the flattened triangle arrays
(vertices, normals, uvs, emission: 33 floats, its primitive), its lane in the packed leaves
(9 floats) and the build's per-level lists, with margin."""


def build_accel(tri_v: np.ndarray, accel: str) -> tuple[np.ndarray, Bvh4]:
    """The structure ``accel`` (one of :data:`ACCELS`) over triangles.

    Parameters
    ----------
    tri_v : (T, 9) float64 triangle vertices, T >= 1.
    accel : ``"bvh"``, ``"octree"`` or ``"none"``.

    Returns
    -------
    order : (R,) int64 triangle of each row of the structure's triangle arrays (a permutation
        for ``bvh`` and ``none``, R = T; with repeats for ``octree``, R <= ``REF_FACTOR`` T).
    tree : :class:`.bvh.Bvh4` over ``tri_v[order]``.
    """
    tri_v = np.ascontiguousarray(tri_v, dtype=np.float64)
    if accel == "bvh":
        return build_bvh4(tri_v)
    lo = tri_v.reshape(-1, 3, 3).min(axis=(0, 1))
    hi = tri_v.reshape(-1, 3, 3).max(axis=(0, 1))
    bounds = np.concatenate([lo, hi])
    if accel == "octree":
        from .octree import build_octree
        order, (node, child, leaf) = build_octree(tri_v)
    elif accel == "none":
        order = np.arange(len(tri_v), dtype=np.int64)
        node = np.empty((1, 6, 4))
        node[0, :3, :], node[0, 3:, :] = np.inf, -np.inf  # empty slots
        node[0, :, 0] = bounds
        child = np.array([[-2, -1, -1, -1]], dtype=np.int64)  # slot 0: leaf 0, all triangles
        leaf = np.array([[0, len(tri_v)]], dtype=np.int64)
    else:
        raise ValueError(f"accel must be one of {', '.join(ACCELS)}, got {accel!r}")
    tv4, first, groups = _pack_leaves(tri_v, order, leaf)
    return order, Bvh4(node, child, groups, first, tv4, bounds)


def accel_extra_bytes(n_triangles: int, accel: str) -> int:
    """Bytes ``accel`` needs beyond what the BVH needs for ``n_triangles`` (the octree's
    repeated references, at most ``REF_FACTOR - 1`` more per triangle; the octree's cells and
    brute force's single node are smaller than the BVH's nodes)."""
    if accel == "octree":
        from .octree import REF_FACTOR
        return int((REF_FACTOR - 1) * n_triangles * _BYTES_PER_REFERENCE)
    return 0


class PrimTree(NamedTuple):
    """The analytic primitives' structure (module docstring), as the kernels take it."""
    free: np.ndarray    # (F,) int64 rows tested by every ray, in row order
    node: np.ndarray    # (N4, 6, 4) children's boxes (as Bvh4.node)
    child: np.ndarray   # (N4, 4) int64: node >= 0, leaf l as -2 - l, empty -1
    leaf: np.ndarray    # (L, 2) int64: (first reference, count)
    ref: np.ndarray     # (R,) int64 primitive row of each reference (R = 0: no tree)
    bounds: np.ndarray  # (6,) the tree's box


def pad_boxes(boxes: np.ndarray, scale: float) -> np.ndarray:
    """World boxes (P, 6) grown on every side by ``tol.bounds_pad * (|box|_inf + scale)``, so
    that a hit a primitive reports (computed in its object space, a cut quadric's with its
    slack ``tol.cut``) is never outside its box by rounding, and a flat primitive (a
    rectangle in an axis plane) has a box of non-zero thickness."""
    boxes = np.asarray(boxes, dtype=np.float64)
    pad = tol.bounds_pad * (np.abs(boxes).max(axis=1) + scale)
    return np.concatenate([boxes[:, :3] - pad[:, None], boxes[:, 3:] + pad[:, None]], axis=1)


def build_prim_tree(rows: np.ndarray, boxes: np.ndarray, accel: str) -> PrimTree:
    """The analytic primitives' structure.

    Parameters
    ----------
    rows : (P,) int64 top-level primitive rows, increasing.
    boxes : (P, 6) their padded world boxes; a row whose box is not finite is unbounded.
    accel : one of :data:`ACCELS` (``none``: every row in the list, no tree).

    Returns
    -------
    :class:`PrimTree`.
    """
    rows = np.asarray(rows, dtype=np.int64)
    boxes = np.asarray(boxes, dtype=np.float64).reshape(-1, 6)
    bounded = np.isfinite(boxes).all(axis=1) if accel != "none" else np.zeros(len(rows), dtype=bool)
    free = np.ascontiguousarray(rows[~bounded])
    if not bounded.any():
        node = np.empty((1, 6, 4))
        node[0, :3, :], node[0, 3:, :] = np.inf, -np.inf
        return PrimTree(free, node, np.full((1, 4), -1, dtype=np.int64), np.zeros((1, 2), dtype=np.int64),
                        np.zeros(0, dtype=np.int64), np.array([np.inf] * 3 + [-np.inf] * 3))
    items, ib = rows[bounded], np.ascontiguousarray(boxes[bounded])
    if accel == "bvh":
        order, (node, child, leaf) = build_box_tree(ib)
    elif accel == "octree":
        from .octree import build_box_octree
        order, (node, child, leaf) = build_box_octree(ib)
    else:
        raise ValueError(f"accel must be one of {', '.join(ACCELS)}, got {accel!r}")
    bounds = np.concatenate([ib[:, :3].min(0), ib[:, 3:].max(0)])
    return PrimTree(free, node, child, leaf, np.ascontiguousarray(items[order]), bounds)
