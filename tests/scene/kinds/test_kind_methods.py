"""The new kinds (blob, isosurface, lathe polyline and bezier, prism) in the methods that take them from their
tessellation: radiosity cuts them into patches (one per triangle) and lights them; the raster
and the ray caster see the same pixels."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from seen_pixels import coverage, iou, scene_dict
from workbench.scene.io import scene_from_dict

NEW = [{"type": "blob", "threshold": 0.3, "material": "m",
        "components": [{"center": [-1.5, 0, 0], "radius": 1.0}, {"center": [-0.8, 0.3, 0], "radius": 0.8}]},
       {"type": "lathe", "material": "m", "points": [[0, -1], [0.5, -1], [0.3, 0], [0.5, 0.6], [0, 0.6]]},
       {"type": "prism", "material": "m", "polygon": [[1, -0.5], [2, -0.5], [2, 0.5], [1.5, 0], [1, 0.5]],
        "heights": [-1, 0]},
       {"type": "isosurface", "material": "m", "function": "x^2 + y^2 + z^2", "threshold": 0.25, "max_gradient": 3.5,
        "bounds": {"min": [-0.8, -0.8, -0.8], "max": [0.8, 0.8, 0.8]}, "transform": {"translate": [0, 0.5, 1.5]}},
       {"type": "lathe", "spline": "bezier", "material": "m", "transform": {"translate": [0.5, -1.0, -1.6]},
        "points": [[0, 0], [0.4, 0], [0.5, 0.4], [0.4, 0.7], [0.4, 0.7], [0.3, 1.0], [0.2, 1.2], [0, 1.2]]}]
FLOOR = {"type": "plane", "point": [0, -1, 0], "normal": [0, 1, 0], "size": [8, 8], "material": "m"}
LIGHT = [{"type": "area", "vertices": [[-1, 3, -1], [1, 3, -1], [1, 3, 1], [-1, 3, 1]], "color": [1, 1, 1],
          "intensity": 5.0}]


def _scene(objects):
    return scene_from_dict(scene_dict(objects, lights=LIGHT))


@pytest.mark.gl
def test_radiosity_patches_and_lights_the_new_kinds(gl_ctx):
    alone = workbench.render(_scene([FLOOR]), "radiosity", width=64, height=48)
    r = workbench.render(_scene([FLOOR, *NEW]), "radiosity", width=64, height=48)
    assert np.isfinite(r.image).all()
    assert not [x for x in r.left_out if x.feature in ("blobs", "isosurfaces", "lathes", "prisms")]
    assert r.stats["patches"] > alone.stats["patches"] + 4 * 50
    seen = coverage(_scene([FLOOR, *NEW]), "raycast", 64, 48)
    lit = r.image.max(-1) > 0.0
    # the objects (pixels the floor alone does not explain) receive light
    floor_only = coverage(_scene([FLOOR]), "raycast", 64, 48)
    assert (lit & seen & ~floor_only).sum() > 0.5 * (seen & ~floor_only).sum()


@pytest.mark.gl
def test_raster_and_ray_caster_see_the_same_new_objects(gl_ctx):
    sc = _scene([FLOOR, *NEW])
    assert iou(coverage(sc, "raycast", 64, 48), coverage(sc, "phong", 64, 48)) >= 0.97
