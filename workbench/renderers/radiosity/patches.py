"""Patches: every surface of a scene cut into planar pieces no larger than ``patch_size``.

Planar surfaces (polygons, plane rectangles, box faces, area lights) are cut directly (quads
into bilinear grids, other polygons into fans of subdivided triangles); curved ones (spheres,
quadrics, CSG) are tessellated by :mod:`workbench.scene.tessellate` at the level whose
triangles are about ``patch_size`` long, one patch per triangle; meshes keep their triangles
(cut further if longer than ``patch_size``).

A patch is a planar quadrilateral or triangle (a triangle is stored as a quad whose last vertex
repeats its third, so that every patch has four corners).  Each surface (one polygon, one face
of a box, one triangle of a mesh, one area light) is cut into a grid of patches that share
their corners, so that the radiosity can be interpolated to vertices for Gouraud display
(Cohen & Greenberg 1985) without smearing it across the crease between two surfaces.

Emitters: an area light's patches emit its radiance ``color * intensity`` and reflect nothing;
a surface whose material has ``emission`` emits it.  Reflectance is ``Material.reflectance``
(``kd * color``, RGB).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...core import transform as tf
from ...core.errors import WorkbenchError
from ...core.tol import tol
from ...scene import model as m
from ...scene.kinds import kind_of
from ...scene.kinds.mesh import edge_max
from ...scene.tessellate import tessellate_object
from ..support import Note

MAX_CURVED_LEVEL = 24   # finest tessellation level asked of workbench.scene.tessellate


@dataclass(frozen=True)
class PatchSet:
    """Patches of a scene (``P`` patches, ``V`` display vertices).

    Attributes
    ----------
    corners : (P, 4, 3) float64
        Corners counter-clockwise seen from the front; a triangle repeats its third corner.
    vertex_ids : (P, 4) int64
        Index of each corner in ``vertices`` (shared between neighbours of one surface).
    vertices : (V, 3) float64
        Display vertices.
    surface : (P,) int64
        Index of the surface (scene object, box face, light) each patch was cut from.
    emission : (P, 3) float64
        Emitted radiance.
    reflectance : (P, 3) float64
        Diffuse reflectance rho.
    surface_names : tuple of str
        Name of each surface.
    surface_objects : tuple
        The scene object (or light) each surface belongs to, ``None`` for raw polygons.
    grids : tuple of :class:`Grid`
        The quadrilateral surfaces cut into bilinear grids (the hemicube draws each as a few
        large quads and finds the patch per pixel, instead of two triangles per patch).
    """

    corners: np.ndarray
    vertex_ids: np.ndarray
    vertices: np.ndarray
    surface: np.ndarray
    emission: np.ndarray
    reflectance: np.ndarray
    surface_names: tuple = ()
    surface_objects: tuple = ()
    grids: tuple = ()

    def __len__(self) -> int:
        return len(self.corners)

    @property
    def normals(self) -> np.ndarray:
        """(P, 3) unit normals (Newell's cross product of the diagonals; zero for zero area)."""
        c = self.corners
        return tf.normalize(np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 1]))

    @property
    def areas(self) -> np.ndarray:
        """(P,) areas: half the norm of the diagonals' cross product (exact for planar quads
        and for triangles stored with a repeated corner)."""
        c = self.corners
        return 0.5 * np.linalg.norm(np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 1]), axis=-1)

    @property
    def centres(self) -> np.ndarray:
        """(P, 3) area centroids (the hemicube's eye point)."""
        c = self.corners
        t1 = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
        t2 = np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 0])
        n = self.normals
        a1, a2 = np.abs((t1 * n).sum(-1)), np.abs((t2 * n).sum(-1))
        g1, g2 = (c[:, 0] + c[:, 1] + c[:, 2]) / 3, (c[:, 0] + c[:, 2] + c[:, 3]) / 3
        s = a1 + a2
        w1 = np.divide(a1, s, out=np.full_like(s, 0.5), where=s > 0)
        return w1[:, None] * g1 + (1 - w1[:, None]) * g2

    @property
    def extent(self) -> float:
        """Diagonal of the patches' bounding box (the scale of every relative tolerance)."""
        if len(self) == 0:
            return 1.0
        p = self.corners.reshape(-1, 3)
        return float(max(np.linalg.norm(p.max(0) - p.min(0)), tol.zero))

    def triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """Two triangles per patch (degenerate second one for a triangle patch).

        Returns
        -------
        positions : (2P, 3, 3) float64, counter-clockwise from the front.
        patch : (2P,) int64, the patch of each triangle.
        """
        c = self.corners
        tri = np.stack([c[:, [0, 1, 2]], c[:, [0, 2, 3]]], 1).reshape(-1, 3, 3)
        return tri, np.repeat(np.arange(len(self)), 2)

    def geometry(self):
        """The patches as form-factor :class:`~.geometry.Geometry`."""
        from .geometry import Geometry
        tri, patch = self.triangles()
        return Geometry(tri, patch, self.centres, self.normals, self.areas, list(self.corners),
                        self.grids)

    def vertex_values(self, values: np.ndarray) -> np.ndarray:
        """Patch values (P, C) interpolated to vertices (V, C): the area-weighted mean of the
        patches around each vertex (all of one surface, since surfaces share no vertices)."""
        values = np.asarray(values, dtype=np.float64).reshape(len(self), -1)
        w = np.repeat(self.areas[:, None], 4, 1)
        # a triangle's repeated corner must count once
        w[:, 3] = np.where(self.vertex_ids[:, 3] == self.vertex_ids[:, 2], 0.0, w[:, 3])
        V = len(self.vertices)
        num = np.zeros((V, values.shape[1]))
        den = np.zeros(V)
        for k in range(4):
            np.add.at(num, self.vertex_ids[:, k], w[:, k, None] * values)
            np.add.at(den, self.vertex_ids[:, k], w[:, k])
        # a vertex touched only by zero-area patches takes their plain mean
        cnt = np.zeros(V)
        plain = np.zeros((V, values.shape[1]))
        for k in range(4):
            np.add.at(cnt, self.vertex_ids[:, k], 1.0)
            np.add.at(plain, self.vertex_ids[:, k], values)
        return np.where(den[:, None] > 0, num / np.where(den > 0, den, 1.0)[:, None],
                        plain / np.maximum(cnt, 1.0)[:, None])


