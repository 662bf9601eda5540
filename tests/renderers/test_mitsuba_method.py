"""The ``mitsuba`` method end to end (Mitsuba 3 is installed by the README's commands: these
tests fail, not skip, when it is missing)."""
from __future__ import annotations

import importlib.util

import numpy as np
import pytest

import workbench
from child_processes import children
from statistics_budget import band
from workbench.core.errors import WorkbenchError
from workbench.renderers import mitsuba_method as mm
from workbench.renderers.base import get_renderer
from workbench.scene import model as m


def test_mitsuba_is_installed():
    assert importlib.util.find_spec("mitsuba") is not None, mm.INSTALL_HINT


def _spot_scene(width=48, height=40) -> m.Scene:
    """A small emissive sphere off-centre (upper left of the image), nothing else."""
    cam = m.Camera(position=(0.3, 0.2, 6.0), look_at=(0.0, 0.0, 0.0), fov_y=35.0, width=width, height=height)
    mats = {"glow": m.Material("glow", color=(0.0, 0.0, 0.0), kd=0.0, ka=0.0, emission=(5.0, 5.0, 5.0))}
    return m.Scene("spot", cam, mats, (m.Sphere("glow", center=(-0.8, 0.6, 0.4), radius=0.12),),
                   ambient=(0.0, 0.0, 0.0))


def _centroid(img: np.ndarray) -> np.ndarray:
    w = img.sum(-1).astype(np.float64)
    ii, jj = np.indices(w.shape)
    return np.array([(w * jj).sum(), (w * ii).sum()]) / w.sum() + 0.5  # (x, y), pixel centres at +0.5


def test_camera_convention_a_bright_sphere_lands_where_the_ray_caster_puts_it():
    s = _spot_scene()
    mit = workbench.render(s, "mitsuba", spp=16)
    ray = workbench.render(s, "raycast", spp=16)
    c_mit, c_ray = _centroid(mit.image), _centroid(ray.image)
    c_proj = s.camera.project(np.array([[-0.8, 0.6, 0.4]]))[0][0]
    assert c_proj[0] < 24 and c_proj[1] < 20  # upper left: a mirrored image would be far off
    assert np.abs(c_mit - c_ray).max() < 0.25, (c_mit, c_ray)
    assert np.abs(c_mit - c_proj).max() < 0.5, (c_mit, c_proj)


def _light_pixels(scene: m.Scene, width: int, height: int) -> np.ndarray:
    """(H, W) bool: pixels the area light's projected bounding box touches (grown by one pixel)."""
    xy, _ = scene.camera.with_resolution(width, height).project(np.asarray(scene.lights[0].vertices))
    lo, hi = np.floor(xy.min(0)).astype(int) - 1, np.ceil(xy.max(0)).astype(int) + 1
    mask = np.zeros((height, width), bool)
    mask[max(lo[1], 0):hi[1], max(lo[0], 0):hi[0]] = True
    return mask


def test_cornell_mean_radiance_agrees_with_radiosity_and_reports_its_noise(tmp_path):
    check_cornell_mean(0, tmp_path)


#: radiosity's discretisation at 48x48 (about 1 %) and the box filter's blur near the light
BIAS_ALLOWANCE = 0.02


def check_cornell_mean(seed: int, tmp_path) -> None:
    """Off the light's own pixels (where a box-filtered and a pixel-centre image differ most),
    the mean radiance of Mitsuba's path tracing (one pinned variant, seeded) and of the
    workbench's radiosity agree within :data:`BIAS_ALLOWANCE` plus the normal band of the
    mean's standard error (from Mitsuba's per-pixel estimate, 2,300 pixels at 256 spp)."""
    s = workbench.load_scene("cornell")
    mit = workbench.render(s, "mitsuba", width=48, height=48, spp=256, seed=seed, variant=mm.FALLBACK_VARIANT)
    rad = workbench.render(s, "radiosity", width=48, height=48)
    keep = ~_light_pixels(s, 48, 48)
    a, b = mit.image[keep].mean(0), rad.image[keep].mean(0)
    assert np.isfinite(mit.image).all() and mit.stats["nonfinite_pixels"] == 0
    assert mit.stats["variant"] == mm.FALLBACK_VARIANT and mit.stats["variant_reason"]
    err = mit.stats["stderr"]
    assert err.shape == mit.image.shape and np.isfinite(err).all()
    se = np.sqrt((err[keep].astype(np.float64) ** 2).sum(0)) / keep.sum()
    # the noise is small beside the bias allowance: the check is about the means, not the noise
    z = band("test_mitsuba_method::cornell_mean", 3)
    assert np.all(z * se < 0.01 * a), (z * se / a)
    assert np.all(np.abs(a - b) <= BIAS_ALLOWANCE * b + z * se), (a, b, se)
    assert mit.left_out == [] and "area_lights" in mit.features_used


def test_mirror_glass_csg_quadrics_and_opacity_render_finite():
    """Every BSDF combination (nested blends, dielectric, thin dielectric, mask) and every shape
    kind the exporter writes loads in Mitsuba and gives a finite image."""
    for name in ("cornell_spheres", "csg", "quadrics", "envmap"):
        r = workbench.render(workbench.load_scene(name), "mitsuba", width=16, height=12, spp=4, tessellation=4)
        assert np.isfinite(r.image).all() and r.stats["nonfinite_pixels"] == 0, name
        assert r.image.max() > 0.0, name


