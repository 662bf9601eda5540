"""Scale invariance of the ray tracer with refraction at a contact (issue 26, item 4): a glass
object of every kind resting on (touching) a floor, with its camera and lights, scaled by
1e-6 and 1e6, renders the image of scale 1.  Every offset and epsilon of the ray tracer is
relative (``tol.ray_offset``, ``tol.t_min`` times the larger of the hit point's magnitude and
the scene's extent), so the three images agree; the bound allows 4 of the 48 x 36 pixels to
differ by more than 0.05 (a grazing ray at a silhouette, where the last bit decides).  A box's
bottom face coincides with the floor: surfaces closer than the ray offset are one, the object
listed first wins (``renderers.kernels.intersect.nearer``), whatever the rounding at each scale says.  A mesh's
vertex normals are judged cancelled in object space (at scale 1e6 the inverse transpose makes
them 1e-6 long, and half of them were taken for cancelled).
"""
from __future__ import annotations

import copy

import numpy as np
import pytest

from workbench.compare.stress import scale_scene_dict
from workbench.renderers.base import render
from workbench.scene.io import scene_from_dict

from closed_objects import CLOSED  # closed objects of size ~2 about the origin

#: every kind, lifted so that its lowest point touches the floor y = 0 (a blob's surface
#: is lower than its components' reach: it floats a little; the plane and polygon stand on it)
KINDS = {**{k: (o, 1.8 if k == "quadric" else 0.0 if k == "blob" else 2.0) for k, o in CLOSED.items()},
         "plane": ({"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "size": [3.0, 3.0],
                    "transform": {"rotate": [0, 30, 0]}}, 0.0),
         "polygon": ({"type": "polygon", "vertices": [[-1.5, 0, 0], [1.5, 0, 0], [0, 2.5, 0]]}, 0.0)}


def _scene(kind: str, factor: float):
    obj, lift = KINDS[kind]
    o = copy.deepcopy(obj)
    o["material"] = "glass"
    if kind == "csg":
        o["left"]["material"] = o["right"]["material"] = "glass"
    t = o.setdefault("transform", {})
    x, y, z = t.get("translate", [0.0, 0.0, 0.0])
    t["translate"] = [x, y + lift, z]
    d = {"scene": {"name": "glass_on_floor", "background": [0.2, 0.3, 0.5], "ambient": [0.15, 0.15, 0.15]},
         "camera": {"position": [0.0, 4.0, -10.0], "look_at": [0.0, 1.6, 0.0], "fov_y": 40.0, "resolution": [48, 36]},
         "lights": [{"type": "point", "position": [-6.0, 10.0, -6.0], "intensity": 0.9}],
         "materials": {"glass": {"color": [1, 1, 1], "ka": 0.0, "kd": 0.1, "ks": 0.5, "shininess": 50.0,
                                 "kr": 0.1, "kt": 0.9, "ior": 1.5},
                       "floor": {"color": [0.8, 0.8, 0.8], "ka": 0.2, "kd": 0.8}},
         "objects": [o, {"type": "plane", "material": "floor", "point": [0, 0, 0], "normal": [0, 1, 0],
                         "size": [16.0, 16.0]}]}
    return scene_from_dict(scale_scene_dict(d, factor), source="glass_on_floor")


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_glass_resting_on_the_floor_renders_alike_at_every_scale(kind):
    img = {f: render(_scene(kind, f), "raytrace").image for f in (1e-6, 1.0, 1e6)}
    for f in (1e-6, 1e6):
        assert np.isfinite(img[f]).all()
        off = int((np.abs(img[f] - img[1.0]).max(-1) > 0.05).sum())
        assert off <= 4, (kind, f, off)
