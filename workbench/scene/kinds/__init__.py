"""Object kinds as plugins (pbrt-v4's ``Shape::Create``, Mitsuba 3's plugins): one module per
kind of ``[[objects]]`` table, and :data:`KINDS`, the registry by scene-file ``type`` name.

A kind is two files and one registry line: its scene module (this page's contract below) and,
for a kind the kernels do not know, its kernel module (``KERNELS``: ``first``, ``events``,
``normal``), plus its entry in :data:`KINDS`, or :func:`register` for a kind defined outside
the package (a plugin; ``tests/scene/kinds/toy_disk.py`` is one).  Everything else reads the
registry: the scene reader, the needs manifest (``FEATURE``), the ray tracer's table
(``flatten``) and the kernels' dispatch (:mod:`workbench.renderers.kernels.specialise`, which
compiles a kind's kernels only for a scene that has it), the raster (``tessellate``,
``CLOSED_TESSELLATION``), radiosity (``patch_surfaces``, else the tessellation), the path
tracer's emitters and the exporters (``povray``, ``mitsuba``: a kind without them is left out
with the reason, never an error).  Renderers ask the registry (:func:`kind_of`) instead of
testing classes.  Kind modules are in the scene layer:
they import ``workbench.core``, the scene's :mod:`..model`, :mod:`..readers`, :mod:`..parts`,
other kind modules, numpy and numba, never ``workbench.renderers`` nor this registry (a
composite kind is handed the dispatch, see below).

What a kind module provides
---------------------------
Constants

``TYPE``        the scene file's ``type = "..."`` name (the registry key; ``obj.kind`` of its objects).
``MODEL``       its dataclass (kept in :mod:`workbench.scene.model`, beside :class:`Scene`).
``FEATURE``     its entry of the needs manifest (a name in :data:`workbench.scene.features.ALL`).
``PTYPE``       its ``ptype`` in the ray tracer's primitive table (a unique int; the kernels
                dispatch on it).
``SOLID``       True when it has an inside: a CSG leaf, a medium for refraction; False for a
                thin sheet (transmission goes straight through).  A kind whose objects differ (a
                lathe: solid when its profile is closed) also has ``solid(obj) -> bool``
                (:func:`.csg.is_solid` asks it).
``CONVEX``      True when it cannot shadow itself (one such object alone needs no shadow rays).
``CLOSED_TESSELLATION``  True when its triangles (``tessellate``) are a closed, outward-wound
                surface (the raster then culls back faces of its blended objects seen from
                outside).
``KERNELS``     kinds the kernels do not know (``PTYPE >= KERNEL_PTYPES_FROM``): the dotted
                name of its kernel module, which defines the numba functions ``first``,
                ``events``, ``normal`` (and ``inside``) with the signatures of
                :mod:`.crossing_events`.
``COMPOSITE``   True only for kinds made of other objects (CSG), see below.
``KEYS``, ``REQUIRED``  the keys of its table beside the common ones (``type``, ``material``,
                ``transform``, ``name``, ``tessellation``), and which of them are required.

Functions (``W`` and ``M`` are (4, 4) ``world_from_object`` including any CSG parents)

``parse(ctx, t, w, common) -> MODEL``  validate table ``t`` (named ``w`` in messages) with the
    readers of :mod:`..readers`; ``common`` holds the common fields already read.  Bad input:
    ``ctx.fail(where, what)``, one line naming the key and what was expected.
``bound_points(obj) -> (n, 3)``  object-space points whose hull holds the object (the
    prepared scene's bounds, extent and clip planes, :mod:`workbench.scene.prepared`).
``tessellate(obj, level, M) -> list[Part]``  triangles for the raster methods (:mod:`..parts`).
``solid_mesh(obj, level) -> (P (V, 3), F (F, 3))``  SOLID kinds: a closed, welded object-space
    mesh for the raster's CSG booleans.
``analytic_normals(obj, P (3T, 3)) -> (normals (3T, 3), cap (3T,) bool) | None``  SOLID kinds:
    object-space shading normals at points of its CSG triangles (None: flat triangles).
``patch_surfaces(obj, W, h) -> list | None``  radiosity: ``("polygon", (k, 3) world convex
    polygon)`` and ``("mesh", (P (V, 3), F (F, 3)))`` surfaces; None for a curved kind, which
    the patch builder cuts from its tessellation at triangles about ``h`` long.
``flatten(b, obj, index, W, top) -> row``  its rows of the kernels' primitive table, through
    the ray tracer's builder ``b``: ``b.add(PTYPE, index, obj, W, par, top=, solid=,
    shadow=)`` (``par``: a row of the kind's ``Par``, a :class:`workbench.core.columns.Columns`
    of at most ``NPAR`` columns that its kernels read by name, written with
    :func:`~workbench.core.columns.pack`), and for kinds with variable-length data the builder's
    arrays (``b.poly_v``, ``b.meshes``, ``b.add_aux``).
``Par``  the columns of its ``par`` (every kind but the mesh, which has none); a kind with
    ``params`` starts it with ``OFFSET = AUX_OFFSET`` (:mod:`.aux_rows`).
``params(obj, aux_offset) -> (head, aux)``  kinds with variable-length data (blob, isosurface,
    lathe, prism): the parameter row's head and the numbers that go to the ``aux`` array
    (:func:`.aux_rows.flatten_aux`); the ray tracer's memory estimate counts ``aux``
    (:func:`workbench.renderers.raytrace.flatten.flatten_bytes`).
``hits(obj, O, D, solid) -> [(t, face), ...]``  readable intersection of the object-space line
    ``O + t D`` (every crossing, sorted; a SOLID kind's alternate entering / leaving; ``solid``
    is True for a CSG leaf).  ``face`` (int) picks the normal.  Meshes have none (the
    reference tracer intersects their world triangles).
``normal(obj, face, P) -> (3,)``  outward object-space normal (not normalised) at point ``P``.
``inside(obj, q) -> bool``  strict inside test of object-space point ``q`` (False for sheets).

``povray(obj, w, in_csg) -> str | None``  the object's POV-Ray 3.7 SDL (shape in object
    space, texture, ``matrix``) through the exporter's writer ``w``
    (:class:`workbench.renderers.povray_sdl.Writer`): ``w.vec(a)``, ``w.num(x)`` (10
    significant digits), ``w.matrix(W)``, ``w.texture(material)`` (pigment, finish, interior),
    ``w.leave(feature, reason)`` and, for CSG operands, ``w.shape(child, True)``;
    ``in_csg``: it is a CSG operand (a cut quadric becomes a capped solid, an isosurface
    keeps all its crossings).  None: POV-Ray cannot express it (the writer notes it).
``mitsuba(obj, x) -> list[dict] | None``  its Mitsuba 3 shapes, added through the exporter's
    shape writer ``x`` (:class:`workbench.renderers.mitsuba_export.ShapeWriter`):
    ``x.tessellated(obj, level, flat=, open_surface=)`` (its raster tessellation as PLY
    meshes), ``x.analytic(shape_dict, material, lo, hi)`` (a Mitsuba primitive of its own),
    ``x.similarity_scale(W)``, ``x.leave(feature, reason, approximated=False)`` (in
    ``left_out``), ``x.level`` (the export's tessellation level) and, for a participating
    medium, ``x.write_volume(grid, lo, hi)`` (a Mitsuba ``.vol`` file, its path),
    ``x.medium(shape_dict, medium_dict, lo, hi, around_camera)`` (a boundary with a ``null``
    BSDF and the medium inside; the export then uses ``volpath``) and ``x.volume_grid`` (the
    export's grid resolution).  Returns the shape dicts added; None: not exported (noted).
``mitsuba_bytes(obj, volume_grid) -> int``  optional: bytes its Mitsuba export adds beyond
    its triangles (a medium's grids), for the ``mitsuba`` method's memory estimate.

The numba functions (intersection and normal by ``par`` row) live in
:mod:`workbench.renderers.kernels.shapes`, which imports the ``PTYPE`` constants from here.

Composite kinds (``COMPOSITE = True``: CSG) take the dispatch as an argument instead of
importing it: ``parse(ctx, t, w, common, child, kind_of)``, ``children(obj)``,
``tessellate(obj, level, parent, kind_of)``, ``crossings(obj, W, O, D, eps, crossings_of)``,
``containing(obj, W, p, containing_of)``, ``world_bounds(obj, W, bounds_of)``; their
``flatten`` calls ``b.leaf(child, index, W, top=False)`` for operands and their ``povray``
the writer's ``w.shape`` (the exporters' dispatch, handed over in ``w``).
"""
from __future__ import annotations