@dataclass(frozen=True)
class Grid:
    """A quadrilateral surface cut into an ``nu`` x ``nv`` bilinear grid of patches.

    quad : (4, 3) corners q0..q3, counter-clockwise from the front; the patch corners are
        (1-a)(1-b) q0 + a(1-b) q1 + ab q2 + (1-a)b q3 at a = i/nu, b = j/nv.
    nu, nv : cells along q0 -> q1 and along q0 -> q3.
    first : index of cell (0, 0); cell (i, j) is patch ``first + i * nv + j``.
    """

    quad: np.ndarray
    nu: int
    nv: int
    first: int

    def corners(self, a0: float, a1: float, b0: float, b1: float) -> np.ndarray:
        """(4, 3) corners of the block of parameters [a0, a1] x [b0, b1]."""
        q = self.quad
        a = np.array([a0, a1, a1, a0])[:, None]
        b = np.array([b0, b0, b1, b1])[:, None]
        return (1 - a) * (1 - b) * q[0] + a * (1 - b) * q[1] + a * b * q[2] + (1 - a) * b * q[3]


# --------------------------------------------------------------------------- splitting
def _grid_shape(q: np.ndarray, h: float) -> tuple[int, int]:
    """Cells (nu, nv) of the bilinear grid on quad ``q`` with edges no longer than ``h``."""
    nu = max(1, int(np.ceil(max(np.linalg.norm(q[1] - q[0]), np.linalg.norm(q[2] - q[3])) / h)))
    nv = max(1, int(np.ceil(max(np.linalg.norm(q[3] - q[0]), np.linalg.norm(q[2] - q[1])) / h)))
    return nu, nv


