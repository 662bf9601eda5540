"""Memory estimates shared by the raster-style methods (GLSL raster, pyrender): triangle
counts from a level-1 tessellation and the bytes of triangles and pixels.  Each renderer's
``estimate_bytes`` (see :mod:`workbench.renderers.base`) builds on these."""
from __future__ import annotations

from ..scene import model as m
from ..scene.model import Scene
from ..scene.tessellate import tessellate_scene

CURVED_GROWTH = 2.0
"""Triangles of a tessellated (non-mesh) object at level L over L^2 times its level-1 count:
4/3 for spheres, 1 for quadrics and polygons, below 1 for CSG (measured on every bundled
scene for L = 1..32); 2 for margin."""


def triangle_bound(scene: Scene, level: int) -> int:
    """Upper bound of the triangles of ``tessellate_scene(scene, level)``: meshes keep theirs,
    every other object grows as ``level^2`` from its level-1 tessellation (cheap: tens of
    triangles per object)."""
    mesh = sum(len(o.faces) for o in scene.objects if isinstance(o, m.Mesh))
    curved = sum(len(p.faces) for p in tessellate_scene(scene, 1)) - mesh
    return int(mesh + CURVED_GROWTH * max(curved, 0) * level * level)


def raster_bytes(scene: Scene, width: int, height: int, level: int, per_triangle: int,
                 per_pixel: int, fixed: int) -> int:
    """``fixed + per_triangle x triangle_bound + per_pixel x width x height``."""
    return int(fixed + per_triangle * triangle_bound(scene, level) + per_pixel * width * height)
