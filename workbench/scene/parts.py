"""Triangle sets with one material (:class:`Part`), what the raster methods draw, and the
builders every object kind's tessellation shares (planar polygons cut in grids, object-space
arrays moved to world space with their normals).

Everything in a Part is in world space except ``obj_positions`` (the points in the object space
of the object, or of the CSG leaf, they belong to: what textures are evaluated on, see
:mod:`workbench.renderers.texturing`).  Triangles are counter-clockwise seen from the side their
normal points to.  Shading normals are never zero: a vertex normal that cancels
(``< tol.normal_cancel``) is replaced by the area-weighted mean of its triangles' normals.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core import transform as tf
from ..core.tol import tol
from . import model as m


@dataclass(frozen=True, eq=False)
class Part:
    """Triangles with one material, in world space.

    Attributes
    ----------
    name, kind : the source object's name and kind (``"sphere"``, ..., ``"csg"``).
    material : material name.
    world_from_object : (4, 4) of the object (or CSG leaf) ``obj_positions`` belong to.
    positions : (V, 3) float64 world points.
    normals : (V, 3) unit world shading normals (smooth where the surface is smooth).
    obj_positions : (V, 3) object-space points (texture coordinates are computed from them).
    uvs : (V, 2) mesh texture coordinates, or None.
    faces : (F, 3) int64 vertex indices, counter-clockwise seen from the normal side.
    face_normals : (F, 3) unit world normal of each triangle's source polygon.
    face_centroids : (F, 3) world centroid of each triangle's source polygon.
    """

    name: str
    kind: str
    material: str
    world_from_object: np.ndarray
    positions: np.ndarray
    normals: np.ndarray
    obj_positions: np.ndarray
    uvs: np.ndarray | None
    faces: np.ndarray
    face_normals: np.ndarray
    face_centroids: np.ndarray

    @property
    def n_triangles(self) -> int:
        return len(self.faces)


def triangle_normals(P: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit normals (F, 3) of triangles (zero for a degenerate triangle)."""
    return tf.normalize(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]))


def fix_normals(N: np.ndarray, P: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unit normals; where one cancels, the area-weighted mean of its triangles' normals."""
    length = np.linalg.norm(N, axis=-1)
    bad = length < tol.normal_cancel
    if bad.any():
        fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
        acc = np.zeros_like(P)
        for k in range(3):
            np.add.at(acc, F[:, k], fn)
        N = np.where(bad[:, None], acc, N)
    return tf.normalize(N)


def grid_quad(corners: np.ndarray, n: int):
    """A planar quad (4, 3) cut in n x n cells: points, faces."""
    s = np.linspace(0.0, 1.0, n + 1)
    a, b = np.meshgrid(s, s, indexing="ij")
    a, b = a.reshape(-1, 1), b.reshape(-1, 1)
    c = corners
    P = (1 - a) * (1 - b) * c[0] + a * (1 - b) * c[1] + a * b * c[2] + (1 - a) * b * c[3]
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    v00 = (i * (n + 1) + j).ravel()
    v10, v11, v01 = v00 + (n + 1), v00 + (n + 2), v00 + 1
    F = np.vstack([np.stack([v00, v10, v11], -1), np.stack([v00, v11, v01], -1)])
    return P, F


def polygons(polys: list[np.ndarray], n: int):
    """Planar convex polygons, each as a fan cut in n^2 triangles per fan triangle; one face
    normal and centroid per polygon."""
    Ps, Fs, FN, FC, off = [], [], [], [], 0
    s = np.linspace(0.0, 1.0, n + 1)
    for poly in polys:
        normal = tf.normalize(np.cross(poly[1:-1] - poly[0], poly[2:] - poly[0]).sum(0))
        centroid = poly.mean(0)
        if len(poly) == 4:
            P, F = grid_quad(poly, n)
        else:
            P, F = fan(poly, s, n)
        Ps.append(P)
        Fs.append(F + off)
        FN.append(np.tile(normal, (len(F), 1)))
        FC.append(np.tile(centroid, (len(F), 1)))
        off += len(P)
    P, F = np.vstack(Ps), np.vstack(Fs)
    fn = np.vstack(FN)
    N = np.zeros_like(P)
    N[F.ravel()] = np.repeat(fn, 3, axis=0)
    return P, N, F, fn, np.vstack(FC)


def fan(poly: np.ndarray, s: np.ndarray, n: int):
    """Fan triangulation of a convex polygon, each triangle cut by an n-step barycentric grid."""
    Ps, Fs, off = [], [], 0
    # barycentric lattice points (i, j) with i + j <= n, and the small triangles between them
    pts = [(i, j) for i in range(n + 1) for j in range(n + 1 - i)]
    index = {p: k for k, p in enumerate(pts)}
    tri = []
    for i in range(n):
        for j in range(n - i):
            tri.append((index[(i, j)], index[(i + 1, j)], index[(i, j + 1)]))
            if i + j < n - 1:
                tri.append((index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]))
    ij = np.array(pts, dtype=np.float64) / n
    tri = np.array(tri, dtype=np.int64)
    for k in range(1, len(poly) - 1):
        a, b, c = poly[0], poly[k], poly[k + 1]
        Ps.append(a + ij[:, :1] * (b - a) + ij[:, 1:] * (c - a))
        Fs.append(tri + off)
        off += len(pts)
    return np.vstack(Ps), np.vstack(Fs)


def make_part(obj: m.SceneObject, M: np.ndarray, P, N, F, fn, fc, uvs=None, material=None) -> Part:
    """Object-space arrays -> world-space Part."""
    Pw = tf.transform_points(M, P)
    if np.linalg.det(np.asarray(M)[:3, :3]) < 0:  # a mirroring transform flips the winding
        F = np.asarray(F)[:, ::-1]
    Nw = fix_normals(tf.transform_normals(M, N), Pw, F)
    if fn is None:
        fn_w, fc_w = triangle_normals(Pw, F), Pw[F].mean(1)
    else:
        fn_w, fc_w = tf.transform_normals(M, fn), tf.transform_points(M, fc)
    return Part(obj.name, obj.kind, material or obj.material, np.asarray(M, dtype=np.float64),
                Pw, Nw, np.asarray(P, dtype=np.float64), uvs, np.asarray(F, dtype=np.int64), fn_w, fc_w)
