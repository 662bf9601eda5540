"""Tessellation of every object kind to triangles, for the raster methods (and pyrender, the UI,
radiosity if it wants meshes).

API
---
``tessellate_scene(scene, level) -> list[Part]`` and ``tessellate_object(obj, scene, level)
-> list[Part]``.  A :class:`Part` is a triangle set with ONE material: every object gives one
part, except a CSG node, which gives one part per leaf whose surface survives the boolean.
Everything is in world space except ``obj_positions`` (the points in the object space of the
object, or of the CSG leaf, they belong to: what textures are evaluated on, see
:mod:`workbench.renderers.texturing`).

Quality knob ``level`` (an object's own ``tessellation`` overrides it):

=========== =====================================================================
sphere      UV sphere, ``4 level`` rings x ``8 level`` segments, analytic normals
plane       the rectangle cut in ``2 level x 2 level`` cells
box         each face cut in ``level x level`` cells, face normals
polygon     fan of triangles of each convex piece (a concave polygon's ear-clipped
            triangles, :mod:`.polygon_pieces`), each cut in ``level^2`` (barycentric grid)
quadric     surface ``P^T Q P = 0`` inside the object's bounds, not capped (open, as the
            ray tracer sees a cut quadric).  Named shapes (ellipsoid, cylinder, cone,
            hyperboloids, paraboloid): parametric surfaces of revolution, ``4 level`` rows x
            ``8 level`` segments, cut along the bounds' planes.  General Q: marching
            tetrahedra (manifold3d's ``level_set``) on a grid of about ``8 level`` cells
            along the bounds' diagonal, vertices pulled onto the surface by Newton steps.
            Normals: the gradient ``Q P``
mesh        as given (the level does not apply); its normals, or the face normal
csg         leaves tessellated as closed solids (quadrics capped by their bounds), then
            real mesh booleans by manifold3d; normals from each leaf (analytic for spheres
            and quadrics, faces for boxes and meshes), flipped where a leaf's surface
            bounds the result from the other side (the inside of a difference).  Closed
            quadric leaves: ellipsoids (scaled UV sphere) and cylinders whose x/z bounds
            do not cut them (tube + caps) directly, other quadrics by the level set
=========== =====================================================================

Triangles are counter-clockwise seen from the side their normal points to.  Shading normals
are never zero: a vertex normal that cancels (``< tol.normal_cancel``) is replaced by its
triangle's face normal.  ``face_normals`` and ``face_centroids`` are those of the source
polygon (the whole rectangle, box face or polygon), so that flat shading gives one colour per
polygon as the course draws it.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..core import transform as tf
from ..core.errors import WorkbenchError
from ..core.tol import tol
from . import model as m
from .mesh_normals import mean_face_normals
from .polygon_pieces import convex_pieces

DEFAULT_LEVEL = 6


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


def _fix_normals(N: np.ndarray, P: np.ndarray, F: np.ndarray) -> np.ndarray:
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


# --------------------------------------------------------------------------- object-space builders
# Each returns (P, N, F, face_normal, face_centroid) in object space.
def _sphere(s: m.Sphere, level: int):
    n_lat, n_lon = 4 * level, 8 * level
    th = np.linspace(0.0, np.pi, n_lat + 1)[1:-1]  # interior rings
    ph = np.arange(n_lon) * (2 * np.pi / n_lon)
    T, Ph = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([np.sin(T) * np.cos(Ph), np.cos(T), -np.sin(T) * np.sin(Ph)], -1).reshape(-1, 3)
    N = np.vstack([[0.0, 1.0, 0.0], ring, [0.0, -1.0, 0.0]])
    top, bottom = 0, len(N) - 1
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)
    F = []
    j = np.arange(n_lon)
    F.append(np.stack([np.full(n_lon, top), idx(0, j), idx(0, j + 1)], -1))
    for i in range(n_lat - 2):
        a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
        F += [np.stack([a, b, c], -1), np.stack([a, c, d], -1)]
    F.append(np.stack([idx(n_lat - 2, j), np.full(n_lon, bottom), idx(n_lat - 2, j + 1)], -1))
    F = np.vstack(F).astype(np.int64)
    P = np.asarray(s.center) + s.radius * N
    return P, N, F, None, None


def _grid_quad(corners: np.ndarray, n: int):
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


def _polygons(polys: list[np.ndarray], n: int):
    """Planar convex polygons, each as a fan cut in n^2 triangles per fan triangle; one face
    normal and centroid per polygon."""
    Ps, Fs, FN, FC, off = [], [], [], [], 0
    s = np.linspace(0.0, 1.0, n + 1)
    for poly in polys:
        normal = tf.normalize(np.cross(poly[1:-1] - poly[0], poly[2:] - poly[0]).sum(0))
        centroid = poly.mean(0)
        if len(poly) == 4:
            P, F = _grid_quad(poly, n)
        else:
            P, F = _fan(poly, s, n)
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


def _fan(poly: np.ndarray, s: np.ndarray, n: int):
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


def _box_faces(b: m.Box) -> list[np.ndarray]:
    lo, hi = np.asarray(b.min), np.asarray(b.max)
    c = np.array([[lo[0], lo[1], lo[2]], [hi[0], lo[1], lo[2]], [hi[0], hi[1], lo[2]], [lo[0], hi[1], lo[2]],
                  [lo[0], lo[1], hi[2]], [hi[0], lo[1], hi[2]], [hi[0], hi[1], hi[2]], [lo[0], hi[1], hi[2]]])
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
    return [c[list(q)] for q in quads]


def _quadric_value(Q: np.ndarray, P: np.ndarray) -> np.ndarray:
    """``P^T Q P`` with P lifted to w = 1 (N,)."""
    H = np.concatenate([P, np.ones((len(P), 1))], 1)
    return np.einsum("ni,ij,nj->n", H, Q, H)


def _quadric_gradient(Q: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Outward (towards ``P^T Q P > 0``) gradient ``2 (Q P)_xyz`` (N, 3)."""
    H = np.concatenate([P, np.ones((len(P), 1))], 1)
    return 2.0 * (H @ Q.T)[:, :3]


