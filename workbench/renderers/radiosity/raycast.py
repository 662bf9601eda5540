"""Ray-cast form factors with occlusion (Malley's method), the independent cross-check of the
hemicube: cosine-distributed rays leave stratified points of patch i, and F_ij is the
fraction whose nearest hit is the front face of patch j (Sillion & Puech 1994, sec. 4.9).
Unbiased; relative noise ~ 1 / sqrt(rays * F_ij).  Brute-force nearest hit: O(P^2 rays).
"""
from __future__ import annotations

import numpy as np

from ...core.errors import WorkbenchError
from ...core.tol import offset_scale, tol
from .formfactors import Geometry


def raycast(geom: Geometry, rays: int = 4096, seed: int = 0) -> np.ndarray:
    """F (P, P) by ray casting ``rays`` rays per patch (rounded down to a square)."""
    if rays < 1:
        raise WorkbenchError(f"raycast form factors need at least one ray per patch, got {rays}")
    from .kernels import raycast_rows
    order = np.argsort(geom.tri_patch, kind="stable")
    tris = np.ascontiguousarray(geom.tris[order])
    owner = geom.tri_patch[order].astype(np.int64)
    P = len(geom)
    first = np.searchsorted(owner, np.arange(P + 1)).astype(np.int64)
    ext = geom.extent
    return raycast_rows(tris, owner, first, np.ascontiguousarray(geom.normals), int(rays),
                        int(seed), tol.t_min * ext, offset_scale(0.0, ext))
