"""The ray tracer's acceleration structure over triangles, a method option (``accel``):

* ``bvh``: the binned-SAH bounding volume hierarchy collapsed to 4-wide nodes (:mod:`.bvh`);
* ``octree``: the course's octree of equal cubes (:mod:`.octree`);
* ``none``: brute force, every triangle tested by every ray that meets the triangles' box
  (one leaf holding them all).

All three are laid out as :class:`.bvh.Bvh4` (4-wide nodes, leaves of triangles packed by
four), so the one traversal :func:`.kernels.bvh_hit` serves them: they differ only in which
boxes a ray tests and which triangles it tests.  They find the same closest hit; where two
triangles have exactly the same ``t`` (a ray through a shared edge or vertex), the first
tested wins, and the order of the tests is the structure's.  The octree references a triangle
once per cell it meets: the triangle arrays of the flattened scene then hold one row per
reference (``order`` repeats triangles), so that a hit's row is its triangle's data.

Analytic primitives (spheres, boxes, quadrics, ...) are tested one after the other by every
ray whatever ``accel`` is (:func:`.kernels.closest`).
"""
from __future__ import annotations

import numpy as np

from .bvh import Bvh4, _pack_leaves, build_bvh4

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
