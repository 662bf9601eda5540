"""Ground truth: the ``pathtrace`` method against Mitsuba 3 (the ``mitsuba`` method) on the
Cornell box and the Cornell box with a mirror and a glass sphere.

One image definition on both sides: a pixel is the box-filtered average of the radiance over
its square (pathtrace: uniform jitter; Mitsuba: ``box`` reconstruction filter), linear RGB,
not clipped.  Both describe the same scene: no Phong lobe (ks = 0 in both scenes, checked: a
scene with ks > 0 would have to be compared on a copy with ks = 0, Mitsuba has no normalised
Phong lobe), no ambient term (ka = 0 and a black ambient), the glass with the exact Fresnel split
(pathtrace ``fresnel = "exact"`` = Mitsuba's ``dielectric``), the area light emitting from
its front face and black (a black BSDF in the export, an opaque black surface in the path
tracer); each side's ``left_out`` is checked to hold nothing else.

Statistics (:mod:`workbench.compare.agreement`): the pixel ratio
``R = sum (a - b)^2 / sum (se_a^2 + se_b^2)`` within ``z sd_R`` of 1 (``sd_R`` from its
sampling distribution), the block chi-square within ``z sqrt(2 / K)`` of 1, the mean radiance
within ``max(1 %, z se)`` (off the light's own pixels, and all pixels), and the fraction of
pixels with ``|z| > 3`` below the worst case ``P(|t_1| > 3) = 0.205`` of a one-dof noise
estimate.  ``z`` comes from the test's false-failure probability in tests/statistics_budget.py
(Bonferroni over the four normal checks: ``z`` = 4.57 for 1e-5).  The test must be able to see
a bias: ``z se`` of the mean off the light at most :data:`POWER_TOL`.

Both sides are seeded and Mitsuba runs one pinned variant (:data:`VARIANT`): the outcome is the
same on every machine, whichever variants it can load (with ``auto`` a machine that loads
``llvm_ad_rgb`` drew other samples, and cornell_spheres failed the power check on one).
"""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.compare import agreement as ag
from workbench.renderers.mitsuba_export import export_scene
from statistics_budget import band
from workbench.renderers.mitsuba_method import mitsuba_installed

pytestmark = pytest.mark.skipif(not mitsuba_installed(), reason="Mitsuba 3 not installed (extra 'reference')")

MEAN_TOL = 0.01
#: The mean's band (z standard errors) must be at most this: the test sees a 2 % bias.
POWER_TOL = 0.02
#: The Mitsuba variant of the reference: the one every machine loads.
VARIANT = "scalar_rgb"
#: What each side may leave out on these scenes, and nothing else (prefixes).
#: Normal-approximation checks per comparison (ratio, block chi-square, two means).
CHECKS = 4
ALLOWED_LEFT_OUT = {"pathtrace": ("ambient: off",),
                    "mitsuba": ("refraction: exact Fresnel split only",)}


def compare_scene(name: str, size: int, spp: int, block: int = 4, z: float = 4.0,
                  seed: int = 0) -> dict:
    scene = workbench.load_scene(name)
    # no Phong lobe (Mitsuba has no normalised Phong BSDF): a scene with ks > 0 would be
    # compared on a copy with ks = 0; the Cornell scenes have none
    assert all(mt.ks == 0.0 for mt in scene.materials.values())
    pt = workbench.render(scene, "pathtrace", width=size, height=size, spp=spp, seed=2 * seed + 1,
                          fresnel="exact")
    mi = workbench.render(scene, "mitsuba", width=size, height=size, spp=spp, seed=2 * seed,
                          variant=VARIANT)
    assert mi.stats["variant"] == VARIANT, mi.stats["variant_reason"]
    for method, res in (("pathtrace", pt), ("mitsuba", mi)):
        extra = [x for x in res.left_out if not str(x).startswith(ALLOWED_LEFT_OUT[method])]
        assert not extra, f"{method} leaves out part of {name}: {extra}"
    st = ag.noise_agreement(pt.image, pt.std_error, spp - 1, mi.image, mi.stats["stderr"], 1,
                            block=block, exclude=ag.light_pixels(scene, size, size), band_sd=z)
    st["z"] = z
    return st


