"""The needs manifest: which features a scene uses, so renderers build only those.

Feature names are plain strings (stable, printed by ``workbench scenes`` and listed in every
``RenderResult.left_out``).
"""
from __future__ import annotations

from . import model as m

TEXTURES = "textures"
SOLID_TEXTURES = "solid_textures"
IMAGE_TEXTURES = "image_textures"
BUMP = "bump"
ENVIRONMENT = "environment"
OPACITY = "opacity"
SHADOWS = "shadows"
SPECULAR = "specular"
REFLECTION = "reflection"
REFRACTION = "refraction"
ABSORPTION = "absorption"
CSG = "csg"
QUADRICS = "quadrics"
SPHERES = "spheres"
PLANES = "planes"
BOXES = "boxes"
POLYGONS = "polygons"
MESHES = "meshes"
TRANSFORMS = "transforms"
EMITTERS = "emitters"
POINT_LIGHTS = "point_lights"
DIRECTIONAL_LIGHTS = "directional_lights"
AREA_LIGHTS = "area_lights"

ALL = (TEXTURES, SOLID_TEXTURES, IMAGE_TEXTURES, BUMP, ENVIRONMENT, OPACITY, SHADOWS, SPECULAR,
       REFLECTION, REFRACTION, ABSORPTION, CSG, QUADRICS, SPHERES, PLANES, BOXES, POLYGONS, MESHES,
       TRANSFORMS, EMITTERS, POINT_LIGHTS, DIRECTIONAL_LIGHTS, AREA_LIGHTS)

_KIND = {"sphere": SPHERES, "plane": PLANES, "box": BOXES, "quadric": QUADRICS,
         "polygon": POLYGONS, "mesh": MESHES, "csg": CSG}


def material_needs(mat: m.Material) -> set[str]:
    """Features one material uses."""
    f = set()
    if mat.texture is not None:
        f.add(TEXTURES)
        if mat.texture.projection == "solid":
            f.add(SOLID_TEXTURES)
        if mat.texture.kind == "image":
            f.add(IMAGE_TEXTURES)
    if mat.bump is not None:
        f.add(BUMP)
    if mat.opacity is not None:
        f.add(OPACITY)
    if mat.environment:
        f.add(ENVIRONMENT)
    if mat.ks > 0:
        f.add(SPECULAR)
    if mat.kr > 0:
        f.add(REFLECTION)
    if mat.kt > 0:
        f.add(REFRACTION)
        if max(mat.absorption) > 0:
            f.add(ABSORPTION)
    if mat.is_emitter:
        f.add(EMITTERS)
    return f


def _object_needs(obj: m.SceneObject, scene: m.Scene, f: set[str]):
    import numpy as np
    f.add(_KIND[obj.kind])
    if not np.allclose(obj.world_from_object, np.eye(4)):
        f.add(TRANSFORMS)
    f |= material_needs(scene.materials[obj.material])
    if isinstance(obj, m.CSG):
        for child in (obj.left, obj.right):
            _object_needs(child, scene, f)


def scene_needs(scene: m.Scene) -> frozenset[str]:
    """Every feature the scene uses: geometry kinds, material effects, light kinds, shadows
    (any light and at least two objects, or a non-convex one), environment."""
    f: set[str] = set()
    for obj in scene.objects:
        _object_needs(obj, scene, f)
    for light in scene.lights:
        f.add({m.PointLight: POINT_LIGHTS, m.DirectionalLight: DIRECTIONAL_LIGHTS,
               m.AreaLight: AREA_LIGHTS}[type(light)])
        if isinstance(light, m.AreaLight):
            f.add(EMITTERS)
    if scene.lights and (len(scene.objects) > 1 or scene.objects[0].kind in ("mesh", "csg", "quadric")):
        f.add(SHADOWS)
    if scene.environment is not None:
        f.add(ENVIRONMENT)
    return frozenset(f)
