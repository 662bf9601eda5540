"""The needs manifest: which features a scene uses, so renderers build only those.

Feature names are plain strings (stable, printed by ``workbench scenes`` and listed in every
``RenderResult.left_out``).
"""
from __future__ import annotations

from . import model as m
from .kinds import kind_of, leaves

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
BLOBS = "blobs"
ISOSURFACES = "isosurfaces"
LATHES = "lathes"
PRISMS = "prisms"
HYPERTEXTURES = "hypertextures"
TEXELS = "texels"

ALL = (TEXTURES, SOLID_TEXTURES, IMAGE_TEXTURES, BUMP, ENVIRONMENT, OPACITY, SHADOWS, SPECULAR,
       REFLECTION, REFRACTION, ABSORPTION, CSG, QUADRICS, SPHERES, PLANES, BOXES, POLYGONS, MESHES,
       TRANSFORMS, EMITTERS, POINT_LIGHTS, DIRECTIONAL_LIGHTS, AREA_LIGHTS, BLOBS, ISOSURFACES, LATHES,
       PRISMS, HYPERTEXTURES, TEXELS)

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
    """Its kind's feature (and its operands'), transforms, its materials' features."""
    import numpy as np
    for o in leaves(obj):
        f.add(kind_of(o).FEATURE)
        if not np.allclose(o.world_from_object, np.eye(4)):
            f.add(TRANSFORMS)
        f |= material_needs(scene.materials[o.material])


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
    if scene.lights and (len(scene.objects) > 1 or not kind_of(scene.objects[0]).CONVEX):
        f.add(SHADOWS)
    if scene.environment is not None:
        f.add(ENVIRONMENT)
    return frozenset(f)
