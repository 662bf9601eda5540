"""Hypertextures in the raster methods (GLSL march through a 3D texture, ``raster_volume``) and
in their CPU twin, the Z-buffer (``zbuffer_volume``): the two agree, converge to the
analytic emission-absorption answer, refuse textures above the limit and give no NaN."""
from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

import workbench
from workbench.core.errors import WorkbenchError
from workbench.renderers.base import get_renderer
from workbench.renderers.support import Status
from workbench.scene import features as ft

from media_scenes import medium_toml

R0, SOFT, DENSITY = 0.5, 0.4, 1.5
ANALYTIC = medium_toml(name="hypertexture-analytic", distance=3.0, resolution=(9, 9), size=R0, soft=SOFT,
                       noise='"none"', density=DENSITY, emission="[1.0, 1.0, 1.0]", step=0.23)


def _fire(grid: int = 0, camera=None):
    """The bundled fire scene, its hypertexture given ``grid`` (and the camera ``camera``)."""
    s = workbench.load_scene("fire")
    objs = tuple(replace(o, grid=grid) if o.kind == "hypertexture" else o for o in s.objects)
    s = replace(s, objects=type(s.objects)(objs))
    return s if camera is None else s.with_camera(camera)


TWIN = {"interpolation": "screen", "standins": "off"}
"""The GL options whose images the Z-buffer twins (test_zbuffer.py): the bare local model,
varyings linear in screen space."""


@pytest.mark.parametrize("ball", [False, True])
def test_gl_march_and_cpu_twin_agree_on_fire(ball, gl_ctx):
    """Phong (GL, float32) and the Z-buffer (numpy, float64) on fire at 48x36, the medium a
    grid object (both sample the same 24^3 grid); with ``ball`` an opaque sphere inside the
    medium clips the march at the depth buffer (its centre pixel loses most of the glow).
    Measured: RMSE 3e-7, largest pixel difference 6e-6 (values up to 2.9): llvmpipe's
    trilinear filter matched sample_grid to float32 here, though GL allows 8-bit weight
    fractions (a weight off by 1/512 times the jump between neighbour texels, up to ~0.3 at
    24^3: D off by ~6e-4, a pixel by ~1e-3 along ~115 steps).  A pixel whose segment length is
    within float32 rounding of a multiple of the step gets one step more or less (every sample
    moves: ~1e-3).  Bounds: RMSE 1e-3, 99 % of the pixels within 2e-3, every pixel within 2e-2."""
    from workbench.scene.model import Sphere
    s = _fire(grid=24)
    if ball:
        s = replace(s, objects=type(s.objects)(tuple(s.objects)
                                               + (Sphere(material="floor", center=(0.0, 1.0, 0.0), radius=0.4),)))
    a = workbench.render(s, "phong", width=48, height=36, **TWIN)
    b = workbench.render(s, "zbuffer", width=48, height=36, shading="phong")
    assert a.stats["volume_resolutions"] == [24]
    d = np.abs(a.image.astype(np.float64) - b.image).max(-1)
    assert math.sqrt(float((d ** 2).mean())) < 1e-3
    assert np.quantile(d, 0.99) < 2e-3 and d.max() < 2e-2
    centre = float(a.image[18, 24, 0])
    assert (centre < 1.0) if ball else (centre > 2.0)  # measured 0.63 and 2.84


@pytest.mark.parametrize("method", ["phong", "zbuffer"])
def test_march_converges_to_the_analytic_optical_depth(method, tmp_path, gl_ctx):
    """noise none, bias = gain = 1/2: D = clamp(1/2 - (|x| - r0) / soft, 0, 1), whose integral
    along a line through the centre is 2 r0 (the ramp is symmetric about r0), so the centre
    pixel sees L = E (1 - exp(-2 r0 density)) (albedo 0, black background).  Texture and step
    refined together: the error falls (measured 1.2e-2 .. 5e-5 for phong, GL's 8-bit weights
    included) and ends below 3e-4."""
    path = tmp_path / "analytic.toml"
    path.write_text(ANALYTIC)
    s = workbench.load_scene(path)
    exact = 1.0 - math.exp(-2.0 * R0 * DENSITY)
    errors = []
    for res, scale in ((8, 1.0), (16, 0.5), (32, 0.25), (64, 0.125), (128, 0.0625)):
        r = workbench.render(s, method, width=9, height=9, volume_resolution=res, step_scale=scale)
        errors.append(abs(float(r.image[4, 4, 0]) - exact))
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 3e-4, errors


def test_texture_above_the_limit_is_one_line_and_exit_2(tmp_path):
    """volume_resolution 1024 (4 GiB of float32) is refused before anything is baked, through
    the console script: one line, exit 2, no image."""
    for method in ("phong", "zbuffer"):
        p = subprocess.run([sys.executable, "-m", "workbench", "render", "fire", "-m", method, "--size", "16x12",
                            "--set", "volume_resolution=1024", "-o", str(tmp_path / "x.png")],
                           capture_output=True, text=True, timeout=300, cwd=tmp_path)
        lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
        assert p.returncode == 2, p.stderr[-2000:]
        assert len(lines) == 1 and "volume_resolution" in lines[0] and "MiB" in lines[0], lines
        assert not (tmp_path / "x.png").exists()


def test_bad_volume_options_refused():
    s = _fire()
    for method in ("phong", "zbuffer"):
        with pytest.raises(WorkbenchError, match="step_scale"):
            get_renderer(method).estimate_bytes(s, 8, 6, step_scale=1e-6)
        with pytest.raises(WorkbenchError, match="volume_resolution"):
            workbench.render(s, method, width=8, height=6, volume_resolution=1)


def test_camera_inside_the_medium_no_nan_and_twins_agree(gl_ctx):
    """Camera at the fire's centre (t0 = 0: the march starts at the eye), and on its bounding
    sphere: finite images, GL and numpy within the bounds of the fire test."""
    from workbench.scene.kinds.hypertexture import bound_radius
    s0 = _fire(grid=16)
    R = bound_radius(next(o for o in s0.objects if o.kind == "hypertexture"))
    for pos in ([0.0, 1.0, 0.0], [0.0, 1.0, -R]):
        cam = replace(s0.camera, position=tuple(pos), look_at=(0.0, 1.0, 2.0))
        s = s0.with_camera(cam)
        a = workbench.render(s, "gouraud", width=24, height=18, **TWIN)
        b = workbench.render(s, "zbuffer", width=24, height=18)
        assert a.stats["nonfinite_pixels"] == 0 and b.stats["nonfinite_pixels"] == 0
        assert float(a.image.max()) > 0.1
        d = np.abs(a.image.astype(np.float64) - b.image)
        assert math.sqrt(float((d ** 2).mean())) < 1e-3


def test_support_tables_say_approximated():
    for method in ("flat", "gouraud", "phong", "zbuffer"):
        cell = get_renderer(method).support[ft.HYPERTEXTURES]
        assert cell.status is Status.APPROXIMATED and "3D texture" in cell.reason


def test_medium_drawn_not_reported_empty(gl_ctx):
    """The hypertexture has no triangles but is drawn: not in the 'objects' note, counted as used."""
    r = workbench.render(_fire(), "flat", width=16, height=12)
    assert ft.HYPERTEXTURES in r.features_used
    assert not any(n.feature == "objects" for n in r.left_out)