def test_memory_estimate_covers_the_child_process():
    s = workbench.load_scene("cornell")
    r = workbench.render(s, "mitsuba", width=40, height=40, spp=4)
    est = get_renderer("mitsuba").estimate_bytes(s, 40, 40, spp=4)
    assert 0 < r.stats["child_peak_rss_bytes"] <= est
    assert get_renderer("mitsuba").estimate_bytes(s, 4000, 4000) > est + 4000 * 4000 * 4 * 3


def test_bad_options_and_missing_mitsuba_give_one_clear_line(monkeypatch):
    s = workbench.load_scene("cornell")
    with pytest.raises(WorkbenchError, match="spp must be within 2"):
        workbench.render(s, "mitsuba", width=8, height=8, spp=1)
    with pytest.raises(WorkbenchError, match="variant"):
        workbench.render(s, "mitsuba", width=8, height=8, variant="cuda_ad_rgb")
    monkeypatch.setattr(mm, "mitsuba_installed", lambda: False)
    with pytest.raises(WorkbenchError, match="Mitsuba 3 is not installed") as e:
        workbench.render(s, "mitsuba", width=8, height=8)
    assert "\n" not in str(e.value)


def test_variant_probe_survives_a_failing_variant_and_falls_back():
    ok, why = mm.probe_variant("no_such_variant")
    assert not ok and "exit status" in why
    r = mm.MitsubaRenderer()
    r._variant_checks[mm.FAST_VARIANT] = (False, "exit status -6 (aborted)")
    variant, why = r.choose_variant("auto")
    assert variant == mm.FALLBACK_VARIANT and "aborted" in why
    assert r.choose_variant("llvm_ad_rgb") == ("llvm_ad_rgb", "requested")


def test_two_pass_standard_error_is_unbiased():
    """Pass means of n1 and n2 iid samples of variance sigma^2: the estimate's mean square is
    sigma^2 / (n1 + n2), the variance of the combined mean (checked over 200,000 pixels, whose
    relative sampling error is about 0.3 %)."""
    rng = np.random.default_rng(7)
    sigma, n1, n2 = 0.3, 5, 11
    a = rng.normal(1.0, sigma / np.sqrt(n1), size=(200, 1000, 3))
    b = rng.normal(1.0, sigma / np.sqrt(n2), size=(200, 1000, 3))
    image, err = mm.combine_passes(np.stack([a, b]), [n1, n2])
    assert np.allclose(image, (n1 * a + n2 * b) / (n1 + n2), atol=1e-6)
    ratio = np.mean(err.astype(np.float64) ** 2) / (sigma ** 2 / (n1 + n2))
    assert abs(ratio - 1.0) < 0.02
    a[0, 0, 0], b[0, 1, 2] = np.nan, np.inf
    _, err = mm.combine_passes(np.stack([a, b]), [n1, n2])
    assert np.isfinite(err).all() and err[0, 0, 0] == 0.0 and err[0, 1, 2] == 0.0


def test_mitsuba_is_registered_but_not_in_the_default_method_lists():
    from workbench.renderers.base import available, default_methods
    assert "mitsuba" in available() and "mitsuba" not in default_methods()
    assert set(default_methods()) == set(available()) - {"mitsuba"}


def test_cli_and_reports_summarise_the_noise_image_instead_of_dumping_it(tmp_path):
    """Before: ``workbench render -m mitsuba`` printed the whole (H, W, 3) stderr array and a
    comparison report would have written it as a nested list into report.json."""
    import json
    import subprocess
    import sys
    from workbench.renderers.base import stats_for_display
    r = subprocess.run([sys.executable, "-m", "workbench.app.cli", "render", "cornell", "-m", "mitsuba",
                        "--set", "spp=4", "--size", "24x20", "-o", str(tmp_path / "a.png"),
                        "--json", str(tmp_path / "a.json")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    line = [ln for ln in r.stdout.splitlines() if ln.strip().startswith("stderr:")]
    assert len(line) == 1 and "array (20, 24, 3) float32, RMS" in line[0]
    assert json.loads((tmp_path / "a.json").read_text())["stats"]["stderr"].startswith("array (20, 24, 3)")
    shown = stats_for_display({"stderr": np.full((2, 2, 3), 3.0, np.float32), "spp": 4})
    assert shown == {"stderr": "array (2, 2, 3) float32, RMS 3", "spp": 4}


class Stop(Exception):
    """Raised by a progress callback: the render must end with it, and the child with it."""


@pytest.mark.parametrize("variant", ["scalar_rgb", "auto"])
def test_progress_counts_the_childs_samples_and_a_stop_ends_the_child(variant):
    """The window's progress bar of the mitsuba method (issue #29): the child's start-up
    reports no amount done, then the samples per pixel done (the scalar variant block by
    block, the LLVM one pass by pass); a cancelled job's next report raises, which must end
    the child process (before: it ran on unseen)."""
    scene = _spot_scene(16, 12)
    steps = []
    res = workbench.render(scene, "mitsuba", spp=8, variant=variant, on_progress=lambda *a: steps.append(a))
    assert steps[0] == ("Mitsuba choosing its variant", 0, None, "")
    assert all(total is None and done == 0 for phase, done, total, unit in steps if phase != "Mitsuba")
    counted = [done for phase, done, total, unit in steps if phase == "Mitsuba"]
    assert counted == sorted(counted) and steps[-1] == ("Mitsuba", 8, 8, "spp")
    assert np.array_equal(res.image, workbench.render(scene, "mitsuba", spp=8, variant=variant).image)
    before = children()

    def stop(phase, *_):  # the first report read from the running child
        if phase in ("Mitsuba loading the scene", "Mitsuba"):
            raise Stop
    with pytest.raises(Stop):
        workbench.render(scene, "mitsuba", spp=8, variant=variant, on_progress=stop)
    assert children() <= before
