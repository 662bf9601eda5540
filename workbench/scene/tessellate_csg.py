"""CSG tessellation by real mesh booleans (manifold3d), used by :mod:`.tessellate`.

Each leaf is tessellated as a closed, welded solid in world space and tagged with its index as
an extra vertex property; manifold3d carries properties through union / intersection /
difference, so every output triangle knows the leaf it comes from.  Normals are then rebuilt
from the leaf: analytic for spheres and quadrics (flipped when the leaf bounds the result from
its other side, i.e. the inside of a subtracted solid), the triangle's own for boxes and meshes.
"""
from __future__ import annotations

import numpy as np

from ..core import transform as tf
from ..core.errors import WorkbenchError
from ..core.tol import tol
from . import model as m
from .tessellate import (Part, _box_faces, _named_radii, _quadric_gradient, _quadric_solid, _sphere,
                         triangle_normals)


def _leaf_manifold(leaf: m.SceneObject, M: np.ndarray, level: int, leaf_id: int):
    """Closed manifold of one leaf in world space, vertex properties (x, y, z, leaf_id)."""
    import manifold3d
    if isinstance(leaf, m.Sphere):
        P, _, F, _, _ = _sphere(leaf, level)
    elif isinstance(leaf, m.Box):
        quads = _box_faces(leaf)
        P = np.unique(np.vstack(quads), axis=0)
        F = []
        for q in quads:
            ids = [int(np.flatnonzero((P == c).all(1))[0]) for c in q]
            F += [(ids[0], ids[1], ids[2]), (ids[0], ids[2], ids[3])]
        F = np.array(F, dtype=np.int64)
    elif isinstance(leaf, m.Quadric):
        closed = _closed_named_quadric(leaf, level)
        P, F = closed if closed is not None else _quadric_solid(leaf, level)
    elif isinstance(leaf, m.Mesh):
        import trimesh
        tm = trimesh.Trimesh(np.asarray(leaf.vertices), np.asarray(leaf.faces), process=True)
        if not tm.is_watertight:
            raise WorkbenchError(f"CSG leaf mesh {leaf.name or leaf.source!r} is not watertight: "
                                 "mesh booleans need closed solids")
        P, F = np.asarray(tm.vertices), np.asarray(tm.faces, dtype=np.int64)
    else:
        raise WorkbenchError(f"CSG needs solids; a {leaf.kind} has no inside")
    Pw = tf.transform_points(M, P)
    if np.linalg.det(M[:3, :3]) < 0:  # a mirroring transform turns the winding inside out
        F = F[:, ::-1]
    props = np.concatenate([Pw, np.full((len(Pw), 1), float(leaf_id))], 1).astype(np.float32)
    man = manifold3d.Manifold(manifold3d.Mesh(vert_properties=np.ascontiguousarray(props),
                                              tri_verts=np.ascontiguousarray(F, dtype=np.uint32)))
    if man.status() != manifold3d.Error.NoError:
        raise WorkbenchError(f"CSG leaf {leaf.name or leaf.kind!r} is not a closed manifold ({man.status()})")
    return man


def _closed_named_quadric(q: m.Quadric, level: int):
    """Closed welded mesh (points, faces) of an ellipsoid inside its bounds, or of a cylinder
    whose x/z bounds do not cut it (a tube and two cap fans); None for the other cases (the
    level set handles them)."""
    ra, rb, rc = _named_radii(q)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    if q.shape == "ellipsoid" and np.all(lo <= [-ra, -rb, -rc]) and np.all(hi >= [ra, rb, rc]):
        P, _, F, _, _ = _sphere(m.Sphere(q.material), level)
        return P * [ra, rb, rc], F
    if q.shape == "cylinder" and np.all(lo[[0, 2]] <= [-ra, -rc]) and np.all(hi[[0, 2]] >= [ra, rc]):
        n_phi, n_y = 8 * level, 2 * level
        phi = np.arange(n_phi) * (2 * np.pi / n_phi)
        ring = np.stack([ra * np.cos(phi), np.zeros(n_phi), -rc * np.sin(phi)], -1)
        ys = np.linspace(lo[1], hi[1], n_y + 1)
        P = np.vstack([ring + [0.0, y, 0.0] for y in ys] + [[[0.0, lo[1], 0.0]], [[0.0, hi[1], 0.0]]])
        j = np.arange(n_phi)
        F = []
        for i in range(n_y):
            a, b = i * n_phi + j, i * n_phi + (j + 1) % n_phi
            F += [np.stack([a, b, b + n_phi], -1), np.stack([a, b + n_phi, a + n_phi], -1)]
        bottom, top, last = len(P) - 2, len(P) - 1, n_y * n_phi
        F += [np.stack([np.full(n_phi, bottom), (j + 1) % n_phi, j], -1),
              np.stack([np.full(n_phi, top), last + j, last + (j + 1) % n_phi], -1)]
        F = np.vstack(F).astype(np.int64)
        # outward winding (the tube's by the quadric gradient)
        fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
        centroid_dir = P[F].mean(1) - P.mean(0)
        if np.sum(fn * centroid_dir) < 0:
            F = F[:, ::-1]
        return P, F
    return None


