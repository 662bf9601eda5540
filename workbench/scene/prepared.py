"""The prepared scene: what several renderers derive from a :class:`~.model.Scene`, computed
once per render (issue 14; pbrt-v4's split of the scene description from what the renderer
builds from it).

Every method's ``render`` (and each long-lived session) calls :func:`prepare`, which builds
the prepared scene once per scene object and keeps it there, so that a render's estimate, its
renderer and what it calls read one object: the world bounds of every object and of the whole scene, its extent (the scale of
every relative tolerance in :mod:`workbench.core.tol`), the area lights as emissive polygons,
the camera's automatic near and far planes (:mod:`.clip_planes`) and the media holding the
camera (:mod:`.media`).  Before this step the ray tracer took the extent from its primitive
table, radiosity from a coarse tessellation of its surfaces, the raster methods and pyrender
their clip planes from the boxes of their own triangles (pyrender without the area lights),
and each tracer asked for the camera's media and the area-light polygons itself.

Bounds are robust by construction: a box holds the object's kind's ``bound_points`` (every
leaf of a CSG tree, under its composed ``world_from_object``) moved to world space, the hull
of points that hold the object, so no hit, vertex or patch lies outside it by more than the
rounding of its own transform; points with a non-finite coordinate are left out (an object
with none has the empty box ``lo = +inf, hi = -inf`` and takes no part in the extent or the
clip planes).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.tol import tol
from . import model as m
from .clip_planes import auto_near_far
from .kinds import kind_of
from .media import enclosing_media


@dataclass(frozen=True, eq=False)
class PreparedScene:
    """What every renderer reads of a scene, built by :func:`prepare`.

    Attributes
    ----------
    scene : Scene
        The scene it was built from (its camera gives :attr:`near`, :attr:`far` and
        :attr:`camera_media`).
    object_bounds : (N, 2, 3) float64
        World box ``(lo, hi)`` of each of ``scene.objects``, in scene order (of its finite
        bound points).
    unbounded : (N,) bool
        The objects with a bound point at infinity (an unbounded quadric from the API): no
        finite box holds them, so acceleration structures test them on every ray.
    area_lights : tuple of (k, Polygon, Material)
        Every area light as the emissive polygon the methods see
        (:meth:`.model.Scene.area_light_polygons`: light index, polygon, its material).
    light_bounds : (K, 2, 3) float64
        World box of each area light's polygon, in :attr:`area_lights` order.
    bounds : (2, 3) float64
        World box of everything: objects and area lights (finite points only).
    extent : float
        Diagonal of :attr:`bounds` (at least ``tol.zero``; 1 for a scene with no finite
        point): the scale of relative offsets (:func:`workbench.core.tol.offset_scale`) and of
        radiosity patch sizes.
    near, far : float
        The camera's clip planes (its own where given, else :func:`.clip_planes.auto_near_far`
        over :attr:`boxes`).
    camera_media : tuple of Material
        The transmissive solids holding the camera, outermost first
        (:func:`.media.enclosing_media`): the media stack of the primary rays.
    """

    scene: m.Scene
    object_bounds: np.ndarray
    unbounded: np.ndarray
    area_lights: tuple
    light_bounds: np.ndarray
    bounds: np.ndarray
    extent: float
    near: float
    far: float
    camera_media: tuple

    @property
    def boxes(self) -> np.ndarray:
        """(B, 2, 3) the non-empty boxes of :attr:`object_bounds` and :attr:`light_bounds`
        (objects first): what the clip planes are fitted to."""
        return _finite_boxes(self.object_bounds, self.light_bounds)

    def clip_planes(self, camera: m.Camera) -> tuple[float, float]:
        """``(near, far)`` for another view of the same scene (a session whose camera moves)."""
        return auto_near_far(camera, self.boxes)


def _finite_boxes(*boxes: np.ndarray) -> np.ndarray:
    """(B, 2, 3) the boxes of the (K_i, 2, 3) arrays that are not empty, in order."""
    allb = np.concatenate(boxes).reshape(-1, 2, 3)
    return allb[np.isfinite(allb).all(axis=(1, 2))]


def _box(points: list[np.ndarray]) -> np.ndarray:
    """(2, 3) box of the finite rows of the (n_i, 3) point arrays; empty: ``+inf, -inf``."""
    p = np.concatenate(points).reshape(-1, 3) if points else np.zeros((0, 3))
    p = p[np.isfinite(p).all(1)]
    if not len(p):
        return np.array([np.full(3, np.inf), np.full(3, -np.inf)])
    return np.array([p.min(0), p.max(0)])


def world_points(obj: m.SceneObject, parent: np.ndarray) -> list[np.ndarray]:
    """World-space bound points, one (n, 3) array per leaf of ``obj`` (parent transform
    ``parent`` (4, 4)): each leaf kind's ``bound_points`` under its composed transform."""
    W = parent @ np.asarray(obj.world_from_object)
    kind = kind_of(obj)
    if kind.COMPOSITE:
        return [p for child in kind.children(obj) for p in world_points(child, W)]
    pts = np.asarray(kind.bound_points(obj), dtype=np.float64).reshape(-1, 3)
    return [pts @ W[:3, :3].T + W[:3, 3]]


def prepare(scene: m.Scene) -> PreparedScene:
    """The :class:`PreparedScene` of ``scene`` (for its camera), built once per scene object and
    kept on it: a scene is immutable (an edit, a camera or a resolution makes a new one), so a
    render's memory estimate, its renderer and the renderers it calls in turn (the hybrid's ray
    tracer on its own derived scene excepted) all read the one built for it."""
    kept = scene.__dict__.get(_KEPT)
    if kept is None:
        kept = build(scene)
        scene.__dict__[_KEPT] = kept  # a frozen dataclass's __dict__: no field, no __setattr__
    return kept


_KEPT = "_prepared"
"""The attribute of a :class:`~.model.Scene` that keeps its prepared scene."""


def build(scene: m.Scene) -> PreparedScene:
    """Build the :class:`PreparedScene` of ``scene`` (:func:`prepare` keeps it)."""
    objects = [world_points(o, np.eye(4)) for o in scene.objects]
    area_lights = tuple(scene.area_light_polygons())
    lights = [world_points(polygon, np.eye(4)) for _, polygon, _ in area_lights]
    object_bounds = np.array([_box(p) for p in objects]).reshape(-1, 2, 3)
    unbounded = np.array([not all(np.isfinite(q).all() for q in p) for p in objects], dtype=bool)
    light_bounds = np.array([_box(p) for p in lights]).reshape(-1, 2, 3)
    bounds = _box([p for pts in objects + lights for p in pts])
    extent = float(np.linalg.norm(bounds[1] - bounds[0])) if np.isfinite(bounds).all() else 1.0
    near, far = auto_near_far(scene.camera, _finite_boxes(object_bounds, light_bounds))
    return PreparedScene(scene, object_bounds, unbounded, area_lights, light_bounds, bounds, max(extent, tol.zero),
                         near, far, tuple(enclosing_media(scene, scene.camera.position)))
