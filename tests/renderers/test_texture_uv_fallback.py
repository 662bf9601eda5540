"""A texture with the default ``projection = "uv"`` on every object kind: kinds without
texture coordinates of their own take the documented spherical fallback
(:func:`workbench.renderers.texturing.project`), and the raster (Phong) and the ray tracer
both apply it: the textured image differs from the untextured one on the object, and the two
methods agree on which checker colour each pixel shows (the path tracer leaves a non-fused
texture out and says so in ``left_out``)."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from seen_pixels import scene_dict
from workbench.renderers.support import Status
from workbench.scene.io import scene_from_dict

W, H = 64, 48
OBJECTS = {
    "sphere": {"type": "sphere", "radius": 1.0},
    "plane": {"type": "plane", "point": [0, 0, 0], "normal": [0.2, 0.3, 1], "size": [2.4, 1.8]},
    "box": {"type": "box", "min": [-0.8, -0.7, -0.6], "max": [0.8, 0.7, 0.6], "transform": {"rotate": [20, 30, 0]}},
    "polygon": {"type": "polygon", "vertices": [[-1, -0.8, 0], [1, -0.8, 0], [1.1, 0.7, 0], [-0.9, 0.9, 0]]},
    "quadric": {"type": "quadric", "shape": "ellipsoid", "radii": [1.0, 0.8, 0.6]},
    "mesh": {"type": "mesh", "generate": {"kind": "torus", "subdivisions": 2, "radius": 0.9},
             "transform": {"rotate": [60, 0, 0]}},
    "csg": {"type": "csg", "op": "difference", "left": {"type": "sphere", "radius": 1.0},
            "right": {"type": "box", "min": [0, 0, 0], "max": [2, 2, 2]}},
    "blob": {"type": "blob", "threshold": 0.3, "components": [{"center": [-0.3, 0, 0], "radius": 0.9},
                                                               {"center": [0.4, 0.1, 0], "radius": 0.8}]},
    "isosurface": {"type": "isosurface", "function": "x^2 + y^2 + z^2", "threshold": 1.0, "max_gradient": 4.2,
                   "bounds": {"min": [-1.2, -1.2, -1.2], "max": [1.2, 1.2, 1.2]}},
    "lathe": {"type": "lathe", "points": [[0, -0.9], [0.6, -0.9], [0.4, -0.3], [0.9, 0.4], [0.5, 0.9], [0, 0.7]]},
    "prism": {"type": "prism", "polygon": [[1, 0], [0.3, 0.3], [0.3, 1], [-0.1, 0.4], [-0.9, 0.6], [-0.4, 0],
                                           [-0.9, -0.6], [-0.1, -0.4], [0.3, -1], [0.3, -0.3]],
              "heights": [-0.4, 0.4], "transform": {"rotate": [60, 0, 0]}},
}
MATERIALS = {"t": {"color": [0.8, 0.8, 0.8], "ka": 0.3, "kd": 0.7,
                   "texture": {"type": "checker", "scale": 6.0, "colors": [[1.0, 0.1, 0.1], [0.1, 0.1, 1.0]]}},
             "m": {"color": [0.8, 0.8, 0.8], "ka": 0.3, "kd": 0.7}}


def _scene(kind: str, material: str):
    obj = {**OBJECTS[kind], "material": material}
    cam = {"position": [0.5, 0.8, 4.5], "look_at": [0, 0, 0], "fov_y": 45.0, "resolution": [W, H]}
    return scene_from_dict(scene_dict([obj], camera=cam, materials=MATERIALS,
                                      lights=[{"type": "point", "position": [1, 2, 6]}]))


@pytest.mark.gl
@pytest.mark.parametrize("kind", sorted(OBJECTS))
def test_default_uv_texture_is_applied_alike(kind, gl_ctx):
    out = {}
    for method in ("phong", "raytrace"):
        tex = workbench.render(_scene(kind, "t"), method, width=W, height=H)
        plain = workbench.render(_scene(kind, "m"), method, width=W, height=H)
        assert not [x for x in tex.left_out if "textur" in str(x) and x.status is not Status.NOT_NEEDED], (method, tex.left_out)
        on = np.isfinite(tex.depth)
        assert on.sum() > 150, (kind, method, int(on.sum()))
        red = tex.image[..., 0] > tex.image[..., 2]
        # both checker colours show, and the object is no longer grey
        assert 0.1 < red[on].mean() < 0.9, (kind, method, red[on].mean())
        assert np.abs(tex.image - plain.image)[on].mean() > 0.1, (kind, method)
        out[method] = (on, red)
    (on_a, red_a), (on_b, red_b) = out["phong"], out["raytrace"]
    both = on_a & on_b
    assert (red_a == red_b)[both].mean() >= 0.8, (kind, (red_a == red_b)[both].mean())
