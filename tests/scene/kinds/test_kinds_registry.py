"""The object-kind registry (:mod:`workbench.scene.kinds`): every kind module provides the
interface its package docstring lists, the ray tracer's ptype table is one-to-one with the
registry, and an area light becomes a polygon in one place (``Scene.area_light_polygons``),
which every method's geometry then holds."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.scene import features, model as m
from workbench.scene.io import SceneError, scene_from_dict
from workbench.scene.kinds import KERNEL_FUNCTIONS, KERNEL_PTYPES_FROM, KINDS, crossings, kernel_module, kind_of

LEAF = ("parse", "bound_points", "tessellate", "patch_surfaces", "flatten", "inside", "povray", "mitsuba")
SOLID = ("solid_mesh", "analytic_normals")
COMPOSITE = ("parse", "children", "tessellate", "patch_surfaces", "flatten", "crossings",
             "containing", "world_bounds", "povray", "mitsuba")
CONSTANTS = ("TYPE", "MODEL", "FEATURE", "PTYPE", "SOLID", "CONVEX", "COMPOSITE", "CLOSED_TESSELLATION",
             "KERNELS", "KEYS", "REQUIRED")


@pytest.mark.parametrize("name", sorted(KINDS))
def test_every_kind_provides_the_interface(name):
    k = KINDS[name]
    missing = [c for c in CONSTANTS if not hasattr(k, c)]
    # a medium has an inside but no surface for the raster's CSG booleans (CSG refuses it)
    needed = COMPOSITE if k.COMPOSITE else LEAF + (SOLID if k.SOLID and not getattr(k, "MEDIUM", False) else ())
    missing += [f for f in needed if not callable(getattr(k, f, None))]
    assert not missing, f"kind {name} lacks {missing}"
    assert k.TYPE == name and k.MODEL.kind == name
    assert k.FEATURE in features.ALL
    assert not (k.KEYS & {"type", "material", "transform", "name", "tessellation"})
    assert k.REQUIRED <= k.KEYS


def test_ptypes_are_unique_and_match_the_kernels():
    from workbench.renderers.kernels import intersect, shapes
    ptypes = {k.PTYPE for k in KINDS.values()}
    assert len(ptypes) == len(KINDS)
    assert (shapes.SPHERE, shapes.RECT, shapes.BOX, shapes.POLYGON, shapes.QUADRIC,
            intersect.CSGNODE) == tuple(KINDS[n].PTYPE for n in ("sphere", "plane", "box", "polygon",
                                                                 "quadric", "csg"))


@pytest.mark.parametrize("name", sorted(KINDS))
def test_a_kind_has_a_kernel_module_exactly_when_the_kernels_do_not_know_it(name):
    k = KINDS[name]
    assert (k.KERNELS is not None) == (k.PTYPE >= KERNEL_PTYPES_FROM)
    module = kernel_module(k)
    if module is not None:
        assert all(callable(getattr(module, f, None)) for f in KERNEL_FUNCTIONS)


def _scene(objects):
    return scene_from_dict({
        "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0]},
        "materials": {"w": {}},
        "lights": [{"type": "area", "vertices": [[-1, 3, -1], [-1, 3, 1], [1, 3, 1], [1, 3, -1]],
                    "color": [1, 0.5, 0.25], "intensity": 2.0}],
        "objects": objects})


def test_an_unknown_type_is_one_line_naming_the_known_kinds():
    with pytest.raises(SceneError) as e:
        _scene([{"type": "torus", "material": "w"}])
    msg = str(e.value)
    assert "\n" not in msg and "[[objects]] #1.type" in msg
    assert all(repr(n) in msg for n in KINDS)


def test_a_sheet_in_a_csg_tree_is_refused_by_its_kind():
    with pytest.raises(SceneError, match=r"left\.type: CSG needs solids; a plane has no inside"):
        _scene([{"type": "csg", "material": "w", "op": "union",
                 "left": {"type": "plane", "normal": [0, 1, 0], "size": [1, 1]},
                 "right": {"type": "sphere", "radius": 1.0}}])


def test_area_light_is_one_polygon_in_every_method():
    from workbench.renderers.radiosity.patches import patches_from_scene
    from workbench.scene.tessellate import area_light_parts
    from workbench.renderers.kernels.columns import Mat
    from workbench.renderers.raytrace.flatten import flatten
    from workbench.renderers.raytrace.reference import Context
    from workbench.scene.prepared import prepare
    scene = _scene([{"type": "sphere", "material": "w", "radius": 0.5}])
    ((k, poly, mat),) = scene.area_light_polygons()
    assert k == 0 and np.array_equal(poly.vertices, scene.lights[0].vertices)
    assert mat.emission == (2.0, 1.0, 0.5) and mat.name not in scene.materials
    sd = flatten(scene)                                   # ray tracer: last row, front-only
    assert sd.obj[-1] == len(scene.objects) and not sd.shadow[-1]
    assert sd.materials[sd.mat[-1]] == mat and sd.mat_tab[sd.mat[-1], Mat.EMISSION + 1] == 1.0
    ctx = Context(scene)                                  # readable reference tracer
    assert np.array_equal(ctx.items[-1].obj.vertices, poly.vertices) and ctx.materials[mat.name] == mat
    ((part, pmat),) = area_light_parts(prepare(scene).area_lights)  # raster, zbuffer
    assert pmat == mat and np.allclose(np.sort(part.positions, 0)[[0, -1]],
                                       np.sort(poly.vertices, 0)[[0, -1]])
    patches, _ = patches_from_scene(scene, 10.0)          # radiosity
    light = patches.surface == patches.surface.max()
    assert np.array_equal(patches.corners[light][0], poly.vertices)
    assert np.array_equal(patches.emission[light][0], mat.emission)


def test_readable_crossings_of_a_csg_difference():
    """A unit box minus a sphere of radius 0.5 at its centre, along the x axis: in at -1, out
    at -0.5 (the sphere's surface, normal flipped), in at 0.5, out at 1."""
    scene = _scene([{"type": "csg", "material": "w", "op": "difference",
                     "left": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1]},
                     "right": {"type": "sphere", "radius": 0.5}}])
    obj = scene.objects[0]
    cs = crossings(obj, np.eye(4), np.array([-3.0, 0, 0]), np.array([1.0, 0, 0]), 1e-9)
    assert [c.t for c in cs] == pytest.approx([2.0, 2.5, 3.5, 4.0], abs=1e-12)
    assert [c.flip for c in cs] == [False, True, True, False]
    assert [kind_of(c.leaf[0]).TYPE for c in cs] == ["box", "sphere", "sphere", "box"]
    assert isinstance(obj, m.CSG)