def _unit_quadric(q: m.Quadric) -> tuple[np.ndarray, np.ndarray]:
    """The quadric in the unit frame of its bounds: ``(Qu, S)``.

    S (4, 4) maps the frame's coordinates onto the world's (the bounds' centre at the origin,
    half their diagonal as unit length), and ``Qu = S^T Q S / max |S^T Q S|``: the same surface,
    ``P^T Qu P`` of order 1 over the bounds, and the same Qu for the quadric scaled, moved or
    multiplied by any constant.  Work done in this frame (level set, gradient floors) does not
    depend on the scene's scale."""
    Q = np.asarray(q.Q, dtype=np.float64)
    lo, hi = np.asarray(q.bounds_min, dtype=np.float64), np.asarray(q.bounds_max, dtype=np.float64)
    S = np.eye(4)
    S[:3, :3] *= 0.5 * float(np.linalg.norm(hi - lo))
    S[:3, 3] = 0.5 * (lo + hi)
    Qu = S.T @ Q @ S
    return Qu / np.abs(Qu).max(), S


def _quadric_solid(q: m.Quadric, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed mesh of ``{P^T Q P <= 0} ∩ bounds`` by marching tetrahedra (manifold3d level
    set, about ``8 level`` cells along the bounds' diagonal): points (V, 3), faces (F, 3).

    The signed function handed to manifold3d is ``min(-q(P) / |grad q(P)|, distance inside
    the box)`` (first-order distance to the quadric), evaluated with plain floats because
    manifold3d calls it once per grid point.  The level set is built in
    :func:`_unit_quadric`'s frame (so that manifold3d's own tolerances, and the floor
    ``tol.normal_cancel`` of ``|grad q|``, which vanishes at an ellipsoid's centre, meet the
    same numbers at every scale); its points are then scaled and moved onto the bounds."""
    import manifold3d
    Qu, S = _unit_quadric(q)
    Q = [[float(x) for x in row] for row in Qu]
    k, c = float(S[0, 0]), S[:3, 3]
    lo = [float(x) for x in (np.asarray(q.bounds_min) - c) / k]
    hi = [float(x) for x in (np.asarray(q.bounds_max) - c) / k]
    h = 2.0 / (8.0 * level)          # the frame's diagonal is 2
    floor = tol.normal_cancel

    def sdf(x, y, z):
        p = (x, y, z, 1.0)
        qp = [Q[i][0] * x + Q[i][1] * y + Q[i][2] * z + Q[i][3] for i in range(4)]
        value = qp[0] * p[0] + qp[1] * p[1] + qp[2] * p[2] + qp[3]
        grad = 2.0 * (qp[0] * qp[0] + qp[1] * qp[1] + qp[2] * qp[2]) ** 0.5
        inside_box = min(x - lo[0], y - lo[1], z - lo[2], hi[0] - x, hi[1] - y, hi[2] - z)
        return min(-value / max(grad, floor), inside_box)

    pad = 2.5 * h    # the lower box faces half a cell off the grid: no sdf sign left to rounding there
    bounds = [lo[0] - pad, lo[1] - pad, lo[2] - pad, hi[0] + pad, hi[1] + pad, hi[2] + pad]
    mesh = manifold3d.Manifold.level_set(sdf, bounds, h).to_mesh()
    U = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    return c + k * U, np.asarray(mesh.tri_verts, dtype=np.int64)


def _named_radii(q: m.Quadric) -> tuple[float, float, float]:
    """(ra, rb, rc) of a named quadric, read back from its Q (see ``io.quadric_matrix``)."""
    Q = np.asarray(q.Q)
    ra, rc = 1.0 / np.sqrt(abs(Q[0, 0])), 1.0 / np.sqrt(abs(Q[2, 2]))
    rb = -0.5 / Q[1, 3] if q.shape == "paraboloid" else (1.0 / np.sqrt(abs(Q[1, 1])) if Q[1, 1] else 1.0)
    return ra, rb, rc


def _revolution(q: m.Quadric, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Parametric surface of a named quadric (elliptic surface of revolution about y),
    ``x = ra rho(t) cos(phi)``, ``z = -rc rho(t) sin(phi)``, ``y = y(t)``, over the bounds'
    y range, before cutting to the bounds: points, faces (outward winding)."""
    ra, rb, rc = _named_radii(q)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    n_t, n_phi = 4 * level, 8 * level
    t = np.linspace(0.0, 1.0, n_t + 1)
    sheets = []  # (rho(t), y(t)) rows, each sheet swept about y
    if q.shape == "ellipsoid":
        th = np.pi * t
        sheets.append((np.sin(th), rb * np.cos(th)))
    elif q.shape == "paraboloid":
        y0, y1 = max(lo[1], 0.0), max(hi[1], 0.0)
        y = y0 + (y1 - y0) * t
        sheets.append((np.sqrt(np.maximum(y / rb, 0.0)), y))
    elif q.shape == "hyperboloid2":
        ymax = max(abs(lo[1]), abs(hi[1]))
        rho = np.sqrt(max(ymax * ymax / (rb * rb) - 1.0, 0.0)) * t
        sheets += [(rho, rb * np.sqrt(1.0 + rho * rho)), (rho[::-1], -rb * np.sqrt(1.0 + rho[::-1] ** 2))]
    else:
        y = np.union1d(lo[1] + (hi[1] - lo[1]) * t, [0.0] if lo[1] < 0 < hi[1] else [])[::-1]
        rho = {"cylinder": np.ones_like(y), "cone": np.abs(y) / rb,
               "hyperboloid": np.sqrt(1.0 + (y / rb) ** 2)}[q.shape]
        sheets.append((rho, y))
    phi = np.arange(n_phi) * (2 * np.pi / n_phi)
    Ps, Fs, off = [], [], 0
    for rho, y in sheets:
        R, Ph = np.meshgrid(rho, phi, indexing="ij")
        P = np.stack([ra * R * np.cos(Ph), np.broadcast_to(y[:, None], R.shape), -rc * R * np.sin(Ph)], -1)
        i, j = np.meshgrid(np.arange(len(rho) - 1), np.arange(n_phi), indexing="ij")
        a, b = (i * n_phi + j).ravel(), (i * n_phi + (j + 1) % n_phi).ravel()
        c, d = a + n_phi, b + n_phi
        Ps.append(P.reshape(-1, 3))
        Fs.append(np.vstack([np.stack([a, c, d], -1), np.stack([a, d, b], -1)]) + off)
        off += len(Ps[-1])
    P, F = np.vstack(Ps), np.vstack(Fs).astype(np.int64)
    # orient outwards (gradient of P^T Q P) by the area-weighted majority
    if np.sum(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
              * _quadric_gradient(np.asarray(q.Q), P[F].mean(1))) < 0:
        F = F[:, ::-1]
    return P, F


def _cut_to_bounds(P: np.ndarray, F: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Keep the part of a triangle mesh inside the box [lo, hi] (triangles split along the box
    planes, no caps)."""
    from trimesh.intersections import slice_faces_plane
    for axis in range(3):
        for sign, plane in ((1.0, lo[axis]), (-1.0, hi[axis])):
            if len(F) == 0:
                return P, F
            n = np.zeros(3)
            n[axis] = sign
            origin = np.zeros(3)
            origin[axis] = plane
            P, F = slice_faces_plane(P, F, n, origin)[:2]
    return np.asarray(P, dtype=np.float64), np.asarray(F, dtype=np.int64)


def _general_quadric(q: m.Quadric, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Surface of a general quadric inside its bounds: the level-set solid with its box caps
    removed."""
    P, F = _quadric_solid(q, level)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    on_cap = np.zeros(len(F), dtype=bool)
    for axis in range(3):
        for plane in (lo[axis], hi[axis]):
            on_cap |= (np.abs(P[F][:, :, axis] - plane) <= tol.planar * (hi[axis] - lo[axis])).all(1)
    # vertices of the crease between surface and caps are interpolated across it: pull every
    # vertex onto the surface (Newton steps along the gradient), staying inside the bounds
    Qu, S = _unit_quadric(q)
    k, c = S[0, 0], S[:3, 3]
    U, ulo, uhi = (P - c) / k, (lo - c) / k, (hi - c) / k   # in the unit frame
    for _ in range(3):
        g = _quadric_gradient(Qu, U)
        g2 = np.maximum(np.sum(g * g, -1), tol.normal_cancel ** 2)
        U = np.clip(U - (_quadric_value(Qu, U) / g2)[:, None] * g, ulo, uhi)
    P = np.clip(c + k * U, lo, hi)
    return P, F[~on_cap]


def _quadric(q: m.Quadric, level: int):
    """Open surface of a quadric cut to its bounds: named shapes parametric, general Q by
    marching tetrahedra; normals from the gradient ``Q P``."""
    if q.shape == "general":
        P, F = _general_quadric(q, level)
    else:
        P, F = _cut_to_bounds(*_revolution(q, level), np.asarray(q.bounds_min), np.asarray(q.bounds_max))
    if len(F) == 0:
        raise WorkbenchError(f"quadric {q.name or q.shape!r}: no surface inside its bounds "
                             f"{list(q.bounds_min)}..{list(q.bounds_max)}")
    used = np.unique(F)
    remap = np.full(len(P), -1)
    remap[used] = np.arange(len(used))
    P, F = P[used], remap[F]
    N = _fix_normals(_quadric_gradient(np.asarray(q.Q), P), P, F)
    return P, N, F, None, None


# --------------------------------------------------------------------------- parts
MAX_LEVEL = 64
"""Largest tessellation level accepted (a sphere at 64 has 256 x 512 quads)."""


def _level(obj: m.SceneObject, level: int) -> int:
    if not 1 <= level <= MAX_LEVEL:
        raise WorkbenchError(f"tessellation level must be within 1..{MAX_LEVEL}, got {level}")
    return int(obj.tessellation or level)


def _part(obj: m.SceneObject, M: np.ndarray, P, N, F, fn, fc, uvs=None, material=None) -> Part:
    """Object-space arrays -> world-space Part."""
    Pw = tf.transform_points(M, P)
    if np.linalg.det(np.asarray(M)[:3, :3]) < 0:  # a mirroring transform flips the winding
        F = np.asarray(F)[:, ::-1]
    Nw = _fix_normals(tf.transform_normals(M, N), Pw, F)
    if fn is None:
        fn_w, fc_w = triangle_normals(Pw, F), Pw[F].mean(1)
    else:
        fn_w, fc_w = tf.transform_normals(M, fn), tf.transform_points(M, fc)
    return Part(obj.name, obj.kind, material or obj.material, np.asarray(M, dtype=np.float64),
                Pw, Nw, np.asarray(P, dtype=np.float64), uvs, np.asarray(F, dtype=np.int64), fn_w, fc_w)


def tessellate_object(obj: m.SceneObject, level: int = DEFAULT_LEVEL,
                      parent: np.ndarray | None = None) -> list[Part]:
    """Triangles of one object (see the module docstring for what ``level`` means).

    Parameters
    ----------
    obj : any scene object.
    level : tessellation level >= 1 (the object's own ``tessellation`` wins).
    parent : (4, 4) transform applied after the object's own (CSG children).
    """
    M = obj.world_from_object if parent is None else parent @ obj.world_from_object
    L = _level(obj, level)
    if isinstance(obj, m.Sphere):
        return [_part(obj, M, *_sphere(obj, L))]
    if isinstance(obj, m.Plane):
        return [_part(obj, M, *_polygons([obj.corners()], 2 * L))]
    if isinstance(obj, m.Box):
        return [_part(obj, M, *_polygons(_box_faces(obj), L))]
    if isinstance(obj, m.Polygon):
        P, N, F, fn, fc = _polygons(convex_pieces(obj.vertices), L)
        fc[:] = np.asarray(obj.vertices).mean(0)  # one flat-shading point for the whole polygon
        return [_part(obj, M, P, N, F, fn, fc)]
    if isinstance(obj, m.Quadric):
        return [_part(obj, M, *_quadric(obj, L))]
    if isinstance(obj, m.Mesh):
        P, F = np.asarray(obj.vertices), np.asarray(obj.faces, dtype=np.int64)
        N = np.asarray(obj.normals) if obj.normals is not None else np.zeros_like(P)
        return [_part(obj, M, P, N, F, None, None,
                      None if obj.uvs is None else np.asarray(obj.uvs, dtype=np.float64))]
    if isinstance(obj, m.CSG):
        from .tessellate_csg import csg_parts
        return csg_parts(obj, L, np.eye(4) if parent is None else parent)
    raise WorkbenchError(f"cannot tessellate object kind {obj.kind!r}")


def tessellate_scene(scene: m.Scene, level: int = DEFAULT_LEVEL) -> list[Part]:
    """Parts of every object of the scene, in scene order."""
    parts: list[Part] = []
    for obj in scene.objects:
        parts.extend(tessellate_object(obj, level))
    return parts


def area_light_parts(scene: m.Scene) -> list[tuple[Part, m.Material]]:
    """Area lights as emissive polygons of radiance ``color * intensity`` (what the raster
    methods draw of them), each with its own material."""
    out = []
    for i, light in enumerate(scene.lights):
        if isinstance(light, m.AreaLight):
            mat = m.Material(f"area light {i + 1}", color=(0.0, 0.0, 0.0), ka=0.0, kd=0.0, ks=0.0,
                             emission=tuple(float(x) for x in light.radiance))
            (part,) = tessellate_object(m.Polygon(mat.name, vertices=light.vertices, name=mat.name), 1)
            out.append((part, mat))
    return out


#: Vertex-normal rules of the raster methods' ``normals`` option: ``"smooth"`` keeps the
#: tessellation's (analytic for spheres and quadrics, area-weighted for meshes), ``"face_mean"``
#: is the course's plain mean of the incident triangles' normals.
NORMAL_RULES = ("smooth", "face_mean")


def with_normal_rule(part: Part, rule: str) -> Part:
    """``part`` with its vertex normals by ``rule`` (:data:`NORMAL_RULES`; ``"face_mean"``:
    :func:`.mesh_normals.mean_face_normals`, the course's "moyenne des normales aux faces
    incidentes", over the part's triangles)."""
    if rule == "smooth":
        return part
    if rule != "face_mean":
        raise WorkbenchError(f"normals must be one of {', '.join(NORMAL_RULES)}, got {rule!r}")
    return replace(part, normals=mean_face_normals(part.positions, part.faces, part.normals))
