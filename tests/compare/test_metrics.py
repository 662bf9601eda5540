"""Metrics: RMSE/PSNR definitions, FLIP ordering, bad input."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.core.errors import WorkbenchError


def test_rmse_psnr_of_a_known_offset():
    ref = np.full((8, 8, 3), 0.5, dtype=np.float32)
    m = workbench.compare.metrics(ref + 0.1, ref)
    assert m["rmse"] == pytest.approx(0.1, rel=1e-6)
    assert m["psnr"] == pytest.approx(20.0, rel=1e-5)
    assert workbench.compare.metrics(ref, ref) == {"rmse": 0.0, "psnr": float("inf"), "flip": 0.0, "rmse_hdr": 0.0}


def test_rmse_is_taken_in_the_display_range():
    ref = np.full((10, 10, 3), 0.5, dtype=np.float32)
    ref[0, 0] = 20.0                      # an emitter pixel
    img = ref.copy()
    img[0, 0] = 5.0                       # another method's emitter edge: both show white
    m = workbench.compare.metrics(img, ref)
    assert m["rmse"] == 0.0 and m["rmse_hdr"] == pytest.approx(15.0 / 10.0)


def test_flip_grows_with_the_error():
    rng = np.random.default_rng(3)
    ref = rng.random((32, 32, 3)).astype(np.float32)
    small = workbench.compare.metrics(np.clip(ref + 0.02, 0, 1), ref)["flip"]
    large = workbench.compare.metrics(np.clip(ref + 0.2, 0, 1), ref)["flip"]
    assert 0 < small < large <= 1


def test_bad_pairs_are_refused():
    a = np.zeros((4, 4, 3))
    with pytest.raises(WorkbenchError, match="same size"):
        workbench.compare.metrics(a, np.zeros((4, 5, 3)))
    b = a.copy()
    b[0, 0, 0] = np.nan
    with pytest.raises(WorkbenchError, match="finite"):
        workbench.compare.metrics(b, a)


def test_metrics_and_maps_agree_with_the_separate_calls():
    from workbench.compare.metrics import error_map, metrics_and_maps
    rng = np.random.default_rng(7)
    ref = rng.random((24, 20, 3)).astype(np.float32)
    img = np.clip(ref + rng.normal(0.0, 0.08, ref.shape), -0.2, 1.3).astype(np.float32)
    values, maps = metrics_and_maps(img, ref)
    assert values == workbench.compare.metrics(img, ref)
    for kind in ("flip", "abs"):
        np.testing.assert_allclose(maps[kind], error_map(img, ref, kind), rtol=0, atol=1e-12)
    assert values["flip"] == pytest.approx(float(maps["flip"].mean()), rel=1e-4)
