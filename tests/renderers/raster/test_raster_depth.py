"""The Z-buffer made visible: depth precision (16 / 24 / 32F bits) decides whether a surface
0.01 behind another shows through (z-fighting) with a poor near plane; the depth view."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.scene.io import scene_from_dict

DELTA = 0.01   # gap between the planes
Z = 10.0       # their distance from the camera


def _two_planes(near):
    """A red plane DELTA behind a green one, both facing the camera at distance ~Z.  The red
    plane's centre is nearer to the camera, so it is drawn first: where the depth buffer
    cannot tell the two apart (equal stored depth, test "<") the red one stays visible."""
    return scene_from_dict({
        "scene": {"ambient": [1.0, 1.0, 1.0]},
        "camera": {"position": [0.0, 0.0, Z], "look_at": [0.0, 0.0, 0.0], "fov_y": 30.0,
                   "resolution": [48, 36], "near": near, "far": 100.0},
        "materials": {"red": {"color": [1, 0, 0], "ka": 1.0, "kd": 0.0},
                      "green": {"color": [0, 1, 0], "ka": 1.0, "kd": 0.0}},
        "objects": [
            {"type": "plane", "material": "red", "point": [0.0, 0.0, -DELTA], "normal": [0, 0, 1], "size": [8.0, 8.0]},
            {"type": "plane", "material": "green", "point": [3.0, 0.0, 0.0], "normal": [0, 0, 1], "size": [8.0, 8.0]},
        ]})


def _red_fraction(near, bits):
    r = workbench.render(_two_planes(near), "flat", depth_bits=bits)
    overlap = r.image[:, :, 1] + r.image[:, :, 0] > 0.5
    overlap[:, : r.image.shape[1] // 2] = False  # only where the green plane covers
    green_side = r.image[overlap]
    return float((green_side[:, 0] > 0.5).mean())


@pytest.mark.parametrize("bits", [16, 24, 32])
def test_depth_precision_decides_z_fighting(gl_ctx, bits):
    # poor near plane (0.01): z resolution at Z is about Z^2 / (near 2^bits): 0.15 with 16
    # bits (> DELTA: the back plane wins everywhere), 6e-4 with 24 bits (resolved)
    frac = _red_fraction(0.01, bits)
    if bits == 16:
        assert frac > 0.9, frac
    else:
        assert frac == 0.0, frac
    # a good near plane (1.0) resolves DELTA even with 16 bits (resolution 1.5e-3)
    assert _red_fraction(1.0, bits) == 0.0


def test_depth_view_and_depth_values(gl_ctx):
    scene = workbench.load_scene("whitted")
    r = workbench.render(scene, "phong", width=64, height=48, view="depth")
    d = r.depth
    drawn = np.isfinite(d)
    assert drawn.any() and (~drawn).any()  # the sky is empty
    # depth is the camera-space distance: compare with the ray-cast floor (y = 0)
    o, dirs = scene.camera.with_resolution(64, 48).rays()
    t = -o[..., 1] / dirs[..., 1]
    fwd = np.asarray(scene.camera.look_at) - np.asarray(scene.camera.position)
    fwd /= np.linalg.norm(fwd)
    floor_depth = t * (dirs @ fwd)
    bottom = (slice(44, 48), slice(0, 64))  # the bottom rows see only the floor
    assert np.allclose(d[bottom], floor_depth[bottom], rtol=1e-3)
    # the depth view: white near, black far and where nothing was drawn; monotone in depth
    g = r.image[..., 0]
    assert np.all(g[~drawn] == 0.0)
    order = np.argsort(d[drawn])
    assert np.all(np.diff(g[drawn][order]) <= 1e-6)
