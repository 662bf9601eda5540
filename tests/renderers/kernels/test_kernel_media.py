"""The hypertexture's medium as the ray methods render it: the emission-absorption march of
the ray caster / Whitted tracer (renderers/kernels/media.py) against a closed-form optical
depth, the path tracer's delta tracking against the march on a medium with nothing to scatter,
shadows through the medium, and the bundled scene through the console script."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import workbench
from workbench.scene.io import load_scene
from workbench.scene.kinds import hypertexture as H

from media_scenes import medium_toml
from statistics_budget import band

def _scene_text(noise="none", density=3.0) -> str:
    return medium_toml(distance=4.0, resolution=(33, 25), size=0.6, soft=0.5, noise=f'"{noise}"', frequency=3.0,
                       amplitude=1.0, bias=0.3, gain=0.7, density=density, emission="[2.0, 1.0, 0.5]", step=0.05)


def _scene(tmp_path: Path, noise="none", density=3.0):
    p = tmp_path / "medium.toml"
    p.write_text(_scene_text(noise, density))
    return load_scene(p)


def _optical_depth_through_centre(h: H.Hypertexture, n: int = 200001) -> float:
    """tau along the line through the centre, by the midpoint rule on a fine grid (error ~1e-9)."""
    R = H.bound_radius(h)
    z = (np.arange(n) + 0.5) / n * 2 * R - R
    pts = np.stack([np.zeros(n), np.zeros(n), z], -1)
    return float(h.density * H.field_density(h, pts).sum() * (2 * R / n))


def test_the_march_converges_to_the_closed_form_through_the_centre(tmp_path):
    """L = E (1 - exp(-tau)) for a medium of constant colour that only emits and absorbs; the
    centre pixel's ray is the sphere's axis.  The midpoint rule's error is second order where
    the profile is smooth and first order at its kinks (where D0 reaches 0 and 1, bias and
    gain make them corners), so it is bounded by a constant times the step: 4e-4 relative at
    the scene's step (measured 1e-4), halving with it."""
    scene = _scene(tmp_path, density=0.4)
    h = scene.objects[0]
    tau = _optical_depth_through_centre(h)
    assert 0.3 < tau < 0.6  # neither transparent nor opaque: the step matters
    exact = np.array(h.emission) * (1 - np.exp(-tau))
    for scale in (1.0, 0.5, 0.25, 0.125):
        img = workbench.render(scene, "raycast", step_scale=scale).image
        err = float(np.abs(img[12, 16] - exact).max() / exact.max())
        assert err < 4e-4 * scale, (scale, err)


def check_delta_tracking(seed: int, tmp_path) -> None:
    """The path tracer (collision estimator of the emission: unbiased) against the march at a
    fine step (its own error < 1e-4 of the emission, the test above) on a turbulent medium
    that only emits and absorbs, both through the pixel centres.  The image means differ by
    less than the budget's band of standard errors of the path tracer's mean (pixels
    independent, normal approximation over 2475 values) plus 1e-3 of the mean for the march;
    the per-pixel RMS difference is within 1.3 times the path tracer's own noise estimate
    (its chi-square ratio over 2475 values exceeds 1.3^2 with a probability far below the
    mean check's).  Bonferroni over the two checks."""
    scene = _scene(tmp_path, noise="turbulence", density=1.5)
    march = workbench.render(scene, "raycast", step_scale=0.25).image.astype(np.float64)
    pt = workbench.render(scene, "pathtrace", spp=256, seed=seed, pixel_filter="center")
    img, se = pt.image.astype(np.float64), pt.std_error.astype(np.float64)
    assert np.isfinite(img).all() and march.max() > 0.3
    z = band("test_kernel_media::delta_tracking", 2)
    se_mean = float(np.sqrt((se ** 2).sum()) / se.size)
    assert abs(img.mean() - march.mean()) < z * se_mean + 1e-3 * march.mean(), (img.mean(), march.mean(), se_mean)
    rms = float(np.sqrt(((img - march) ** 2).mean()))
    assert rms < 1.3 * float(np.sqrt((se ** 2).mean())) + 1e-3 * march.max(), rms


def test_delta_tracking_agrees_with_the_march(tmp_path):
    check_delta_tracking(3, tmp_path)


def test_raycast_and_raytrace_march_alike_and_the_medium_shades_the_floor(tmp_path):
    """The bundled fire: the two Whitted methods march the same medium (no mirror or glass in
    the scene: the same image to rounding); the fire's shadow on the floor is dark in its
    middle and partial around it (feelers through thinner medium: what no opaque occluder
    gives under a point light), and the floor far from it is unchanged."""
    scene = load_scene(Path(__file__).parents[3] / "scenes" / "fire.toml")
    a = workbench.render(scene, "raycast", width=64, height=48).image
    b = workbench.render(scene, "raytrace", width=64, height=48).image
    assert np.abs(a - b).max() < 1e-6
    import dataclasses
    bare = dataclasses.replace(scene, objects=scene.objects[:1])
    c = workbench.render(bare, "raycast", width=64, height=48).image
    r = a[..., 1] / np.maximum(c[..., 1], 1e-9)
    shadow = r[32:40]
    assert shadow.min() < 0.1
    assert ((shadow > 0.2) & (shadow < 0.9)).sum() >= 5
    assert np.abs(r[42:] - 1).max() < 1e-5


