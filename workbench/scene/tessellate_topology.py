"""Topology of tessellated parts, for the raster methods' vertex layout and culling.

* :func:`closed_outward`: whether triangles bound a solid with outward winding, so that a
  viewer outside it never sees a back face (the first surface a ray from outside meets is
  one it enters: a front face) and back-face culling leaves the image unchanged.
* :func:`provoking_layout`: an indexed layout for flat shading in which every triangle has its
  own provoking vertex (the last one, OpenGL's default convention), so that per-polygon values
  (face normal, centroid) can ride on shared vertices: about one vertex per triangle instead
  of three for an unwelded list.
"""
from __future__ import annotations

import numpy as np


def closed_outward(positions: np.ndarray, faces: np.ndarray) -> bool:
    """True when the triangles form closed, consistently and outward-wound surfaces.

    Vertices are welded by exact position first (tessellators duplicate seam and corner
    vertices); triangles that collapse under welding (a UV sphere's pole caps) are dropped.
    Closed and consistent: every directed edge ``(i, j)`` occurs once and its reverse
    ``(j, i)`` once.  Outward: the signed volume ``sum p0 . (p1 x p2) / 6`` of every closed
    shell (connected component) is positive.

    Parameters
    ----------
    positions : (V, 3) points; faces : (F, 3) vertex indices.
    """
    if len(faces) == 0:
        return False
    _, weld = np.unique(np.asarray(positions), axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    G = weld[np.asarray(faces)]
    kept = (G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 2] != G[:, 0])
    G = G[kept]
    if len(G) == 0:
        return False
    n = int(weld.max()) + 1
    a = np.concatenate([G[:, 0], G[:, 1], G[:, 2]])
    b = np.concatenate([G[:, 1], G[:, 2], G[:, 0]])
    edges = np.sort(a * n + b)
    if (np.diff(edges) == 0).any():
        return False
    reverse = b * n + a
    k = np.searchsorted(edges, reverse)
    if not (edges[np.minimum(k, len(edges) - 1)] == reverse).all():
        return False
    # each closed shell on its own: an inside-out shell inside (or beside) an outward one would
    # be culled wrongly if only the total volume were tested
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    _, shell = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)), directed=False)
    P = np.asarray(positions, dtype=np.float64)[np.asarray(faces)[kept]]
    volumes = np.einsum("ij,ij->i", P[:, 0], np.cross(P[:, 1], P[:, 2])) / 6.0
    per_shell = np.bincount(shell[G[:, 0]], weights=volumes)
    return bool((per_shell[np.unique(shell[G[:, 0]])] > 0.0).all())


def provoking_layout(n_vertices: int, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Indexed layout with a distinct provoking (last) vertex per triangle.

    Greedy: in three rounds, each triangle not yet served claims its k-th corner if no other
    triangle owns it (the first claimant wins); the triangles left get a copy of their first
    corner.  Corners are rotated (winding kept) so that the owned vertex comes last.

    Returns
    -------
    source : (V',) index of the input vertex each output vertex copies (V' >= n_vertices).
    owner : (V',) triangle whose per-polygon values the vertex carries (-1: none).
    out_faces : (F, 3) indices into the output vertices, provoking vertex last.
    """
    F = np.asarray(faces, dtype=np.int64)
    T = len(F)
    owner = np.full(n_vertices, -1, dtype=np.int64)
    corner = np.full(T, -1, dtype=np.int64)
    for k in range(3):
        todo = np.flatnonzero((corner < 0) & (owner[F[:, k]] < 0))
        v, first = np.unique(F[todo, k], return_index=True)
        owner[v] = todo[first]
        corner[todo[first]] = k
    rest = np.flatnonzero(corner < 0)
    F = F.copy()
    source = np.concatenate([np.arange(n_vertices, dtype=np.int64), F[rest, 0]])
    owner = np.concatenate([owner, rest])
    F[rest, 0] = n_vertices + np.arange(len(rest))
    corner[rest] = 0
    rows = np.arange(T)[:, None]
    order = (corner[:, None] + np.array([1, 2, 3])) % 3
    return source, owner, F[rows, order]
