"""Every solid kind as either operand of each CSG operation with a box: the raster's mesh
booleans (Phong) take it (no "not a closed manifold" in ``left_out``, which happened for the
smooth lathes: their tessellation's rings at the segments' joints were an ulp apart) and draw
the silhouette the ray caster sees (IoU of covered pixels >= 0.97 at 64 x 48)."""
from __future__ import annotations

import pytest

import workbench
from workbench.core.errors import NotApplicable
from seen_pixels import coverage, iou, scene_dict
from workbench.scene.io import scene_from_dict

W, H = 64, 48
M = {"material": "m"}
SOLIDS = {  # kind -> a solid about the origin, about 1 across
    "sphere": {"type": "sphere", "radius": 0.9},
    "box": {"type": "box", "min": [-0.8, -0.7, -0.6], "max": [0.8, 0.7, 0.6], "transform": {"rotate": [20, 30, 0]}},
    "quadric ellipsoid": {"type": "quadric", "shape": "ellipsoid", "radii": [0.9, 0.7, 0.5]},
    "quadric cut cylinder": {"type": "quadric", "shape": "cylinder", "radii": [0.5, 1.0, 0.5],
                             "bounds": {"min": [-0.9, -0.9, -0.9], "max": [0.9, 0.9, 0.9]}},
    "mesh": {"type": "mesh", "generate": {"kind": "torus", "subdivisions": 2, "radius": 0.9},
             "transform": {"rotate": [60, 0, 0]}},
    "csg": {"type": "csg", "op": "difference", "left": {"type": "sphere", "radius": 0.9, **M},
            "right": {"type": "sphere", "center": [-0.6, 0.3, 0.5], "radius": 0.5, **M}},
    "blob": {"type": "blob", "threshold": 0.3, "components": [{"center": [-0.3, 0, 0], "radius": 0.8},
                                                               {"center": [0.4, 0.1, 0], "radius": 0.7}]},
    "isosurface": {"type": "isosurface", "function": "(sqrt(x^2 + z^2) - 0.6)^2 + y^2", "threshold": 0.06,
                   "max_gradient": 5.0, "bounds": {"min": [-1, -0.3, -1], "max": [1, 0.3, 1]},
                   "transform": {"rotate": [60, 0, 0]}},
    "lathe linear": {"type": "lathe", "points": [[0, -0.8], [0.5, -0.8], [0.3, -0.3], [0.7, 0.4], [0.4, 0.8], [0, 0.6]]},
    "lathe quadratic": {"type": "lathe", "spline": "quadratic",
                        "points": [[0.3, -1.0], [0, -0.8], [0.6, -0.6], [0.8, 0.2], [0.4, 0.8], [0, 0.8]]},
    "lathe cubic": {"type": "lathe", "spline": "cubic",  # the bundled vase's profile
                    "points": [[-0.5, 0.0], [0.0, 0.0], [0.5, 0.0], [0.62, 0.35], [0.45, 0.8], [0.2, 1.1],
                               [0.24, 1.4], [0.0, 1.5], [-0.24, 1.5]], "transform": {"translate": [0, -0.75, 0]}},
    "lathe cubic loop": {"type": "lathe", "spline": "cubic",  # closed by first == last, off the axis
                         "points": [[0.3, 0.4], [0.3, -0.5], [0.8, -0.4], [0.8, 0.5], [0.3, 0.4], [0.3, -0.5],
                                    [0.8, -0.4]]},
    "lathe bezier": {"type": "lathe", "spline": "bezier",
                     "points": [[0.0, -0.8], [0.6, -0.8], [0.9, 0.0], [0.5, 0.2], [0.5, 0.2], [0.2, 0.4],
                                [0.8, 0.9], [0.0, 0.8]]},
    "prism": {"type": "prism", "polygon": [[0.9, 0], [0.3, 0.25], [0.3, 0.9], [-0.1, 0.4], [-0.8, 0.6], [-0.4, 0],
                                           [-0.8, -0.6], [-0.1, -0.4], [0.3, -0.9], [0.3, -0.25]],
              "heights": [-0.4, 0.4], "transform": {"rotate": [70, 0, 0]}},
}
BOX = {"type": "box", "min": [-0.2, -0.3, -1.2], "max": [1.2, 1.2, 1.2], **M}


def _scene(kind: str, op: str, side: str):
    solid = {**SOLIDS[kind], **M}
    left, right = (solid, BOX) if side == "left" else (BOX, solid)
    node = {"type": "csg", "op": op, "left": left, "right": right, **M,
            "transform": {"rotate": [0, 25, 0]}}
    cam = {"position": [0.8, 1.2, 4.5], "look_at": [0, 0, 0], "fov_y": 45.0, "resolution": [W, H]}
    return scene_from_dict(scene_dict([node], camera=cam))


@pytest.mark.gl
@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("op", ["difference", "intersection", "union"])
@pytest.mark.parametrize("kind", sorted(SOLIDS))
def test_raster_csg_takes_every_solid_kind(kind, op, side, gl_ctx):
    sc = _scene(kind, op, side)
    r = workbench.render(sc, "phong", width=W, height=H)
    assert not [x for x in r.left_out if x.feature == "csg" or "manifold" in x.reason], r.left_out
    ras = coverage(sc, "phong", W, H)
    if kind == "mesh":  # the ray tracer refuses a mesh inside CSG (documented): nothing to compare
        with pytest.raises(NotApplicable, match="mesh inside a CSG"):
            workbench.render(sc, "raycast", width=W, height=H)
        assert ras.sum() > 100
        return
    ray = coverage(sc, "raycast", W, H)
    assert ray.sum() > 100, (kind, op, side, int(ray.sum()))
    assert iou(ray, ras) >= 0.97, (kind, op, side, iou(ray, ras), int(ray.sum()), int(ras.sum()))
