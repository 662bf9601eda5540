"""Turn a :class:`~workbench.scene.model.Scene` into flat arrays for the numba kernels (pbrt: the
scene is data, each renderer builds its own runtime objects).

Every analytic primitive (sphere, rectangle, box, polygon, quadric) keeps its own object space:
the ray is taken into it by ``object_from_world`` (the course's "objet transformé: appliquer la
transformation au rayon"); the ray parameter ``t`` is unchanged by an affine map, so hits of
different objects compare directly.  Triangle meshes are moved to world space once and share
one BVH.  A CSG tree becomes a postfix program over its leaves.  The top-level analytic
primitives with finite world bounds go into a structure of their own (:mod:`.accel`).

Primitive table (``P`` rows)
----------------------------
``ptype`` (P,) int: one of the ``SPHERE`` ... ``CSGNODE`` constants.
``top`` (P,) bool: intersected on its own (False for CSG leaves and meshes).
``obj`` (P,) int: index of the scene object (``len(scene.objects) + k`` for area light ``k``).
``mat`` (P,) int: material index into the material table.
``xf`` (P, 12): rows of ``object_from_world[:3, :4]``; ``nm`` (P, 9): world normal matrix
(``object_from_world[:3, :3].T``, row-major) mapping object normals to world normals.
``par`` (P, 20): per type parameters (see each kind's ``flatten`` in :mod:`workbench.scene.kinds`).
``solid`` (P,) bool: a closed surface with an inside (refraction enters a medium), else a thin
sheet (transmission goes straight through).
``shadow`` (P,) bool: casts shadows (area lights' own polygons do not).
``ident`` (P,) bool: ``object_from_world`` is the identity (the kernels skip the transform).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ...core.columns import pack
from ...core.tol import tol
from ...core.transform import transform_normals
from ...scene import model as m
from ...scene.kinds import PACKAGE_KINDS, kernel_kinds, kind_of
from ...scene.kinds.csg import CSGNODE
from ...scene.prepared import PreparedScene, prepare
from ..kernels.columns import LIGHT_COLS, Light, Mat
from ..kernels.layout import Geometry, kinds_marker, marker_name

if TYPE_CHECKING:
    from .accel import PrimTree
    from .bvh import Bvh4

OPACITY_CUT = 0.5
"""Opacity maps (model.Opacity): alpha below this cuts the surface out."""
MAX_CUTOUTS = 64
"""Cut-out surfaces a ray passes through before it stops."""
SHADOW_CROSSINGS = 32
"""Surfaces a shadow feeler goes on through (transmissive with ``transmissive_shadows``, cut out
or partly opaque by an opacity map) before it stops with the visibility gathered so far."""
NPAR = 20
_IDENTITY_ROWS = np.eye(4)[:3].reshape(-1)


@dataclass
class SceneData:
    """Arrays consumed by the kernels (all float64 / int64 / bool, C-contiguous)."""

    ptype: np.ndarray
    top: np.ndarray
    obj: np.ndarray
    mat: np.ndarray
    xf: np.ndarray
    nm: np.ndarray
    par: np.ndarray
    solid: np.ndarray
    shadow: np.ndarray
    ident: np.ndarray
    wfo: np.ndarray             # (P, 4, 4) world_from_object (texturing, bump)
    has_uv: np.ndarray          # (P,) bool: a mesh with uvs (else texturing's own mapping)
    poly_v: np.ndarray          # (K, 3) polygon vertices, object space
    csg_prog: np.ndarray        # postfix program: leaf primitive >= 0 or a CSG_* op
    tri_v: np.ndarray           # (T, 9) world-space vertices, BVH order (octree: one row per reference)
    tri_n: np.ndarray           # (T, 9) world-space vertex normals
    tri_uv: np.ndarray          # (T, 6)
    tri_e: np.ndarray           # (T, 9) vertex emission (radiance)
    tri_prim: np.ndarray        # (T,) the mesh's primitive row
    tri_src: np.ndarray         # (T,) int64 the triangle of each row: its index among the
                                # meshes' triangles in input order (octree: repeats)
    bvh: Bvh4                   # 4-wide BVH over the triangles (see .bvh)
    prims: PrimTree             # the analytic primitives' list and structure (see .accel)
    materials: list             # Material objects, index = mat
    mat_tab: np.ndarray         # (M, MAT_COLS) material table, columns ``kernels.columns.Mat``
    lights: np.ndarray          # (L, LIGHT_COLS) light table, columns ``kernels.columns.Light``
    extent: float               # diagonal of the scene's bounds (PreparedScene.extent)
    n_objects: int
    bvh_build_time: float = 0.0
    aux: np.ndarray = field(default_factory=lambda: np.zeros(1))
    """Variable-length data of the kinds that have it (blob components, an isosurface's
    program, lathe profiles, prism polygons), flat float64; each row holds its offset."""

    @property
    def has_media(self) -> bool:
        """Whether a heterogeneous medium bounds any material (``Mat.MEDIUM``)."""
        return bool((self.mat_tab[:, Mat.MEDIUM] >= 0).any())

    def media_holding(self, scene: m.Scene, point) -> list[int]:
        """Material rows of the heterogeneous media whose bounds hold the world ``point`` (the
        camera inside a hypertexture starts in its medium), in row order."""
        out = []
        for r in np.flatnonzero(self.mat_tab[self.mat, Mat.MEDIUM] >= 0):
            if self.obj[r] >= len(scene.objects):
                continue
            o = scene.objects[self.obj[r]]
            q = self.xf[r].reshape(3, 4) @ np.append(np.asarray(point, dtype=np.float64), 1.0)
            if kind_of(o).inside(o, q):
                out.append(int(self.mat[r]))
        return out

    def features(self) -> tuple[str, ...]:
        """What the kernels compile for this scene (:func:`..kernels.layout.features`), in
        groups, so that all scenes of the package's kinds together need at most four compiled
        variants of each kernel: the extended kinds (the package's kinds with kernel modules of
        their own, the media kinds hypertexture and fur among them, and CSG: all of them if the
        scene has any among its rows, CSG leaves included; one variant for all, since the
        kernels above the kinds, compiled once per variant, cost more than the kinds' own),
        each plugin kind the scene has (:func:`workbench.scene.kinds.register`), and the
        triangles' tree (if the scene has triangles, or any of the groups before: the path
        tracer turns a scene's plain planes and polygons into triangles, and its variant and the
        ray tracer's are then one: ``closest`` and ``surface`` compiled once for both, their
        triangle walk skipped at run time when there is no triangle) and the analytic rows (if it
        has a top-level row that is not a mesh: :attr:`top`)."""
        present = {int(p) for p in np.unique(self.ptype)}
        package = [k for k in kernel_kinds() if k.TYPE in PACKAGE_KINDS]
        out = []
        if present & ({k.PTYPE for k in package} | {CSGNODE}):  # all or none (one compiled variant)
            out += [k.TYPE for k in package] + ["csg"]
        out += [marker_name(k) for k in kernel_kinds() if k.TYPE not in PACKAGE_KINDS and k.PTYPE in present]
        if len(self.tri_v) or out:  # with a group of kinds, the triangles' walk whether or not it has triangles
            out.append("triangles")
        if self.top.any():
            out.append("analytic")
        return tuple(out)

    def kernel_args(self) -> Geometry:
        """The geometry record passed to every numba kernel, its kind marker naming
        :meth:`features` (kernels compiled for this set of features only)."""
        return Geometry(self.ptype, self.top, self.xf, self.nm, self.par, self.solid, self.shadow,
                        self.poly_v, self.csg_prog, self.tri_v, self.tri_n, self.tri_uv, self.tri_e,
                        self.tri_prim, *self.bvh, self.ident, self.aux, *self.prims,
                        kinds_marker(self.features()))


def _material_row(mat: m.Material, front_only: bool = False, medium: int = -1) -> np.ndarray:
    """The material's row of the material table (columns :class:`..kernels.columns.Mat`);
    ``medium``: the primitive row of the heterogeneous medium it bounds (-1: none)."""
    return pack(Mat, color=mat.color, ka=mat.ka, kd=mat.kd, ks=mat.ks, shininess=mat.shininess,
                kr=mat.kr, kt=mat.kt, ior=mat.ior, absorption=mat.absorption, emission=mat.emission,
                front_only=front_only, textured=mat.texture is not None, bumped=mat.bump is not None,
                opacity=mat.opacity is not None, environment=mat.environment, medium=medium)


def medium_boundary(name: str) -> m.Material:
    """The material of a medium kind's boundary (``MEDIUM`` kinds: the hypertexture): it lights
    nothing and refracts nothing (index 1, all transmitted), so a ray crossing it only enters
    or leaves the medium."""
    return m.Material(name=name, color=(1.0, 1.0, 1.0), ka=0.0, kd=0.0, ks=0.0, kr=0.0, kt=1.0, ior=1.0)


def light_rows(lights) -> np.ndarray:
    """(L, LIGHT_COLS) table of point and directional lights (columns
    :class:`..kernels.columns.Light`)."""
    rows = np.zeros((len(lights), LIGHT_COLS))
    for i, lt in enumerate(lights):
        directional = isinstance(lt, m.DirectionalLight)
        cosine = not directional and lt.cosine_normal is not None
        rows[i] = pack(Light, kind=float(directional),
                       position=lt.direction if directional else lt.position,
                       power=np.asarray(lt.color) * lt.intensity,
                       inverse_square=not directional and lt.falloff == "inverse_square",
                       cosine=cosine, cosine_normal=lt.cosine_normal if cosine else (0.0, 0.0, 0.0))
    return rows


BYTES_PER_ROW = 8192
"""Upper bound of a primitive row's share of a render's peak: the prepared scene's per-object
bounds, the builder's record per row, the kernel columns and the primitives' tree (measured,
ray caster at 16 x 12 with 300 to 4000 spheres: 2.4-4.9 kB a sphere; the flattening alone,
tracemalloc: 2.4-2.5 kB)."""
AUX_COPIES = 3
"""A kind's variable-length numbers (``params(obj, 0)[1]``: a lathe's profile, a blob's
components) exist at most this many times while flattening: the kind's array, the builder's
list and the concatenated ``aux`` column."""


def flatten_bytes(scene: m.Scene) -> int:
    """Upper bound of the bytes :func:`flatten` allocates for ``scene``'s analytic primitives
    (a mesh's triangles are counted apart): :data:`BYTES_PER_ROW` per row, one row per object,
    per node of a composite kind's tree (a CSG root's row and its leaves'; an inner node is
    only a code of the root's program) and per area light, plus :data:`AUX_COPIES` times the
    float64 numbers of each kind with variable-length data."""
    def node_bytes(o) -> int:
        kind = kind_of(o)
        if getattr(kind, "COMPOSITE", False):
            return BYTES_PER_ROW + sum(node_bytes(c) for c in kind.children(o))
        if hasattr(kind, "aux_count"):  # counted without building it (a hypertexture's grid)
            aux = kind.aux_count(o)
        else:
            aux = len(kind.params(o, 0)[1]) if hasattr(kind, "params") else 0
        # a grid is sampled in float32 slabs before it joins the float64 aux numbers
        grid = 4 * kind.grid_samples(o) if hasattr(kind, "grid_samples") else 0
        rows = 2 if getattr(kind, "MEDIUM", False) else 1  # a medium's own row beside a base's
        return rows * BYTES_PER_ROW + AUX_COPIES * 8 * aux + grid
    lights = sum(isinstance(lt, m.AreaLight) for lt in scene.lights)
    return sum(node_bytes(o) for o in scene.objects) + lights * BYTES_PER_ROW


class _Builder:
    """What the kinds' ``flatten`` functions write into (:mod:`workbench.scene.kinds`)."""

    def __init__(self, scene: m.Scene):
        self.scene = scene
        self.rows: list[dict] = []
        self.poly_v: list[np.ndarray] = []
        self.n_poly = 0
        self.prog: list[int] = []
        self.meshes: list[tuple[int, m.Mesh, np.ndarray]] = []
        self.materials = list(scene.materials.values())
        self.mat_index = {mt.name: i for i, mt in enumerate(self.materials)}
        self.front_only: set[int] = set()
        self.medium_of: dict[int, int] = {}  # material index -> its medium's primitive row
        self.aux: list[np.ndarray] = []
        self.n_aux = 0

    def add_aux(self, data) -> int:
        """Append a kind's variable-length data (flat floats) to the aux array; its offset."""
        data = np.asarray(data, dtype=np.float64).reshape(-1)
        self.aux.append(data)
        self.n_aux += len(data)
        return self.n_aux - len(data)

    def add(self, ptype: int, obj_index: int, obj: m.SceneObject, world_from_object, par, *,
            top=True, solid=True, shadow=True) -> int:
        """A primitive row of kind ``ptype`` for scene object ``obj_index`` with ``obj``'s
        material; ``par`` (at most ``NPAR`` numbers) is zero-padded.  Returns the row."""
        ofw = np.linalg.inv(world_from_object)
        row_par = np.zeros(NPAR)
        row_par[:len(par)] = par
        mat = self.mat_index[obj.material]
        if getattr(kind_of(obj), "MEDIUM", False):  # a boundary material of its own
            self.materials.append(medium_boundary(f"{obj.material}#medium{len(self.rows)}"))
            mat = len(self.materials) - 1
            self.medium_of[mat] = len(self.rows)
        row = dict(ptype=ptype, top=top, obj=obj_index, mat=mat,
                   xf=ofw[:3, :4].reshape(-1), nm=ofw[:3, :3].T.reshape(-1), par=row_par, solid=solid,
                   shadow=shadow, wfo=np.asarray(world_from_object, dtype=np.float64), has_uv=False)
        self.rows.append(row)
        return len(self.rows) - 1

    def leaf(self, o: m.SceneObject, obj_index: int, parent: np.ndarray, *, top: bool) -> int:
        """Rows of object ``o`` under transform ``parent`` (its kind's ``flatten``)."""
        W = parent @ np.asarray(o.world_from_object)
        return kind_of(o).flatten(self, o, obj_index, W, top)

    def area_light(self, k: int, polygon: m.Polygon, mat: m.Material):
        """Area light ``k``'s polygon: emissive from its front only, casting no shadow."""
        self.materials.append(mat)
        self.mat_index[mat.name] = len(self.materials) - 1
        self.front_only.add(len(self.materials) - 1)
        kind_of(polygon).flatten(self, polygon, len(self.scene.objects) + k, np.eye(4), True,
                                 shadow=False)


def _triangles(meshes):
    """World-space triangle arrays of every mesh, in input order."""
    tv, tn, tuv, te, tp = [], [], [], [], []
    for k, mesh, W in meshes:
        V = np.asarray(mesh.vertices, dtype=np.float64) @ W[:3, :3].T + W[:3, 3]
        F = np.asarray(mesh.faces, dtype=np.int64)
        tv.append(V[F].reshape(-1, 9))
        if mesh.normals is not None:
            # a cancelled normal is judged in object space, where normals are unit: the
            # inverse transpose scales them by 1 / scale (1e-6 at scale 1e6)
            n_obj = np.asarray(mesh.normals, dtype=np.float64)
            live = np.linalg.norm(n_obj, axis=1, keepdims=True) > tol.normal_cancel
            nrm = np.where(live, transform_normals(W, n_obj), 0.0)
            tn.append(nrm[F].reshape(-1, 9))
        else:
            tn.append(np.zeros((len(F), 9)))
        tuv.append(np.asarray(mesh.uvs, dtype=np.float64)[F].reshape(-1, 6) if mesh.uvs is not None
                   else np.zeros((len(F), 6)))
        te.append(np.asarray(mesh.vertex_emission, dtype=np.float64)[F].reshape(-1, 9)
                  if mesh.vertex_emission is not None else np.zeros((len(F), 9)))
        tp.append(np.full(len(F), k, dtype=np.int64))
    if not tv:
        z = np.zeros((0, 9))
        return z, z.copy(), np.zeros((0, 6)), z.copy(), np.zeros(0, dtype=np.int64)
    return (np.concatenate(tv), np.concatenate(tn), np.concatenate(tuv), np.concatenate(te),
            np.concatenate(tp))


def _prim_tree(rows: list[dict], owners: list, boxes: np.ndarray, accel: str, scale: float) -> PrimTree:
    """The top-level analytic primitive rows (``top``; a mesh's row is not) and their structure
    ``accel``.  ``owners`` lists the first row of each top-level object and area light, in row
    order; ``boxes`` (len(owners), 6) their world boxes ``(lo, hi)`` (the prepared scene's,
    from each kind's bound points; NaN: unbounded, tested by every ray), padded here
    (:func:`.accel.pad_boxes`)."""
    from .accel import build_prim_tree, pad_boxes
    top_rows, row_boxes = [], []
    ends = owners[1:] + [len(rows)]
    for r0, r1, box in zip(owners, ends, boxes):
        for r in range(r0, r1):
            if rows[r]["top"]:
                top_rows.append(r)
                row_boxes.append(box if accel != "none" else np.full(6, np.nan))
    row_boxes = np.array(row_boxes, dtype=np.float64).reshape(-1, 6)
    if len(row_boxes):
        with np.errstate(invalid="ignore", over="ignore"):
            row_boxes = pad_boxes(row_boxes, scale)
    return build_prim_tree(np.array(top_rows, dtype=np.int64), row_boxes, accel)


def _owner_boxes(prepared: PreparedScene) -> np.ndarray:
    """(N + K, 6) world boxes ``(lo, hi)`` of the scene's objects then area lights; NaN rows
    for objects with a bound point at infinity (:attr:`PreparedScene.unbounded`)."""
    obj = prepared.object_bounds.reshape(-1, 6).copy()
    obj[prepared.unbounded] = np.nan
    return np.concatenate([obj, prepared.light_bounds.reshape(-1, 6)])


def flatten(scene: m.Scene, accel: str = "bvh", prepared: PreparedScene | None = None) -> SceneData:
    """Build the kernel arrays for ``scene`` (area lights become emissive polygons) and the
    acceleration structure ``accel`` (:data:`.accel.ACCELS`) over the triangles and over the
    bounded analytic primitives (``bvh_build_time``: both).

    ``prepared``: the render's :class:`~workbench.scene.prepared.PreparedScene` of ``scene``
    (its area lights, extent and object boxes); built here when not given."""
    import time
    prepared = prepared if prepared is not None else prepare(scene)
    b = _Builder(scene)
    owners = []  # first row of each top-level object and area light
    for i, o in enumerate(scene.objects):
        owners.append(len(b.rows))
        b.leaf(o, i, np.eye(4), top=True)
    for k, polygon, mat in prepared.area_lights:
        owners.append(len(b.rows))
        b.area_light(k, polygon, mat)
    rows = b.rows

    def col(key, dtype):
        return np.ascontiguousarray(np.array([r[key] for r in rows], dtype=dtype))

    tri_v, tri_n, tri_uv, tri_e, tri_p = _triangles(b.meshes)
    from .accel import build_accel
    from .bvh import empty_bvh4
    t0 = time.perf_counter()
    if len(tri_v):
        order, bvh = build_accel(tri_v, accel)
        tri_v, tri_n, tri_uv, tri_e, tri_p = (np.ascontiguousarray(a[order]) for a in
                                              (tri_v, tri_n, tri_uv, tri_e, tri_p))
        tri_src = np.ascontiguousarray(order, dtype=np.int64)
    else:
        bvh = empty_bvh4()
        tri_src = np.zeros(0, dtype=np.int64)
    finite = prepared.bounds if np.isfinite(prepared.bounds).all() else np.zeros((1, 3))
    scale = max(float(np.abs(finite).max()), prepared.extent, float(np.abs(scene.camera.position).max()))
    prims = _prim_tree(rows, owners, _owner_boxes(prepared), accel, scale)
    bvh_time = time.perf_counter() - t0
    mat_tab = np.stack([_material_row(mt, i in b.front_only, b.medium_of.get(i, -1))
                        for i, mt in enumerate(b.materials)])
    return SceneData(
        ptype=col("ptype", np.int64), top=col("top", np.bool_), obj=col("obj", np.int64),
        mat=col("mat", np.int64), xf=col("xf", np.float64).reshape(-1, 12),
        nm=col("nm", np.float64).reshape(-1, 9), par=col("par", np.float64).reshape(-1, NPAR),
        solid=col("solid", np.bool_), shadow=col("shadow", np.bool_),
        ident=np.ascontiguousarray([bool(np.array_equal(r["xf"], _IDENTITY_ROWS)) for r in rows], dtype=np.bool_),
        wfo=col("wfo", np.float64).reshape(-1, 4, 4), has_uv=col("has_uv", np.bool_),
        poly_v=np.ascontiguousarray(np.concatenate(b.poly_v) if b.poly_v else np.zeros((1, 3))),
        csg_prog=np.array(b.prog if b.prog else [0], dtype=np.int64),
        tri_v=tri_v, tri_n=tri_n, tri_uv=tri_uv, tri_e=tri_e, tri_prim=tri_p, tri_src=tri_src,
        bvh=bvh, prims=prims,
        materials=b.materials, mat_tab=np.ascontiguousarray(mat_tab),
        lights=np.ascontiguousarray(light_rows(scene.point_lights()).reshape(-1, LIGHT_COLS)),
        extent=prepared.extent, n_objects=len(scene.objects), bvh_build_time=bvh_time,
        aux=np.ascontiguousarray(np.concatenate(b.aux) if b.aux else np.zeros(1)))
