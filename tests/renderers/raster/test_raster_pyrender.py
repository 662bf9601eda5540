"""pyrender reference: same camera (silhouettes agree with Phong), the Lambert mapping
(brightness of a diffuse sphere agrees), and moderngl keeps working in the same process."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.scene.io import scene_from_dict


def _scene():
    return scene_from_dict({
        "scene": {"ambient": [0.0, 0.0, 0.0], "background": [0.0, 0.0, 0.0]},
        "camera": {"position": [0.5, 0.4, 4.0], "look_at": [0.2, 0.0, 0.0], "fov_y": 40.0, "resolution": [64, 48]},
        "lights": [{"type": "directional", "direction": [-0.3, -0.4, -1.0], "intensity": 1.0}],
        "materials": {"m": {"color": [0.8, 0.5, 0.3], "ka": 0.0, "kd": 0.9, "ks": 0.0}},
        "objects": [{"type": "sphere", "material": "m", "center": [0.3, 0.1, 0.0], "radius": 1.0}]})


def test_pyrender_matches_phong_silhouette_and_lambert(gl_ctx):
    scene = _scene()
    ref = workbench.render(scene, "pyrender", tessellation=8)
    ph = workbench.render(scene, "phong", tessellation=8)
    a, b = ref.depth < np.inf, ph.depth < np.inf
    iou = (a & b).sum() / (a | b).sum()
    assert iou > 0.97, iou
    # Lambert term: pyrender's (1 - F) c_diff / pi * pi I against kd C (N.L) I; Fresnel
    # (F0 = 0.04) and 8-bit output leave a few per cent
    both = a & b & (ph.image[..., 0] > 0.1)
    ratio = np.median(ref.image[both] / np.maximum(ph.image[both], 1e-6), axis=0)
    assert np.allclose(ratio, 1.0, atol=0.08), ratio
    # depth: camera-space distance along the view axis in both
    assert np.median(np.abs(ref.depth[both] - ph.depth[both])) < 1e-2
    # the moderngl path still works after pyrender ran in this process
    again = workbench.render(scene, "phong", tessellation=8)
    assert np.array_equal(again.image, ph.image)


@pytest.mark.slow  # a fresh interpreter imports pyrender and trimesh: several seconds
def test_pyrender_in_a_child_process_gives_the_same_image(gl_ctx):
    scene = workbench.load_scene("whitted")
    here = workbench.render(scene, "pyrender", width=48, height=36)
    child = workbench.render(scene, "pyrender", width=48, height=36, isolate=True)
    assert child.stats["isolated"]
    assert np.abs(child.image - here.image).max() < 2e-2  # same driver, same 8-bit output


def test_unattenuated_point_light_is_scaled_at_the_transformed_scene_centre(gl_ctx):
    # a sphere moved far from the origin by its transform, lit by a distant point light without
    # falloff: pyrender's r^2 division is undone at the world centre of the sphere, so its
    # Lambert shading matches ours within the light's distance ratio across the sphere (+-4 %)
    scene = scene_from_dict({
        "scene": {"ambient": [0.0, 0.0, 0.0], "background": [0.0, 0.0, 0.0]},
        "camera": {"position": [20.0, 0.0, 5.0], "look_at": [20.0, 0.0, 0.0], "fov_y": 30.0,
                   "resolution": [48, 48]},
        "lights": [{"type": "point", "position": [20.0, 0.0, 50.0], "intensity": 1.0}],
        "materials": {"m": {"color": [0.8, 0.8, 0.8], "ka": 0.0, "kd": 0.9, "ks": 0.0}},
        "objects": [{"type": "sphere", "material": "m", "radius": 1.0,
                     "transform": {"translate": [20.0, 0.0, 0.0]}}]})
    ref = workbench.render(scene, "pyrender", tessellation=8)
    ph = workbench.render(scene, "phong", tessellation=8)
    both = (ref.depth < np.inf) & (ph.depth < np.inf) & (ph.image[..., 0] > 0.2)
    assert both.sum() > 200
    ratio = np.median(ref.image[both] / np.maximum(ph.image[both], 1e-6), axis=0)
    assert np.allclose(ratio, 1.0, atol=0.08), ratio