def _split_quad(q: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear grid on a planar quad ``q`` (4, 3) with cells no longer than ``h``
    (cell (i, j), i along q0 -> q1, is number i * nv + j).

    Returns grid vertices (V, 3) and cells (C, 4) as vertex indices."""
    nu, nv = _grid_shape(q, h)
    a, b = np.meshgrid(np.linspace(0, 1, nu + 1), np.linspace(0, 1, nv + 1), indexing="ij")
    a, b = a.reshape(-1, 1), b.reshape(-1, 1)
    verts = (1 - a) * (1 - b) * q[0] + a * (1 - b) * q[1] + a * b * q[2] + (1 - a) * b * q[3]
    idx = np.arange((nu + 1) * (nv + 1)).reshape(nu + 1, nv + 1)
    cells = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    return verts, cells


def _split_triangle(t: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Regular subdivision of a triangle ``t`` (3, 3) into n^2 triangles with edges <= ``h``.

    Returns vertices (V, 3) and cells (n^2, 4) (triangles with a repeated third corner)."""
    n = max(1, int(np.ceil(max(np.linalg.norm(t[1] - t[0]), np.linalg.norm(t[2] - t[1]),
                                np.linalg.norm(t[0] - t[2])) / h)))
    ids, verts = {}, []
    for i in range(n + 1):
        for j in range(n + 1 - i):
            ids[i, j] = len(verts)
            verts.append(t[0] + (t[1] - t[0]) * (i / n) + (t[2] - t[0]) * (j / n))
    cells = []
    for i in range(n):
        for j in range(n - i):
            a, b, c = ids[i, j], ids[i + 1, j], ids[i, j + 1]
            cells.append((a, b, c, c))
            if i + j < n - 1:
                d = ids[i + 1, j + 1]
                cells.append((b, d, c, c))
    return np.array(verts), np.array(cells, dtype=np.int64)


def split_polygon(poly: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Cut a planar convex polygon (k, 3), k >= 3, into patches no larger than ``h``.

    A quadrilateral becomes a bilinear grid of quads, any other polygon a fan of triangles
    each subdivided regularly.  ``h = inf`` keeps the polygon whole (as quads/triangles).

    Returns vertices (V, 3) and cells (C, 4) (corner indices, triangles repeat corner 2)."""
    poly = np.asarray(poly, dtype=np.float64)
    if len(poly) == 4:
        return _split_quad(poly, h)
    verts, cells = [], []
    for k in range(1, len(poly) - 1):
        v, c = _split_triangle(poly[[0, k, k + 1]], h)
        cells.append(c + sum(len(x) for x in verts))
        verts.append(v)
    return np.concatenate(verts), np.concatenate(cells)


def _curved(obj, h: float) -> list:
    """World-space triangle meshes (vertices, faces, material name) of a curved object from
    :mod:`workbench.scene.tessellate`, at the level whose triangles are about ``h`` long."""
    base = tessellate_object(obj, 1)
    e1 = max((edge_max(p.positions, p.faces) for p in base), default=0.0)
    level = int(np.clip(np.ceil(e1 / h), 1, MAX_CURVED_LEVEL)) if np.isfinite(h) else 1
    parts = base if level == 1 else tessellate_object(obj, level)
    return [(p.positions, p.faces, p.material) for p in parts]


def _surfaces(scene: m.Scene, h: float) -> tuple[list, list[str]]:
    """World-space surfaces of a scene, each ``(kind, geometry, material or None, emission,
    object, name)``: kind ``"polygon"`` (a planar convex polygon (k, 3), cut later) or
    ``"mesh"`` (vertices (V, 3), faces (F, 3): one patch per triangle, shared vertices).
    Also returns the ``left_out`` notes (:class:`..support.Note`)."""
    out, left_out = [], []
    for i, obj in enumerate(scene.objects):
        name = obj.name or f"{obj.kind}_{i}"
        mat = scene.material_of(obj)
        emis = np.asarray(mat.emission, dtype=np.float64)
        cut = getattr(kind_of(obj), "patch_surfaces", None)  # optional for a plugin kind
        surfaces = None if cut is None else cut(obj, obj.world_from_object, h)
        if surfaces is None:  # curved (or a plugin kind): one patch per triangle of its tessellation
            try:
                parts = _curved(obj, h)
            except WorkbenchError as e:
                left_out.append(Note(kind_of(obj).FEATURE, f"{obj.kind} {name!r} not cut into patches ({e})"))
                continue
            for k, (P, F, mname) in enumerate(parts):
                pm = scene.materials[mname]
                out.append(("mesh", (P, F), pm, np.asarray(pm.emission, dtype=np.float64), obj,
                            name if len(parts) == 1 else f"{name}[{k}]"))
            continue
        for k, (kind, geo) in enumerate(surfaces):
            out.append((kind, geo, mat, emis, obj, name if len(surfaces) == 1 else f"{name}[{k}]"))
    for k, polygon, mat in scene.area_light_polygons():
        out.append(("polygon", np.asarray(polygon.vertices), None, np.asarray(mat.emission),
                    scene.lights[k], f"area_light_{k}"))
    return out, left_out


def _assemble(surfaces: list, h: float) -> PatchSet:
    """Cut each surface ``(kind, geometry, reflectance, emission, object, name)`` into
    patches."""
    corners, vids, verts, surf, E, R, grids = [], [], [], [], [], [], []
    nv = npatch = 0
    for s, (kind, geo, rho, emis, _obj, _name) in enumerate(surfaces):
        if kind == "polygon":
            v, cells = split_polygon(geo, h)
            if len(geo) == 4:
                grids.append(Grid(np.asarray(geo, dtype=np.float64), *_grid_shape(geo, h), npatch))
        else:
            v, F = geo
            cells = np.concatenate([F, F[:, 2:3]], 1)
        corners.append(v[cells])
        vids.append(cells + nv)
        verts.append(v)
        nv += len(v)
        npatch += len(cells)
        surf.append(np.full(len(cells), s))
        E.append(np.broadcast_to(emis, (len(cells), 3)))
        R.append(np.broadcast_to(rho, (len(cells), 3)))
    if not corners:
        z3 = np.zeros((0, 3))
        return PatchSet(np.zeros((0, 4, 3)), np.zeros((0, 4), np.int64), z3, np.zeros(0, np.int64),
                        z3, z3)
    return PatchSet(np.concatenate(corners), np.concatenate(vids), np.concatenate(verts),
                    np.concatenate(surf), np.concatenate(E).astype(np.float64),
                    np.concatenate(R).astype(np.float64),
                    tuple(x[5] for x in surfaces), tuple(x[4] for x in surfaces), tuple(grids))


def patches_from_scene(scene: m.Scene, patch_size: float) -> tuple[PatchSet, list[str]]:
    """Cut every surface of ``scene`` into patches no longer than ``patch_size`` (scene units;
    curved surfaces: triangles about that long).

    Returns the patches and the ``left_out`` list (objects that could not be cut, with why).
    """
    if not (patch_size > 0 and np.isfinite(patch_size)):
        raise WorkbenchError(f"patch_size must be a positive length in scene units, got {patch_size!r}")
    surfaces, left_out = _surfaces(scene, patch_size)
    surfaces = [(k, g, np.zeros(3) if mat is None else mat.reflectance, e, o, n)
                for k, g, mat, e, o, n in surfaces]
    return _assemble(surfaces, patch_size), left_out


def count_patches(scene: m.Scene, patch_size: float) -> int:
    """The number of patches :func:`patches_from_scene` would cut (same grids and subdivisions,
    counted from the surfaces' edge lengths without building a patch), for the memory estimate
    before anything is allocated.  ``patch_size`` in scene units, positive."""
    if not (patch_size > 0 and np.isfinite(patch_size)):
        raise WorkbenchError(f"patch_size must be a positive length in scene units, got {patch_size!r}")
    total, fans = 0, []
    meshes = [o for o in scene.objects if isinstance(o, m.Mesh)]
    for obj in meshes:  # as _surfaces, vectorised: one patch per triangle, or n^2 if too long
        Pw = tf.transform_points(obj.world_from_object, np.asarray(obj.vertices))
        fans.append(Pw[np.asarray(obj.faces, dtype=np.int64)])
        if edge_max(Pw, np.asarray(obj.faces, dtype=np.int64)) <= patch_size:
            total += len(fans.pop())
    rest = replace(scene, objects=tuple(o for o in scene.objects if not isinstance(o, m.Mesh)))
    for kind, geo, *_ in _surfaces(rest, patch_size)[0]:
        if kind == "mesh":
            total += len(geo[1])
        elif len(geo) == 4:
            nu, nv = _grid_shape(geo, patch_size)
            total += nu * nv
        else:  # a fan of triangles, each cut regularly into n^2 (as _split_triangle)
            g = np.asarray(geo, dtype=np.float64)
            fans.append(np.stack([np.broadcast_to(g[0], (len(g) - 2, 3)), g[1:-1], g[2:]], 1))
    if fans:
        tri = np.concatenate(fans)
        edge = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=-1).max(1)
        n = np.maximum(1.0, np.ceil(edge / patch_size))
        total += int((n * n).sum())
    return int(total)


def patch_size_for_count(scene: m.Scene, count: int) -> float:
    """The patch size that cuts ``scene``'s planar surfaces into about ``count`` patches
    (total area / count, square cells)."""
    surfaces, _ = _surfaces(scene, np.inf)
    area = sum(0.5 * np.linalg.norm(np.cross(g[1:-1] - g[0], g[2:] - g[0]).sum(0))
               for k, g, *_ in surfaces if k == "polygon")
    return float(np.sqrt(area / max(count, 1)))