def test_the_bundled_fire_renders_through_the_console_script(tmp_path):
    """``workbench render scenes/fire.toml`` with the path tracer, as a user runs it: exit 0,
    a finite image with the fire's glow in it."""
    out = tmp_path / "fire.png"
    r = subprocess.run([sys.executable, "-m", "workbench", "render", "fire", "-m", "pathtrace", "--size", "48x36",
                        "--set", "spp=4", "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "nonfinite_pixels: 0" in r.stdout
    from workbench.core.imageio import load_image_linear
    img = load_image_linear(out)
    assert img[10:26, 16:32, 0].max() > 0.5


@pytest.mark.parametrize("bad", ["step_scale=0", "step_scale=100"])
def test_a_step_scale_out_of_range_is_one_line(bad, tmp_path):
    r = subprocess.run([sys.executable, "-m", "workbench", "render", "fire", "-m", "raycast", "--size", "8x6",
                        "--set", bad, "--out", str(tmp_path / "x.png")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "step_scale" in r.stderr and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_the_march_error_estimate_is_the_half_step_difference(tmp_path):
    """``march_error``: the RMS difference from the same render at half the step, which is
    what two renders give, and which falls as the step does (the turbulent medium's error is
    dominated by the step: a factor 1.5 per halving at least, measured 2 to 4)."""
    scene = _scene(tmp_path, noise="turbulence", density=1.5)
    r = workbench.render(scene, "raytrace", march_error=True)
    a = workbench.render(scene, "raytrace").image.astype(np.float64)
    b = workbench.render(scene, "raytrace", step_scale=0.5).image.astype(np.float64)
    assert abs(r.stats["march_error_rmse"] - np.sqrt(((a - b) ** 2).mean())) < 1e-7
    fine = workbench.render(scene, "raytrace", step_scale=0.25, march_error=True).stats["march_error_rmse"]
    assert 0.0 < fine < r.stats["march_error_rmse"] / 1.5


FUR = """
[scene]
name = "fur"
background = [0.0, 0.0, 0.0]
ambient = [0.0, 0.0, 0.0]
[camera]
position = [0.0, 0.0, -3.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
resolution = [40, 30]
[[lights]]
type = "point"
position = [4.0, 0.0, 0.0]
color = [1.0, 1.0, 1.0]
intensity = 1.0
[materials.skin]
color = [0.0, 0.0, 0.0]
ka = 0.0
kd = 0.0
[[objects]]
type = "fur"
material = "skin"
base = "{base}"
size = {size}
length = 0.25
strands = 2000
thickness = 0.008
density = 200.0
color = [1.0, 1.0, 1.0]
kd = 1.0
ks = 0.0
step = 0.004
"""


@pytest.mark.parametrize("base,size", [("sphere", "0.6"), ("box", "[0.5, 0.4, 0.45]")])
def test_the_fur_texel_is_one_field_in_numpy_and_numba(base, size, tmp_path):
    """The strand density (0 or 1) of the numba texel equals the readable one at 20000 random
    points of the shell and around it, for both bases."""
    from workbench.renderers.raytrace.flatten import flatten
    from kernel_twins import Twins
    from workbench.scene.kinds import fur as F, fur_kernels
    K = Twins(fur_kernels)
    p = tmp_path / "fur.toml"
    p.write_text(FUR.format(base=base, size=size))
    scene = load_scene(p)
    f = scene.objects[0]
    sd = flatten(scene)
    row = int(np.flatnonzero(sd.ptype == F.PTYPE)[0])
    R = F.bound_radius(f)
    q = np.random.default_rng(5).uniform(-R, R, size=(20000, 3))
    a = F.density(f, q)
    b = np.array([K.texel(sd.par, row, *x)[0] for x in q])
    assert 0.02 < a.mean() < 0.5
    assert np.array_equal(a, b)


def test_the_fur_is_lit_by_its_lobe_and_shadowed_by_its_base(tmp_path):
    """A white furry ball (kd 1, no highlight, black skin, no ambient) under one light: with
    the light behind the camera, the fur facing it is lit; with the light behind the ball,
    the same fur is in the base's shadow (its feelers meet the sphere) while the rim, whose
    tips see the light past the limb, is lit; no pixel exceeds the diffuse lobe's bound
    ``albedo x intensity = 1`` (sin(T, L) <= 1, absorbed fraction <= 1)."""
    import dataclasses
    p = tmp_path / "fur.toml"
    p.write_text(FUR.format(base="sphere", size="0.6"))
    scene = load_scene(p)
    light = scene.lights[0]
    front = dataclasses.replace(scene, lights=(dataclasses.replace(light, position=(0.0, 0.0, -6.0)),))
    back = dataclasses.replace(scene, lights=(dataclasses.replace(light, position=(0.0, 0.0, 6.0)),))
    for m in ("raycast", "raytrace"):
        lit, dark = workbench.render(front, m).image, workbench.render(back, m).image
        assert np.isfinite(lit).all() and max(lit.max(), dark.max()) <= 1.0 + 1e-6
        centre = (slice(12, 18), slice(17, 23))
        assert lit[centre].mean() > 0.1, (m, lit[centre].mean())
        assert dark[centre].max() < 1e-6, (m, dark[centre].max())
        assert dark.max() > 0.1  # the rim


@pytest.mark.parametrize("method", ["raycast", "pathtrace"])
def test_a_grid_over_the_memory_limit_is_refused_before_it_is_built(method, tmp_path):
    """A hypertexture with a 256^3 grid (128 MiB of float64 numbers, counted three times while
    flattening) under a 300 MB limit: one line naming the estimate, exit 2, no image (the
    estimate counts the grid without building it: ``hypertexture.aux_count``)."""
    p = tmp_path / "big.toml"
    p.write_text(_scene_text("turbulence", 1.0) + "grid = 256\n")
    out = tmp_path / "x.png"
    r = subprocess.run([sys.executable, "-m", "workbench", "render", str(p), "-m", method, "--size", "8x6",
                        "--max-memory", "300M", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "memory" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not out.exists()
