"""The scene as the path tracer traces it: flat opaque polygons and rectangles become
triangle meshes, so that they are intersected through the ray tracer's 4-wide BVH
(:func:`..kernels.walks.bvh_hit`, watertight triangle tests four at a time) instead of one
by one in :func:`..kernels.intersect.closest`'s linear loop over analytic primitives: the
Cornell box's 15 quadrilaterals cost a BVH descent instead of 15 polygon tests per ray.

Only what a triangle mesh describes identically is converted: convex polygons and rectangles
(fan triangles in vertex order: the same front face) whose material has no texture, bump or
opacity map (those read the polygon's own object-space mapping) and no transmission (a mesh is
a solid, a polygon a thin sheet).  Convex area lights become triangle meshes too, of the black
emissive material the ray tracer gives them (named ``__area_light_<k>_tris``, after
``flatten``'s ``__area_light_<k>``), whose emission the path tracer keeps to the front face
(:data:`FRONT_ONLY` names them for the session, which sets the ``front_only_emitter`` column): a
scene of polygons is then all triangles, and every ray a BVH traversal alone.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...scene import model as m
from .emitters import fan_triangles


def _as_mesh(o, vertices):
    tris = fan_triangles(np.asarray(vertices, dtype=np.float64))
    if tris is None:
        return o
    V = tris.reshape(-1, 3)
    F = np.arange(len(V), dtype=np.int64).reshape(-1, 3)
    return m.Mesh(o.material, world_from_object=o.world_from_object, name=o.name,
                  tessellation=o.tessellation, vertices=V, faces=F, source=f"pathtrace: {o.kind} as triangles")


FRONT_ONLY = "__area_light_"
"""Name prefix of the area lights' materials (``raytrace.flatten``): they emit from the front only."""


def triangulated(scene: m.Scene) -> m.Scene:
    """``scene`` with its plain opaque convex polygons and rectangles, and its convex area
    lights, as triangle meshes."""
    out = []
    for o in scene.objects:
        mat = scene.materials.get(o.material) if not isinstance(o, m.CSG) else None
        plain = (mat is not None and mat.kt <= 0.0 and mat.texture is None and mat.bump is None
                 and mat.opacity is None)
        if plain and isinstance(o, m.Polygon):
            o = _as_mesh(o, o.vertices)
        elif plain and isinstance(o, m.Plane):
            o = _as_mesh(o, o.corners())
        out.append(o)
    materials, lights = dict(scene.materials), []
    for k, lt in enumerate(scene.lights):
        if isinstance(lt, m.AreaLight):
            name = f"{FRONT_ONLY}{k}_tris"
            mesh = _as_mesh(m.Polygon(name, vertices=np.asarray(lt.vertices, dtype=np.float64), name=name),
                            lt.vertices)
            if isinstance(mesh, m.Mesh) and name not in materials:
                materials[name] = m.Material(name, color=(0.0, 0.0, 0.0), ka=0.0, kd=0.0, ks=0.0,
                                             emission=tuple(float(x) for x in lt.radiance))
                out.append(mesh)
                continue
        lights.append(lt)
    return replace(scene, objects=tuple(out), materials=materials, lights=tuple(lights))
