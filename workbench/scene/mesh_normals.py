"""Vertex normals of a triangle mesh that stay sharp at creases (the one place every method
gets a mesh's shading normals from: Gouraud, Phong, the ray tracers and radiosity all read
``Mesh.normals``).

Each corner of a triangle gets the area-weighted sum of the normals of the triangles around
its vertex whose normal lies within ``crease_angle`` of its own triangle's (the "auto smooth"
rule of modellers; Max, "Weights for computing vertex normals from facet normals", JGT 1999,
for the weighting).  Corners of one vertex whose sums differ become separate vertices, so a
cube keeps flat faces and a cylinder a sharp rim, while a smooth surface (every dihedral
angle below the threshold) keeps one normal per vertex and its vertices as they are.
"""
from __future__ import annotations

import numpy as np

from ..core.tol import tol
from ..core.transform import normalize

DEFAULT_CREASE_ANGLE = 30.0
"""Degrees between two triangles' normals above which their shared edge is a crease."""


def crease_normals(V: np.ndarray, F: np.ndarray, crease_angle: float = DEFAULT_CREASE_ANGLE,
                   uvs: np.ndarray | None = None):
    """Split vertices at creases and compute their normals.

    Parameters
    ----------
    V : (N, 3) vertices; F : (T, 3) int triangles; uvs : (N, 2) or None.
    crease_angle : degrees; 180 smooths everything, 0 gives each triangle its own normal.

    Returns
    -------
    V2 (N2, 3), F2 (T, 3), normals (N2, 3) unit (a degenerate vertex gets zeros, which the
    renderers replace by the face normal), uvs2 (N2, 2) or None.  When no edge is a crease
    the vertices and triangles are returned as given (``F2 is F``); otherwise vertices are
    renumbered (and ones no triangle uses dropped).
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])  # 2 x area, outward
    fu = normalize(fn)
    cos_max = np.cos(np.radians(crease_angle))
    vert = F.reshape(-1)                                   # (3T,) vertex of each corner
    face = np.repeat(np.arange(len(F)), 3)
    smooth = np.stack([np.bincount(vert, fn[face, c], minlength=len(V)) for c in range(3)], -1)
    at_crease = _crease_vertices(F, fu, cos_max, len(V))
    if not at_crease.any():  # the common case of a smooth mesh: one normal per vertex
        return V, F, normalize(smooth), uvs
    corner_n = smooth[vert]
    sel = np.flatnonzero(at_crease[vert])                  # corners whose vertex is on a crease
    order = np.argsort(vert, kind="stable")
    counts = np.bincount(vert, minlength=len(V))
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    own_start, own_count, own = start[vert[sel]], counts[vert[sel]], face[sel]
    acc = np.zeros((len(sel), 3))
    for k in range(int(own_count.max())):  # the k-th triangle around each corner's vertex
        has = own_count > k
        g = face[order[own_start[has] + k]]
        near = (g == own[has]) | (np.sum(fu[own[has]] * fu[g], -1) >= cos_max)  # its own face always
        acc[np.flatnonzero(has)[near]] += fn[g[near]]
    corner_n[sel] = acc
    key = np.concatenate([vert[:, None].astype(np.float64), corner_n], 1)
    uniq, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    src = vert[first]
    return (V[src], inverse.reshape(-1, 3).astype(np.int64), normalize(uniq[:, 1:]),
            None if uvs is None else np.asarray(uvs)[src])


def _crease_vertices(F: np.ndarray, fu: np.ndarray, cos_max: float, n_vertices: int) -> np.ndarray:
    """(N,) bool: vertices on an edge whose two triangles' unit normals ``fu`` (T, 3) differ by
    more than the crease angle (``fu_a . fu_b < cos_max``)."""
    a = F[:, [0, 1, 2]].reshape(-1)
    b = F[:, [1, 2, 0]].reshape(-1)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * n_vertices + hi
    order = np.argsort(key, kind="stable")
    same = key[order[1:]] == key[order[:-1]]               # consecutive corners of one edge
    e0, e1 = order[:-1][same], order[1:][same]
    crease = np.sum(fu[e0 // 3] * fu[e1 // 3], -1) < cos_max
    out = np.zeros(n_vertices, dtype=bool)
    out[lo[e0[crease]]] = True
    out[hi[e0[crease]]] = True
    return out


def mean_face_normals(V: np.ndarray, F: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """Vertex normals as the course defines them for Gouraud and Phong smoothing: "moyenne des
    normales aux faces incidentes", the plain mean of the unit normals of the triangles around
    each vertex (each triangle counts once, whatever its area or its angle at the vertex;
    compare :func:`crease_normals`' area weights and the analytic normals of spheres).

    Parameters
    ----------
    V : (N, 3) vertices; F : (T, 3) int triangles (a vertex shared by triangles is one index).
    fallback : (N, 3) unit normals kept where the mean cancels (``< tol.normal_cancel``) or
        no triangle uses the vertex.

    Returns
    -------
    (N, 3) unit normals.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    fu = normalize(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]))
    vert = F.reshape(-1)
    face = np.repeat(np.arange(len(F)), 3)
    total = np.stack([np.bincount(vert, fu[face, c], minlength=len(V)) for c in range(3)], -1)
    count = np.bincount(vert, minlength=len(V))
    mean = total / np.maximum(count, 1)[:, None]
    ok = np.linalg.norm(mean, axis=-1) >= tol.normal_cancel
    return np.where(ok[:, None], normalize(mean), np.asarray(fallback, dtype=np.float64))
