"""Tessellation of every object kind to triangles, for the raster methods (and pyrender, the UI,
radiosity if it wants meshes).

API
---
``tessellate_scene(scene, level) -> list[Part]`` and ``tessellate_object(obj, level, parent)
-> list[Part]``: the dispatch to each object kind's ``tessellate`` (:mod:`.kinds`).  A :class:`Part` is a triangle set with ONE material: every object gives one
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

Parts and their shared builders are in :mod:`.parts`.  Triangles are counter-clockwise seen
from the side their normal points to.  Shading normals
are never zero: a vertex normal that cancels (``< tol.normal_cancel``) is replaced by its
triangle's face normal.  ``face_normals`` and ``face_centroids`` are those of the source
polygon (the whole rectangle, box face or polygon), so that flat shading gives one colour per
polygon as the course draws it.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.errors import WorkbenchError
from . import model as m
from .kinds import kind_of
from .mesh_normals import mean_face_normals
from .parts import Part

DEFAULT_LEVEL = 6
MAX_LEVEL = 64
"""Largest tessellation level accepted (a sphere at 64 has 256 x 512 quads)."""


def _level(obj: m.SceneObject, level: int) -> int:
    if not 1 <= level <= MAX_LEVEL:
        raise WorkbenchError(f"tessellation level must be within 1..{MAX_LEVEL}, got {level}")
    return int(obj.tessellation or level)


def tessellate_object(obj: m.SceneObject, level: int = DEFAULT_LEVEL,
                      parent: np.ndarray | None = None) -> list[Part]:
    """Triangles of one object (see the module docstring for what ``level`` means).

    Parameters
    ----------
    obj : any scene object.
    level : tessellation level >= 1 (the object's own ``tessellation`` wins).
    parent : (4, 4) transform applied after the object's own (CSG children).
    """
    L = _level(obj, level)
    kind = kind_of(obj)
    if kind.COMPOSITE:
        return kind.tessellate(obj, L, np.eye(4) if parent is None else parent, kind_of)
    M = obj.world_from_object if parent is None else parent @ obj.world_from_object
    return kind.tessellate(obj, L, M)


def tessellate_scene(scene: m.Scene, level: int = DEFAULT_LEVEL,
                     empty: list[m.SceneObject] | None = None) -> list[Part]:
    """Parts of every object of the scene, in scene order, each with at least one triangle: an
    object with no surface (a blob whose threshold is above its field's maximum) gives none, as
    the ray methods find none; the object is appended to ``empty`` when given."""
    parts: list[Part] = []
    for obj in scene.objects:
        mine = [p for p in tessellate_object(obj, level) if len(p.faces) > 0]
        if not mine and empty is not None:
            empty.append(obj)
        parts.extend(mine)
    return parts


def area_light_parts(area_lights) -> list[tuple[Part, m.Material]]:
    """Area lights as emissive polygons of radiance ``color * intensity`` (what the raster
    methods draw of them), each with its own material; ``area_lights``: the prepared scene's
    ``(k, polygon, material)`` (:attr:`.prepared.PreparedScene.area_lights`)."""
    return [(part, mat) for _, polygon, mat in area_lights for part in tessellate_object(polygon, 1)]


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