import importlib
from types import MappingProxyType, ModuleType

import numpy as np

from ...core.errors import WorkbenchError
from .. import model as m
from . import blob, box, csg, fur, hypertexture, isosurface, lathe, mesh, plane, polygon, prism, quadric, sphere

_REGISTRY = {k.TYPE: k for k in (sphere, plane, box, quadric, polygon, mesh, csg, blob, isosurface, lathe, prism, hypertexture, fur)}
KINDS = MappingProxyType(_REGISTRY)
"""The registry: scene-file ``type`` name -> kind module (the package's, then those added by
:func:`register`)."""
PACKAGE_KINDS = frozenset(_REGISTRY)
"""The package's own kinds (the others are plugins)."""
KERNEL_PTYPES_FROM = 7
"""``ptype`` of the first kind with a kernel module of its own (``KERNELS``); the kinds below it
(sphere, rectangle, box, polygon, quadric, CSG, mesh) are intersected by
:mod:`workbench.renderers.kernels.shapes` itself."""
CONTRACT = ("TYPE", "MODEL", "FEATURE", "PTYPE", "SOLID", "CONVEX", "COMPOSITE", "CLOSED_TESSELLATION",
            "KEYS", "REQUIRED", "KERNELS", "parse", "bound_points", "tessellate", "flatten", "hits",
            "normal", "inside")
