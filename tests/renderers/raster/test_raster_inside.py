"""A camera inside a closed transparent object (issue 26, item 4): the raster draws the
object's inner surface (its stand-in: blended tint, or refraction out through its environment
map) and the scene beyond it the right way up, for every closed kind.

The scene: a glass object of about radius 2 around the camera (at the origin, looking along
-z), kt C = 0.5 with no local light on it (ka = kd = ks = kr = 0), a green floor at y = -5
under a blue sky.  Seen through the inner surface, every pixel is the scene beyond it times
kt C: the image's mean is half the mean without the object (bounds 0.35 .. 0.7 allow the
environment map's parallax and a refracted, not straight, view through the non-spherical
kinds); the bottom rows show the floor (green above blue) and the top rows the sky.  Before
the fix the blended kinds' inner faces were culled (ratio 1) and the environment-mapped ones
refracted as if entering, which showed the floor upside down.
"""
from __future__ import annotations

import numpy as np
import pytest

from workbench.renderers.base import render
from workbench.scene.io import scene_from_dict

from closed_objects import CLOSED

W, H = 32, 24
SKY, FLOOR = [0.1, 0.1, 0.8], [0.1, 0.8, 0.1]


def _scene(obj: dict | None):
    objects = [{"type": "plane", "material": "floor", "point": [0, -5, 0], "normal": [0, 1, 0], "size": [400.0, 400.0]}]
    if obj is not None:
        o = {**obj, "material": "glass"}
        if o["type"] == "csg":
            o["left"], o["right"] = {**o["left"], "material": "glass"}, {**o["right"], "material": "glass"}
        objects.append(o)
    return scene_from_dict({
        "scene": {"name": "inside", "background": SKY, "ambient": [1.0, 1.0, 1.0]},
        "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_y": 60.0, "resolution": [W, H]},
        "lights": [{"type": "directional", "direction": [0, -1, 0], "intensity": 0.0}],
        "materials": {"glass": {"color": [0.5, 0.5, 0.5], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kt": 1.0, "ior": 1.3},
                      "floor": {"color": FLOOR, "ka": 1.0, "kd": 0.0}},
        "objects": objects})


@pytest.mark.gl
@pytest.mark.parametrize("mode", ["phong", "gouraud"])
@pytest.mark.parametrize("kind", sorted(CLOSED))
def test_camera_inside_closed_glass_sees_the_scene_through_it(kind, mode, gl_ctx):
    img = render(_scene(CLOSED[kind]), mode).image.astype(np.float64)
    bare = render(_scene(None), mode).image.astype(np.float64)
    assert np.isfinite(img).all()
    ratio = img.mean() / bare.mean()
    assert 0.35 <= ratio <= 0.7, (kind, mode, ratio)
    green = img[..., 1] > img[..., 2]
    assert green[-H // 4:].mean() >= 0.8, (kind, mode, green.mean(1))
    assert (~green[:H // 4]).mean() >= 0.8, (kind, mode, green.mean(1))