def _build(node: m.SceneObject, M: np.ndarray, level: int, leaves: list):
    """Recursive boolean; ``leaves`` collects (leaf, world_from_leaf) by leaf id."""
    Mn = M @ node.world_from_object
    if not isinstance(node, m.CSG):
        leaves.append((node, Mn))
        return _leaf_manifold(node, Mn, int(node.tessellation or level), len(leaves) - 1)
    a = _build(node.left, Mn, level, leaves)
    b = _build(node.right, Mn, level, leaves)
    return {"union": a + b, "intersection": a ^ b, "difference": a - b}[node.op]


def _leaf_normals(leaf: m.SceneObject, M: np.ndarray, Pw: np.ndarray, tri_n: np.ndarray) -> np.ndarray:
    """Shading normals (3T, 3) for the unwelded triangles (T, 3, 3) ``Pw`` of one leaf:
    analytic on spheres and quadric surfaces, the triangle's own on boxes, meshes and the caps
    that close a quadric at its bounds."""
    flat = np.repeat(tri_n, 3, axis=0)
    P = Pw.reshape(-1, 3)
    if not isinstance(leaf, (m.Sphere, m.Quadric)):
        return flat
    P_obj = tf.transform_points(np.linalg.inv(M), P)
    if isinstance(leaf, m.Sphere):
        n_obj = P_obj - np.asarray(leaf.center)
        cap = np.zeros(len(P), dtype=bool)
    else:
        n_obj = _quadric_gradient(np.asarray(leaf.Q), P_obj)
        lo, hi = np.asarray(leaf.bounds_min), np.asarray(leaf.bounds_max)
        T = P_obj.reshape(-1, 3, 3)
        on = np.zeros(len(T), dtype=bool)
        for axis in range(3):
            for plane in (lo[axis], hi[axis]):
                on |= (np.abs(T[:, :, axis] - plane) <= tol.planar * (hi[axis] - lo[axis])).all(1)
        cap = np.repeat(on, 3)
    N = tf.transform_normals(M, n_obj)
    # a leaf seen from its inside (subtracted): flip by the area-weighted majority
    if np.sum(N[~cap] * flat[~cap]) < 0:
        N = -N
    ok = (np.linalg.norm(N, axis=-1) > 0.5) & ~cap
    return np.where(ok[:, None], N, flat)


def csg_parts(node: m.CSG, level: int, parent: np.ndarray) -> list[Part]:
    """Parts of a CSG node (one per leaf whose surface survives the boolean).

    Parameters
    ----------
    node : the CSG node; level : tessellation level of its leaves;
    parent : (4, 4) transform applied after the node's own ``world_from_object`` (identity
        for a top-level object).
    """
    leaves: list = []
    result = _build(node, parent, level, leaves)
    mesh = result.to_mesh()
    props = np.asarray(mesh.vert_properties, dtype=np.float64)
    F = np.asarray(mesh.tri_verts, dtype=np.int64)
    if len(F) == 0:
        return []
    leaf_of_tri = np.rint(props[F[:, 0], 3]).astype(np.int64)
    parts = []
    for i, (leaf, Ml) in enumerate(leaves):
        Fi = F[leaf_of_tri == i]
        if len(Fi) == 0:
            continue
        Pw = props[Fi][:, :, :3]  # (T, 3, 3), unwelded
        tri_n = triangle_normals(Pw.reshape(-1, 3), np.arange(3 * len(Fi)).reshape(-1, 3))
        N = _leaf_normals(leaf, Ml, Pw, tri_n)
        P = Pw.reshape(-1, 3)
        faces = np.arange(len(P), dtype=np.int64).reshape(-1, 3)
        parts.append(Part(node.name or leaf.name, "csg", leaf.material, Ml, P, tf.normalize(N),
                          tf.transform_points(np.linalg.inv(Ml), P), None, faces, tri_n, Pw.mean(1)))
    return parts
