"""The prepared scene (issue 14, :mod:`workbench.scene.prepared`): its bounds, extent, clip
planes and camera media against analytic values, and every renderer reading the same ones."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.scene.clip_planes import DEPTH_MARGIN, FAR_GROWTH, NEAR_SHRINK
from workbench.scene.io import scene_from_dict
from workbench.scene.prepared import prepare

MATS = {"m": {"color": [0.8, 0.8, 0.8], "ka": 0.2, "kd": 0.7},
        "glass": {"color": [1, 1, 1], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kt": 1.0, "ior": 1.5}}
CAMERA = {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_y": 90.0, "resolution": [32, 32]}


def make(objects, lights=(), camera=None):
    return scene_from_dict({"scene": {}, "camera": camera or CAMERA, "materials": MATS,
                            "lights": list(lights) or [{"type": "point", "position": [0, 5, 0]}],
                            "objects": objects})


def _close(a, b, rel=1e-12):
    """Equal to ``rel`` of the largest magnitude (a few roundings of a transform)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return np.abs(a - b).max() <= rel * max(1.0, np.abs(b).max())


def test_sphere_bounds_are_its_centre_plus_minus_its_radius_after_the_transform():
    sc = make([{"type": "sphere", "center": [1, 2, 3], "radius": 0.5, "material": "m",
                "transform": {"translate": [10, 0, 0], "scale": 2.0}}])
    p = prepare(sc)
    assert p.object_bounds.shape == (1, 2, 3)
    assert _close(p.object_bounds[0], [[11, 3, 5], [13, 5, 7]])
    assert _close(p.bounds, [[11, 3, 5], [13, 5, 7]])
    assert p.extent == pytest.approx(np.sqrt(12.0), rel=1e-12)


def test_a_rotated_scaled_box_has_the_box_of_its_turned_corners():
    """The unit cube [-1, 1]^3 scaled by 2 and turned 45 degrees about y: half-widths
    2 sqrt(2) in x and z, 2 in y (centred at the translation)."""
    sc = make([{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1], "material": "m",
                "transform": {"translate": [0, 0, -10], "rotate": [0, 45, 0], "scale": 2.0}}])
    lo, hi = prepare(sc).object_bounds[0]
    h = 2.0 * np.sqrt(2.0)
    assert _close(lo, [-h, -2, -10 - h]) and _close(hi, [h, 2, -10 + h])


def test_csg_and_area_lights_count_in_the_scene_bounds():
    """A CSG node's box holds both operands (each under the node's transform); an area light's
    polygon extends the scene's box and extent but is not an object."""
    csg = {"type": "csg", "op": "difference", "material": "m", "transform": {"translate": [0, 0, -5]},
           "left": {"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": "m"},
           "right": {"type": "sphere", "center": [1.5, 0, 0], "radius": 1.0, "material": "m"}}
    light = {"type": "area", "vertices": [[-1, 4, -6], [1, 4, -6], [1, 4, -4], [-1, 4, -4]]}
    p = prepare(make([csg], lights=[light]))
    assert _close(p.object_bounds[0], [[-1, -1, -6], [2.5, 1, -4]])
    assert len(p.area_lights) == 1 and p.light_bounds.shape == (1, 2, 3)
    assert _close(p.light_bounds[0], [[-1, 4, -6], [1, 4, -4]])
    assert _close(p.bounds, [[-1, -1, -6], [2.5, 4, -4]])
    assert p.extent == pytest.approx(np.linalg.norm([3.5, 5.0, 2.0]), rel=1e-12)


def test_near_and_far_of_a_box_in_front_of_the_camera():
    """A box at depths 4..6 wholly in a 90-degree view: near = NEAR_SHRINK * 4, far =
    FAR_GROWTH * 6 (the depth-margin rule needs less); the camera's own planes win."""
    box = {"type": "box", "min": [-1, -1, -6], "max": [1, 1, -4], "material": "m"}
    p = prepare(make([box]))
    assert p.near == pytest.approx(NEAR_SHRINK * 4.0, rel=1e-12)
    assert p.far == pytest.approx(FAR_GROWTH * 6.0, rel=1e-12)
    assert p.near * (1 - DEPTH_MARGIN) / (p.near - DEPTH_MARGIN * 6.0) * 6.0 < p.far
    own = prepare(make([box], camera={**CAMERA, "near": 0.5, "far": 100.0}))
    assert (own.near, own.far) == (0.5, 100.0)
    # a moved camera (a session's): the same rule from the same boxes
    cam = make([box], camera={**CAMERA, "position": [0, 0, 2]}).camera
    n, f = p.clip_planes(cam)
    assert n == pytest.approx(NEAR_SHRINK * 6.0, rel=1e-12) and f == pytest.approx(FAR_GROWTH * 8.0, rel=1e-12)