"""What a plugin kind's scene module defines (the module docstring says what each is)."""
KERNEL_FUNCTIONS = ("first", "events", "normal")
"""What its kernel module defines (numba functions, signatures of :mod:`.crossing_events`)."""


def register(kind: ModuleType) -> ModuleType:
    """Add a kind defined outside the package (a plugin) to :data:`KINDS`; returns it.

    Raises WorkbenchError naming what is wrong: a name of :data:`CONTRACT` missing, a ``TYPE``,
    ``FEATURE`` or ``PTYPE`` already taken, a ``PTYPE`` below :data:`KERNEL_PTYPES_FROM`, a
    composite kind, or a kernel module that cannot be imported or lacks a name of
    :data:`KERNEL_FUNCTIONS`.  Registering the same module again does nothing."""
    where = f"kind module {getattr(kind, '__name__', kind)!r}"
    missing = [n for n in CONTRACT if not hasattr(kind, n)]
    if missing:
        raise WorkbenchError(f"{where}: missing {', '.join(missing)} (see workbench.scene.kinds)")
    if _REGISTRY.get(kind.TYPE) is kind:
        return kind
    if not isinstance(kind.PTYPE, int) or not KERNEL_PTYPES_FROM <= kind.PTYPE < 2 ** 31:
        raise WorkbenchError(f"{where}: PTYPE must be an int >= {KERNEL_PTYPES_FROM}, got {kind.PTYPE!r}")
    for other in _REGISTRY.values():
        for attr in ("TYPE", "FEATURE", "PTYPE"):
            if getattr(other, attr) == getattr(kind, attr):
                raise WorkbenchError(f"{where}: {attr} {getattr(kind, attr)!r} is taken by kind {other.TYPE!r}")
    if getattr(kind.MODEL, "kind", None) != kind.TYPE:
        raise WorkbenchError(f"{where}: its MODEL's kind is {getattr(kind.MODEL, 'kind', None)!r}, not its TYPE {kind.TYPE!r}")
    if kind.COMPOSITE:
        raise WorkbenchError(f"{where}: composite kinds (made of other objects) cannot be plugins")
    if not isinstance(kind.KERNELS, str):
        raise WorkbenchError(f"{where}: KERNELS must be the dotted name of its kernel module, got {kind.KERNELS!r}")
    module = kernel_module(kind)
    lacking = [n for n in KERNEL_FUNCTIONS if not callable(getattr(module, n, None))]
    if lacking:
        raise WorkbenchError(f"{where}: its kernel module {kind.KERNELS!r} lacks {', '.join(lacking)}")
    _REGISTRY[kind.TYPE] = kind
    return kind


