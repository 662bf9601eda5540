"""The registered false-failure probabilities (tests/statistics_budget.py) add up to at most the
suite's budget, and the bands derived from them are what a normal distribution gives."""
from __future__ import annotations

import math

from statistics_budget import ALPHA, SUITE_BUDGET, band


def test_the_suite_total_is_within_budget():
    assert sum(ALPHA.values()) <= SUITE_BUDGET
    assert all(0.0 < a < SUITE_BUDGET for a in ALPHA.values())


def test_band_is_the_two_sided_normal_quantile():
    for test in ALPHA:
        for checks in (1, 4):
            z = band(test, checks)
            tail = math.erfc(z / math.sqrt(2.0))  # P(|Z| > z)
            assert abs(tail * checks - ALPHA[test]) <= 1e-9 * ALPHA[test] + 1e-15


def test_band_with_estimated_errors_is_students_t():
    """With the standard error estimated from dof + 1 samples the band is Student's t quantile:
    wider than the normal one, and its tail is the test's share."""
    from scipy.stats import t
    test = "test_pathtrace::furnace"
    for dof in (7, 63, 4095):
        z = band(test, 100, dof=dof)
        assert z > band(test, 100)
        assert abs(2.0 * t.sf(z, dof) * 100 - ALPHA[test]) <= 1e-9 * ALPHA[test]
