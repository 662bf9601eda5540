"""Patches as the form-factor methods see them (:class:`Geometry`): triangles, centres, normals,
areas and outlines, from a :class:`~.patches.PatchSet` or from plain polygons.  Shared by
:mod:`.formfactors`, :mod:`.hemicube` and :mod:`.raycast`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core import transform as tf
from ...core.errors import WorkbenchError
from ...core.tol import tol


@dataclass(frozen=True)
class Geometry:
    """Patches as the form-factor methods see them (``P`` patches, ``T`` triangles).

    tris : (T, 3, 3) triangles, counter-clockwise seen from the front.
    tri_patch : (T,) the patch of each triangle.
    centres, normals : (P, 3); areas : (P,).
    polygons : list of P arrays (k, 3), the patches' outlines (for the contour formula).
    grids : :class:`~.patches.Grid` surfaces whose patches form bilinear grids (optional: the
        hemicube draws them as a few large quads, see :mod:`.hemicube`).
    """

    tris: np.ndarray
    tri_patch: np.ndarray
    centres: np.ndarray
    normals: np.ndarray
    areas: np.ndarray
    polygons: list
    grids: tuple = ()

    def __len__(self) -> int:
        return len(self.areas)

    @property
    def extent(self) -> float:
        if len(self.tris) == 0:
            return 1.0
        p = self.tris.reshape(-1, 3)
        return float(max(np.linalg.norm(p.max(0) - p.min(0)), tol.zero))


def geometry_from_polygons(polygons) -> Geometry:
    """Validate planar convex polygons (list of (k, 3), k >= 3) and fan them into triangles.
    A polygon of zero area is accepted (it exchanges nothing)."""
    if len(polygons) == 0:
        raise WorkbenchError("form_factors: no polygons given")
    polys, tris, owner = [], [], []
    for i, p in enumerate(polygons):
        p = np.asarray(p, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 3:
            raise WorkbenchError(f"form_factors: polygon {i} must be a (k, 3) array with k >= 3, "
                                 f"got shape {p.shape}")
        if not np.isfinite(p).all():
            raise WorkbenchError(f"form_factors: polygon {i} has non-finite coordinates")
        polys.append(p)
        t = np.stack([np.broadcast_to(p[0], (len(p) - 2, 3)), p[1:-1], p[2:]], 1)
        tris.append(t)
        owner.append(np.full(len(t), i))
    tris_a = np.concatenate(tris)
    owner_a = np.concatenate(owner)
    cr = np.cross(tris_a[:, 1] - tris_a[:, 0], tris_a[:, 2] - tris_a[:, 0])
    n = len(polys)
    vec = np.zeros((n, 3))
    np.add.at(vec, owner_a, cr)
    areas = 0.5 * np.linalg.norm(vec, axis=1)
    normals = tf.normalize(vec)
    ta = 0.5 * np.linalg.norm(cr, axis=1)
    cen = np.zeros((n, 3))
    np.add.at(cen, owner_a, ta[:, None] * tris_a.mean(1))
    tsum = np.zeros(n)
    np.add.at(tsum, owner_a, ta)
    plain = np.array([p.mean(0) for p in polys])
    cen = np.where(tsum[:, None] > 0, cen / np.where(tsum > 0, tsum, 1.0)[:, None], plain)
    return Geometry(tris_a, owner_a, cen, normals, areas, polys)