def kernel_module(kind: ModuleType) -> ModuleType | None:
    """The kernel module of a kind with one (``KERNELS``), None for the kinds the kernels know.
    Raises WorkbenchError when it cannot be imported."""
    name = getattr(kind, "KERNELS", None)
    if name is None:
        return None
    try:
        return importlib.import_module(name)
    except ImportError as e:
        raise WorkbenchError(f"kind {kind.TYPE!r}: cannot import its kernel module {name!r} ({e})") from None


def kernel_kinds() -> tuple[ModuleType, ...]:
    """The registered kinds with kernel modules of their own, in registry order."""
    return tuple(k for k in _REGISTRY.values() if getattr(k, "KERNELS", None) is not None)

SPHERE, RECT, BOX, POLYGON = sphere.PTYPE, plane.PTYPE, box.PTYPE, polygon.PTYPE
QUADRIC, CSGNODE, MESH = quadric.PTYPE, csg.PTYPE, mesh.PTYPE


def kind_of(obj: m.SceneObject) -> ModuleType:
    """The kind module of a scene object (by its ``kind``)."""
    try:
        return KINDS[obj.kind]
    except KeyError:
        raise WorkbenchError(f"unknown object kind {obj.kind!r} (known: {', '.join(KINDS)})") from None


def is_solid(obj: m.SceneObject) -> bool:
    """Has an inside (:func:`.csg.is_solid`): a CSG operand, a medium for refraction."""
    return csg.is_solid(obj, kind_of)


def crossings(obj: m.SceneObject, W: np.ndarray, O, D, eps: float, solid: bool = False) -> list[csg.Crossing]:
    """Readable intersection: crossings of the world line ``O + t D`` with ``obj`` whose parent
    transform is ``W``, sorted by ``t``; a primitive is intersected in its object space (the
    course's "objet transformé: appliquer la transformation au rayon"), a CSG node combines
    its operands' interval lists.  ``solid``: ``obj`` is a CSG operand."""
    Wl = W @ np.asarray(obj.world_from_object)
    kind = kind_of(obj)
    if kind.COMPOSITE:
        return kind.crossings(obj, Wl, O, D, eps, crossings)
    inv = np.linalg.inv(Wl)
    o, d = inv[:3, :3] @ O + inv[:3, 3], inv[:3, :3] @ D
    return [csg.Crossing(t, (obj, Wl), f) for t, f in kind.hits(obj, o, d, solid)]


def containing(obj: m.SceneObject, W: np.ndarray, p) -> str | None:
    """The material of the leaf of ``obj`` (parent transform ``W``) whose inside holds world
    point ``p`` and is part of the solid, None if ``p`` is not inside (on a surface is outside)."""
    Wl = W @ np.asarray(obj.world_from_object)
    kind = kind_of(obj)
    if kind.COMPOSITE:
        return kind.containing(obj, Wl, p, containing)
    inv = np.linalg.inv(Wl)
    return obj.material if kind.inside(obj, inv[:3, :3] @ p + inv[:3, 3]) else None


def world_bounds(obj: m.SceneObject, W: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned world box ``(lo (3,), hi (3,))`` of ``obj`` (parent transform ``W``): its
    object-space bounding box's corners moved to world space."""
    Wl = W @ np.asarray(obj.world_from_object)
    kind = kind_of(obj)
    if kind.COMPOSITE:
        return kind.world_bounds(obj, Wl, world_bounds)
    pts = np.asarray(kind.bound_points(obj), dtype=np.float64)
    lo, hi = pts.min(0), pts.max(0)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    w = corners @ Wl[:3, :3].T + Wl[:3, 3]
    return w.min(0), w.max(0)


def leaves(obj: m.SceneObject) -> list[m.SceneObject]:
    """``obj`` and every object inside it (CSG operands, depth first)."""
    kind = kind_of(obj)
    out = [obj]
    if kind.COMPOSITE:
        for child in kind.children(obj):
            out.extend(leaves(child))
    return out
