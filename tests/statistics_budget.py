"""The suite's false-failure budget for statistical comparisons (Bonferroni).

A test that compares noisy estimates registers here the probability ``alpha`` that it fails
although the two estimates agree in expectation (over the random seeds; with fixed seeds a
given build passes or fails every time, and :func:`band` turns ``alpha`` into the acceptance
band its checks use).  By Bonferroni, the probability that any registered test fails falsely is
at most the sum of the registered ``alpha``, which ``tests/test_statistics_budget.py`` keeps at
or below :data:`SUITE_BUDGET` (slow tests included: they run on some machine too).
"""
from __future__ import annotations

from scipy.stats import norm

SUITE_BUDGET = 1e-4

ALPHA = {
    # test_ground_truth.py: four normal-approximation checks each (pixel ratio, block
    # chi-square, mean off the light, mean of all pixels)
    "test_ground_truth::cornell": 1e-5,
    "test_ground_truth::cornell_spheres": 1e-5,
    "test_ground_truth::cornell@64 (slow)": 1e-5,
    "test_ground_truth::cornell_spheres@64 (slow)": 1e-5,
    # test_radiosity_formfactors.py: the ray-cast form factor of two parallel squares (one
    # binomial estimate, normal approximation)
    "test_radiosity_formfactors::raycast": 1e-5,
}
"""Test -> its false-failure probability."""


def band(test: str, checks: int = 1) -> float:
    """The two-sided band in standard deviations that gives each of ``checks`` normal checks of
    ``test`` an equal share of its ``alpha`` (Bonferroni within the test)."""
    return float(norm.isf(ALPHA[test] / (2.0 * checks)))
