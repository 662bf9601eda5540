"""The ``povray`` method: the exported scene rendered by POV-Ray 3.7 against the workbench's own
ray tracer, the camera's pixel convention, and what is left out.

Tolerance of the image comparisons: POV-Ray writes 16 bits per channel (half a step is
7.6e-6) and clips at 1, so the ray tracer's image is clipped at 1 before comparing; the two
programs then compute the same model (same camera rays, local model, Whitted recursion with
the same depth and bail-out, transmissive shadows), so nearly every pixel agrees within 1e-4
(quantisation and float32).  A few pixels may not: a ray grazing a silhouette, or a secondary
ray starting within the two programs' different self-intersection offsets, can go either way
(at most 0.1 % of the pixels; 12 of 307,200 on Whitted's scene at 640x480).
"""
from __future__ import annotations

import shutil

import numpy as np
import pytest

from child_processes import children

import workbench
from workbench.core.errors import WorkbenchError
from workbench.renderers import povray_sdl
from workbench.renderers.povray import progress_report
from workbench.scene.io import scene_from_dict

pytestmark = pytest.mark.skipif(shutil.which("povray") is None, reason="POV-Ray not installed (Debian package povray)")

QUANT = 1e-4      # 16-bit output + float32, with margin
OUTLIERS = 1e-3   # fraction of pixels allowed beyond QUANT (silhouette and offset decisions)


def _agree(pov: np.ndarray, ours: np.ndarray) -> tuple[float, float]:
    """(fraction of pixels beyond QUANT, mean absolute difference) against ``ours`` clipped at 1."""
    d = np.abs(pov - np.minimum(ours, 1.0)).max(-1)
    return float((d > QUANT).mean()), float(d.mean())


def test_whitted_matches_the_ray_tracer():
    scene = workbench.load_scene("whitted")
    pov = workbench.render(scene, "povray", width=160, height=120)
    ours = workbench.render(scene, "raytrace", width=160, height=120, transmissive_shadows=True)
    frac, mean = _agree(pov.image, ours.image)
    assert frac <= OUTLIERS, frac
    assert mean < 2e-4, mean
    assert pov.image.dtype == np.float32 and pov.image.shape == (120, 160, 3)
    # the glass and the mirror were traced: POV-Ray counted reflected and refracted rays
    assert pov.stats["reflected_rays"] > 0 and pov.stats["refracted_rays"] > 0
    # a different depth gives a different picture (the knob reaches POV-Ray)
    shallow = workbench.render(scene, "povray", width=160, height=120, max_trace_level=1)
    assert np.abs(shallow.image - pov.image).max() > 0.1


def _projection_scene():
    return scene_from_dict({
        "scene": {"ambient": [1.0, 1.0, 1.0], "background": [0.0, 0.0, 0.0]},
        "camera": {"position": [1.3, -0.4, 5.0], "look_at": [0.2, 0.3, -0.5], "up": [0.3, 1.0, 0.1],
                   "fov_y": 35.0, "resolution": [61, 47]},
        "materials": {"white": {"color": [1.0, 1.0, 1.0], "ka": 1.0, "kd": 0.0, "ks": 0.0}},
        "objects": [{"type": "sphere", "material": "white", "center": [1.1, 0.9, 0.4], "radius": 0.12}]})


def test_camera_pixel_convention_by_projecting_a_point():
    # a small self-lit sphere: the centroid of its pixels is where Camera.project puts its
    # centre (the perspective shift of a disc this small is far below 0.05 px); POV-Ray's camera
    # is left-handed by default: a mirrored or shifted picture would move it by pixels
    scene = _projection_scene()
    img = workbench.render(scene, "povray").image[..., 0]
    assert 0 < (img > 0.5).sum() < 200
    rows, cols = np.indices(img.shape)
    centroid = np.array([(cols * img).sum(), (rows * img).sum()]) / img.sum() + 0.5
    xy, depth = scene.camera.project(np.array([[1.1, 0.9, 0.4]]))
    assert depth[0] > 0
    assert np.abs(centroid - xy[0]).max() < 0.15, (centroid, xy[0])
    # and the same pixels as the ray caster's
    ours = workbench.render(scene, "raycast").image[..., 0]
    assert np.array_equal(img > 0.5, ours > 0.5)


def _shapes_scene():
    """A mesh with vertex normals under a non-uniform scale, a rotated box with a solid checker,
    an inverse-square point light and a directional light.  (A coarse smooth mesh would differ
    along its silhouettes: where the interpolated normal faces away from the eye the ray tracer
    turns it round, POV-Ray decides by the triangle's own normal.)"""
    s = 2.0 ** -0.5
    return scene_from_dict({
        "scene": {"ambient": [0.2, 0.2, 0.2], "background": [0.05, 0.05, 0.1]},
        "camera": {"position": [0.5, 2.0, 6.0], "look_at": [0.0, 0.3, 0.0], "fov_y": 40.0, "resolution": [96, 72]},
        "lights": [{"type": "point", "position": [-2.0, 4.0, 3.0], "intensity": 20.0, "falloff": "inverse_square"},
                   {"type": "directional", "direction": [0.4, -1.0, -0.3], "intensity": 0.3}],
        "materials": {
            "cube": {"color": [1.0, 1.0, 1.0], "ka": 0.2, "kd": 0.7, "ks": 0.3, "shininess": 20.0,
                     "texture": {"type": "checker", "projection": "solid", "scale": 2.5,
                                 "colors": [[0.9, 0.8, 0.2], [0.2, 0.3, 0.8]]}},
            "gem": {"color": [0.8, 0.3, 0.3], "ka": 0.1, "kd": 0.7, "ks": 0.6, "shininess": 80.0, "kr": 0.3},
            "floor": {"color": [0.6, 0.6, 0.6], "ka": 0.3, "kd": 0.7}},
        "objects": [
            {"type": "box", "material": "cube", "min": [-0.5, 0.0, -0.5], "max": [0.5, 1.0, 0.5],
             "transform": {"translate": [-1.2, 0.0, 0.0], "rotate": [0.0, 30.0, 0.0]}},
            {"type": "mesh", "material": "gem", "generate": {"kind": "icosphere", "subdivisions": 3},
             "transform": {"scale": [0.5, 0.9, 0.7], "rotate": [20.0, 35.0, 0.0], "translate": [1.0, 0.9, 0.2]}},
            {"type": "polygon", "material": "floor",
             "vertices": [[-3, 0, -3], [-3, 0, 3], [3, 0, 3], [3 * s, 0, -3]]}]})