def test_a_camera_inside_a_glass_sphere_is_in_its_medium():
    glass = {"type": "sphere", "center": [0, 0, 0], "radius": 2.0, "material": "glass"}
    wall = {"type": "plane", "point": [0, 0, -5], "normal": [0, 0, 1], "size": [20, 20], "material": "m"}
    inside = prepare(make([wall, glass], camera={**CAMERA, "position": [0.3, 0.2, 0.5]}))
    assert [m.name for m in inside.camera_media] == ["glass"]
    outside = prepare(make([wall, glass], camera={**CAMERA, "position": [0, 0, 3]}))
    assert outside.camera_media == ()


def _far_light_scene():
    """A sphere in front and an area light much farther, in view: the light sets the far
    plane (the raster methods draw its polygon; pyrender drew no polygon and, before the
    prepared scene, fitted its far plane to the sphere alone)."""
    return make([{"type": "sphere", "center": [0, 0, -4], "radius": 1.0, "material": "m"}],
                lights=[{"type": "area", "vertices": [[-1, -1, -40], [1, -1, -40], [1, 1, -40], [-1, 1, -40]],
                         "intensity": 1.0}],
                camera={**CAMERA, "resolution": [16, 12]})


def test_raster_zbuffer_and_pyrender_use_the_prepared_clip_planes():
    """Every raster method gets the same near and far: those of the prepared scene (16 x 12,
    the size the render uses, since the frustum's width depends on the aspect)."""
    sc = _far_light_scene()
    p = prepare(sc)
    assert p.far >= 40.0
    for method in ("flat", "zbuffer", "pyrender"):
        st = workbench.render(sc, method, width=16, height=12).stats
        assert (st["near"], st["far"]) == (p.near, p.far), method


def test_ray_tracer_and_radiosity_use_the_prepared_extent():
    """The ray tracer's offsets and radiosity's patch size scale with the same extent, the
    diagonal of the prepared bounds (radiosity took it from a level-1 tessellation of its
    curved surfaces: for this sphere turned 30 degrees about z, 22 % less than the ray
    tracer's, the box of the turned corners of the sphere's object-space box)."""
    sc = make([{"type": "sphere", "center": [0, 0, 0], "radius": 3.0, "material": "m",
                "transform": {"translate": [0, 0, -6], "rotate": [0, 0, 30]}}],
              lights=[{"type": "area", "vertices": [[2.0, 2.5, -3.5], [2.8, 2.5, -3.5], [2.8, 2.5, -3.1],
                                                    [2.0, 2.5, -3.1]], "intensity": 1.0}],
              camera={**CAMERA, "resolution": [8, 6]})
    p = prepare(sc)
    h = 3.0 * (np.cos(np.radians(30)) + np.sin(np.radians(30)))
    assert p.extent == pytest.approx(np.linalg.norm([2 * h, 2 * h, 6.0]), rel=1e-12)
    assert workbench.render(sc, "raycast", width=8, height=6).stats["scene_extent"] == p.extent
    st = workbench.render(sc, "radiosity", width=8, height=6, patch_size=0.5, hemicube_resolution=16).stats
    assert st["patch_size_world"] == 0.5 * p.extent


@pytest.mark.parametrize("method", ["radiosity", "raycast", "flat"])
def test_a_render_builds_its_prepared_scene_once(monkeypatch, method):
    """The prepared scene is built once per render (issue 27, item 1): the memory estimate and
    the renderer (radiosity asked twice before) read the one kept on the sized scene."""
    from workbench.scene import prepared

    built = []
    real = prepared.build
    monkeypatch.setattr(prepared, "build", lambda s: built.append(s) or real(s))
    sc = _far_light_scene()
    workbench.render(sc, method, width=16, height=12)
    assert len(built) == 1, [s.camera.width for s in built]
    assert prepared.prepare(built[0]) is prepared.prepare(built[0])
