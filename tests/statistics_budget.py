"""The suite's false-failure budget for statistical comparisons (Bonferroni).

A test that compares noisy estimates registers here the probability ``alpha`` that it fails
although the two estimates agree in expectation (over the random seeds; with fixed seeds a
given build passes or fails every time, and :func:`band` turns ``alpha`` into the acceptance
band its checks use).  By Bonferroni, the probability that any registered test fails falsely is
at most the sum of the registered ``alpha``, which ``tests/project/test_statistics_budget.py`` keeps at
or below :data:`SUITE_BUDGET` (slow tests included: they run on some machine too).

Each comparison is also a function of its seed (:data:`SEEDED`), so that
``tests/project/test_statistics_seeds.py`` (slow) can rerun it with 20 seeds and count its failures.
"""
from __future__ import annotations

from scipy.stats import norm, t

SUITE_BUDGET = 1e-4

ALPHA = {
    # test_ground_truth.py: four normal-approximation checks each (pixel ratio, block
    # chi-square, mean off the light, mean of all pixels)
    "test_ground_truth::cornell": 1e-5,
    "test_ground_truth::cornell_spheres": 1e-5,
    "test_ground_truth::cornell@64 (slow)": 1e-5,
    "test_ground_truth::cornell_spheres@64 (slow)": 1e-5,
    # test_ground_truth_media.py: the same four checks on the hypertexture twin
    "test_ground_truth_media::hypertexture_twin (slow)": 5e-6,
    # test_radiosity_formfactors.py: the ray-cast form factor of two parallel squares (one
    # binomial estimate, normal approximation)
    "test_radiosity_formfactors::raycast": 1e-5,
    # test_pathtrace.py: per-pixel checks against a known value or a noiseless method (Student
    # t with spp - 1 degrees of freedom per pixel, Bonferroni over the pixels)
    "test_pathtrace::furnace": 2e-6,
    "test_pathtrace::white_furnace": 2e-6,
    "test_pathtrace::point_light": 2e-6,
    "test_pathtrace::noise_estimate": 1e-6,
    "test_pathtrace::kernel_reference": 2e-6,
    "test_pathtrace::area_light_triangles": 2e-6,
    "test_pathtrace::grazing_area_light": 2e-6,
    # test_pathtrace_modes.py
    "test_pathtrace_modes::diffuse_mode": 1e-6,
    "test_pathtrace_modes::kernel_reference": 2e-6,
    "test_pathtrace_modes::back_face": 2e-6,
    "test_pathtrace_modes::radiosity_cornell (slow)": 2e-6,
    # test_mitsuba_method.py: the mean of Mitsuba's cornell against radiosity's
    "test_mitsuba_method::cornell_mean": 2e-6,
    # test_mitsuba_media.py: Mitsuba's transmittance through a soft sphere against a quadrature
    # (exact Bernoulli variance; block chi-square and mean, normal approximation)
    "test_mitsuba_media::transmittance": 1e-6,
    # test_kernel_media.py: the path tracer's delta tracking against the march (image mean,
    # normal approximation; RMS against the noise estimate)
    "test_kernel_media::delta_tracking": 1e-6,
    # tests/project/test_statistics_seeds.py: two or more failures of one comparison over 20 seeds
    # (binomial: at most C(20, 2) alpha^2 per comparison, summed over the comparisons)
    "test_statistics_seeds::twenty_seeds (slow)": 1e-7,
}
"""Test -> its false-failure probability."""

SEEDED = {
    "test_ground_truth::cornell": "test_ground_truth:check_cornell",
    "test_ground_truth::cornell_spheres": "test_ground_truth:check_cornell_spheres",
    "test_ground_truth_media::hypertexture_twin (slow)": "test_ground_truth_media:check_twin",
    "test_radiosity_formfactors::raycast": "test_radiosity_formfactors:check_raycast",
    "test_pathtrace::furnace": "test_pathtrace:check_furnace",
    "test_pathtrace::white_furnace": "test_pathtrace:check_white_furnace",
    "test_pathtrace::point_light": "test_pathtrace:check_point_light",
    "test_pathtrace::noise_estimate": "test_pathtrace:check_noise_estimate",
    "test_pathtrace::kernel_reference": "test_pathtrace:check_kernel_reference",
    "test_pathtrace::area_light_triangles": "test_pathtrace:check_area_light_triangles",
    "test_pathtrace::grazing_area_light": "test_pathtrace:check_grazing_area_light",
    "test_pathtrace_modes::diffuse_mode": "test_pathtrace_modes:check_diffuse_mode",
    "test_pathtrace_modes::kernel_reference": "test_pathtrace_modes:check_kernel_reference",
    "test_pathtrace_modes::back_face": "test_pathtrace_modes:check_back_face",
    "test_mitsuba_method::cornell_mean": "test_mitsuba_method:check_cornell_mean",
    "test_mitsuba_media::transmittance": "test_mitsuba_media:check_transmittance",
    "test_kernel_media::delta_tracking": "test_kernel_media:check_delta_tracking",
}
"""Test -> ``module:function`` taking ``(seed, tmp_path)`` that raises AssertionError when the
comparison fails: the test itself calls it with a fixed seed.  The slow ground-truth variants
at 64x64 are the same comparison as their small ones (more samples), the slow radiosity check
holds a 1 % bias allowance beside its noise band, and the 20-seed test is itself the rate
check: they have no entry."""


def band(test: str, checks: int = 1, dof: float | None = None) -> float:
    """The two-sided band in standard errors that gives each of ``checks`` checks of ``test``
    an equal share of its ``alpha`` (Bonferroni within the test): the normal quantile, or
    Student's t with ``dof`` degrees of freedom when each standard error is estimated from
    ``dof + 1`` samples (two estimates combined: the smaller ``dof``, which widens the band)."""
    p = ALPHA[test] / (2.0 * checks)
    return float(norm.isf(p) if dof is None else t.isf(p, dof))