@pytest.mark.parametrize("name", ["csg", "quadrics", "shapes"])
def test_csg_quadrics_meshes_and_lights_match_the_ray_tracer(name):
    scene = _shapes_scene() if name == "shapes" else workbench.load_scene(name)
    pov = workbench.render(scene, "povray", width=96, height=72)
    ours = workbench.render(scene, "raytrace", width=96, height=72, transmissive_shadows=True)
    assert pov.left_out == []
    frac, mean = _agree(pov.image, ours.image)
    assert frac <= OUTLIERS, frac
    assert mean < 2e-4, mean


def test_what_povray_cannot_express_is_left_out():
    pov = workbench.render(workbench.load_scene("bricks"), "povray", width=32, height=24)
    assert any(x.feature == "bump" for x in pov.left_out)
    assert any(x.feature == "textures" and "bricks" in x.reason for x in pov.left_out)
    assert "bump" not in pov.features_used
    env = workbench.load_scene("envmap")
    ex = povray_sdl.export(env, 32, 24)
    assert any(x.feature == "environment" for x in ex.left_out)


def test_transmission_scales_ambient_and_diffuse_for_povray():
    # POV-Ray weighs ambient, diffuse and emission by (1 - transmit): the exporter divides them
    mat = workbench.load_scene("whitted").materials["glass"]  # kt 0.85, kd 0.05, ka 0
    sdl = povray_sdl.export(workbench.load_scene("whitted"), 8, 6).sdl
    line = next(x for x in sdl.splitlines() if "rgbt <1, 1, 1, 0.85>" in x)
    assert f"diffuse {mat.kd / (1 - mat.kt):.10g}" in line and "ior 1.5" in line


def test_missing_program_and_bad_options_are_one_line_errors(monkeypatch):
    scene = _projection_scene()
    with pytest.raises(WorkbenchError, match="max_trace_level"):
        workbench.render(scene, "povray", max_trace_level=0)
    monkeypatch.setenv("PATH", "/nonexistent")
    with pytest.raises(WorkbenchError, match="needs the POV-Ray 3.7 program 'povray'"):
        workbench.render(scene, "povray")


def test_estimate_covers_the_images_read_back():
    from workbench.renderers.base import get_renderer
    r = get_renderer("povray")
    scene = workbench.load_scene("mesh")  # 81,920 triangles written as text
    small, big = r.estimate_bytes(scene, 10, 10), r.estimate_bytes(scene, 1000, 1000)
    assert big - small == (1000 * 1000 - 100) * 3 * (2 + 8 + 4 + 16)  # + POV-Ray's float buffer
    assert small > 81920 * 50  # the mesh's SDL text (at least 50 bytes a triangle)


def test_progress_report_reads_povrays_verbose_output():
    lines = ["==== [Parsing...] ====", "Parser Statistics", "==== [Rendering...] ====",
             "Rendered 1024 of 4096 pixels (25%)", "Rendered 2048 of 4096 pixels (50%)"]
    start = ("POV-Ray starting", 0, None, "")
    assert progress_report([], start) == start
    assert progress_report(lines[:2], start) == ("POV-Ray parsing", 0, None, "")
    assert progress_report(lines[:3], start) == ("POV-Ray rendering", 0, None, "")
    assert progress_report(lines, start) == ("POV-Ray rendering", 2048, 4096, "pixels")


class Stop(Exception):
    """Raised by a progress callback: the render must end with it, and POV-Ray with it."""


def test_progress_is_povrays_own_report_and_a_stop_ends_povray():
    """The window's progress bar of the povray method (issue #29); a cancelled job's next
    report raises, which must end the POV-Ray process (before: it ran on unseen)."""
    scene = workbench.load_scene("whitted")
    steps = []
    res = workbench.render(scene, "povray", width=160, height=120, on_progress=lambda *a: steps.append(a))
    assert steps[0] == ("POV-Ray starting", 0, None, "")
    assert steps[-1] == ("POV-Ray rendering", 160 * 120, 160 * 120, "pixels")
    counted = [s[1] for s in steps if s[3] == "pixels"]
    assert counted == sorted(counted)
    assert np.array_equal(res.image, workbench.render(scene, "povray", width=160, height=120).image)
    before = children()

    def stop(phase, *_):
        if phase != "POV-Ray starting":
            raise Stop
    with pytest.raises(Stop):
        workbench.render(scene, "povray", width=640, height=480, on_progress=stop)
    assert children() <= before