def agreement_failures(st: dict) -> list[str]:
    """The checks of the module docstring that fail (empty: the images agree)."""
    z, off, whole = st["z"], st["mean_off"], st["mean"]
    checks = {"ratio": st["ratio_ok"], "block chi-square": st["block_chi2_ok"],
              "|z| > 3 fraction": st["frac_abs_z_gt_3"] < ag.P_Z3_T1,
              "mean off the light": abs(off["rel_diff"]) <= max(MEAN_TOL, z * off["rel_diff_se"]),
              "mean": abs(whole["rel_diff"]) <= max(MEAN_TOL, z * whole["rel_diff_se"])}
    return [k for k, ok in checks.items() if not ok]


def check_agreement(st: dict) -> None:
    assert not agreement_failures(st), (agreement_failures(st), st)
    off = st["mean_off"]
    assert st["z"] * off["rel_diff_se"] <= POWER_TOL, off  # the test can see a 2 % bias


def test_export_gives_the_area_light_a_black_bsdf_and_both_sides_the_same_glass(tmp_path):
    scene = workbench.load_scene("cornell_spheres")
    ex = export_scene(scene, str(tmp_path), tessellation=4)
    emitters = [s for s in ex.scene_dict.values() if isinstance(s, dict) and "emitter" in s]
    assert len(emitters) == 1
    light = emitters[0]
    assert light["bsdf"]["type"] == "diffuse" and max(light["bsdf"]["reflectance"]["value"]) == 0.0
    assert np.allclose(light["emitter"]["radiance"]["value"], scene.lights[0].radiance)
    glass = [s for s in ex.scene_dict.values() if isinstance(s, dict) and s.get("type") == "sphere"
             and "blendbsdf" in str(s["bsdf"])]
    assert len(glass) == 1 and "'dielectric'" in str(glass[0]["bsdf"])


def check_cornell(seed: int, tmp_path=None, size: int = 48, spp: int = 256) -> None:
    check_agreement(compare_scene("cornell", size, spp, z=band("test_ground_truth::cornell", CHECKS), seed=seed))


def check_cornell_spheres(seed: int, tmp_path=None, size: int = 40, spp: int = 2048) -> None:
    check_agreement(compare_scene("cornell_spheres", size, spp, z=band("test_ground_truth::cornell_spheres", CHECKS),
                                  seed=seed))


def test_pathtrace_agrees_with_mitsuba_on_cornell():
    check_cornell(0)


def test_pathtrace_agrees_with_mitsuba_on_cornell_spheres_exact_fresnel():
    check_cornell_spheres(0)


@pytest.mark.slow
@pytest.mark.parametrize("name,spp", [("cornell", 1024), ("cornell_spheres", 4096)])
def test_pathtrace_agrees_with_mitsuba_at_64x64(name, spp):
    st = compare_scene(name, 64, spp, z=band(f"test_ground_truth::{name}@64 (slow)", CHECKS))
    print(name, spp, {k: v for k, v in st.items() if not isinstance(v, dict)}, st["mean"], st["mean_off"])
    check_agreement(st)


def test_the_statistics_see_a_two_percent_bias():
    """The same noisy images, one scaled by 1.02: the block chi-square and the mean leave their
    bands (the statistics can fail), while the unscaled pair stays inside."""
    rng = np.random.default_rng(3)
    truth = rng.uniform(0.2, 1.0, (48, 48, 3))
    se = np.full(truth.shape, 0.004)
    a = truth + rng.normal(0.0, 1.0, truth.shape) * se
    b = truth + rng.normal(0.0, 1.0, truth.shape) * se
    good = ag.noise_agreement(a, se, 1000, b, se, 1000)
    assert good["ratio_ok"] and good["block_chi2_ok"] and abs(good["mean"]["rel_diff"]) < MEAN_TOL
    bad = ag.noise_agreement(a * 1.02, se, 1000, b, se, 1000)
    assert not bad["ratio_ok"] and not bad["block_chi2_ok"] and abs(bad["mean"]["rel_diff"]) > MEAN_TOL


def test_agreement_rejects_bad_input():
    z = np.zeros((4, 4, 3))
    with pytest.raises(workbench.WorkbenchError, match="shape"):
        ag.noise_agreement(z, z, 1, np.zeros((4, 5, 3)), z, 1)
    with pytest.raises(workbench.WorkbenchError, match="non-finite"):
        ag.noise_agreement(z, z, 1, z + np.nan, z, 1)
    with pytest.raises(workbench.WorkbenchError, match="degrees of freedom"):
        ag.noise_agreement(z, z, 0, z, z, 1)
