"""Ray-cast form factors with occlusion (Malley's method), the independent cross-check of the
hemicube: cosine-distributed rays leave stratified points of patch i, and F_ij is the
fraction whose nearest hit is the front face of patch j (Sillion & Puech 1994, sec. 4.9).
Unbiased; relative noise ~ 1 / sqrt(rays * F_ij).  Nearest hits through the kernels' 4-wide BVH.

:class:`RayRows`: rows for matrix-free progressive refinement, by rays from every receiver to
the shooter (Wallace et al. 1989).
"""
from __future__ import annotations

import numpy as np

from ...core.errors import WorkbenchError
from ...core.tol import offset_scale, tol
from .geometry import Geometry


def raycast(geom: Geometry, rays: int = 4096, seed: int = 0) -> np.ndarray:
    """F (P, P) by ray casting ``rays`` rays per patch (rounded down to a square)."""
    if rays < 1:
        raise WorkbenchError(f"raycast form factors need at least one ray per patch, got {rays}")
    from ..raytrace.bvh import build_bvh4
    from .kernels import raycast_rows
    order = np.argsort(geom.tri_patch, kind="stable")
    tris = np.ascontiguousarray(geom.tris[order])
    owner = geom.tri_patch[order].astype(np.int64)
    P = len(geom)
    first = np.searchsorted(owner, np.arange(P + 1)).astype(np.int64)
    ext = geom.extent
    bvh_tri, bvh = build_bvh4(tris.reshape(-1, 9))
    return raycast_rows(tris, owner, first, np.ascontiguousarray(geom.normals),
                        (bvh.node, bvh.child, bvh.leaf, bvh.first, bvh.tv4), bvh_tri.astype(np.int64),
                        int(rays), int(seed), tol.t_min * ext, offset_scale(0.0, ext))


class RayRows:
    """Form-factor rows for progressive refinement by ray casting, without GL (Wallace,
    Elmquist & Haines 1989, "A ray tracing algorithm for progressive radiosity"): when patch
    i shoots, every receiver j takes the exact point-to-polygon factor from its centre to
    patch i (Lambert's formula, unoccluded) times the visible fraction of i, found by rays
    from j's centre to ``4**level`` points per triangle of i through the kernels' 4-wide BVH of the
    patches' triangles (:func:`.kernels.receiver_rows`, numba, parallel over receivers); level 0, one
    ray per triangle (two per quad patch), gives the Cornell box the same solution as level 1
    (1.75 % RMS from the hemicube matrix's) at a third of the cost.

    The factors are the receivers' own F_ji, so shooting solves the gathering system (the one
    the hemicube matrix and the direct solver solve, minus the hemicube's aliasing), not the
    shooter-side reciprocal F_ij A_i / A_j that hemicube rows give.  ``rows(indices)`` returns
    them in row form F_ji A_j / A_i, like :meth:`.hemicube.Hemicube.rows`.
    """

    def __init__(self, geom: Geometry, level: int = 0):
        from ..raytrace.bvh import build_bvh4
        if not (0 <= level <= 3):
            raise WorkbenchError(f"ray-cast rows: level must be 0..3 (1 to 64 rays per triangle), got {level}")
        self.geom, self.level = geom, int(level)
        self.P = len(geom)
        ext = geom.extent
        self.offset = offset_scale(0.0, ext)
        tv = np.ascontiguousarray(geom.tris.reshape(-1, 9), dtype=np.float64)
        _, bvh = build_bvh4(tv)
        self.bvh = (bvh.node, bvh.child, bvh.leaf, bvh.first, bvh.tv4)
        polys = geom.polygons
        self.offsets = np.zeros(self.P + 1, dtype=np.int64)
        self.offsets[1:] = np.cumsum([len(p) for p in polys])
        self.flat = np.ascontiguousarray(np.concatenate(polys), dtype=np.float64) if polys else np.zeros((0, 3))
        self.samples, self.sample_w, self.sample_first = self._samples()
        self.rays_cast = 0

    def _samples(self):
        """Centroids of each triangle's 4**level midpoint sub-triangles, moved off the patch by
        the ray offset, weighted by area; grouped by patch."""
        g = self.geom
        tris = g.tris
        for _ in range(self.level):      # midpoint subdivision: each triangle into four
            a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
            ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
            tris = np.stack([np.stack(t, 1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c),
                                                      (ab, bc, ca))], 1).reshape(-1, 3, 3)
        owner = np.repeat(g.tri_patch, 4 ** self.level)
        order = np.argsort(owner, kind="stable")
        tris, owner = tris[order], owner[order]
        w = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
        pts = tris.mean(1) + self.offset * g.normals[owner]
        first = np.searchsorted(owner, np.arange(self.P + 1)).astype(np.int64)
        return np.ascontiguousarray(pts), w, first

    def rows(self, patches) -> np.ndarray:
        """Rows (len(patches), P): F_ji A_j / A_i for shooter i, receiver j (see the class)."""
        from .kernels import receiver_rows
        patches = np.asarray(patches, dtype=np.int64).ravel()
        out = np.zeros((len(patches), self.P))
        g = self.geom
        receiver_rows(patches, (self.flat, self.offsets),
                      (np.ascontiguousarray(g.centres), np.ascontiguousarray(g.normals),
                       np.ascontiguousarray(g.areas, dtype=np.float64)),
                      (self.samples, self.sample_w, self.sample_first), self.bvh,
                      self.offset, tol.t_min, tol.zero, out)
        per = np.diff(self.sample_first)[patches]
        self.rays_cast += int((per * self.P).sum())
        return out
