"""Colour-space conversions: round trips, agreement with colour-science, edge cases."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.core import color as C
from workbench.core.errors import WorkbenchError

colour = pytest.importorskip("colour")
RNG = np.random.default_rng(20261121)
IN_GAMUT = RNG.uniform(0.0, 1.0, (20000, 3))
OUT_OF_GAMUT = RNG.uniform(-0.5, 1.5, (20000, 3))
EDGES = np.array([[0, 0, 0], [1, 1, 1], [0.5, 0.5, 0.5], [1e-9, 1e-9, 1e-9], [1, 0, 0], [0, 1, 0],
                  [0, 0, 1], [1, 1, 0], [0, 1, 1], [1, 0, 1], [1, 0.5, 0], [0.2, 0.2, 0.6],
                  [-0.1, 0.5, 1.2], [1.5, 1.5, 1.5], [-0.2, -0.2, -0.2], [-0.3, 0.0, -0.1]],
                 dtype=float)


def _hue_dist(a, b):
    d = np.abs(a - b) % 360.0
    return np.minimum(d, 360.0 - d)


@pytest.mark.parametrize("fwd, inv", [(C.rgb_to_xyz, C.xyz_to_rgb), (C.rgb_to_cmy, C.cmy_to_rgb),
                                      (C.rgb_to_cmyk, C.cmyk_to_rgb), (C.rgb_to_hsv, C.hsv_to_rgb),
                                      (C.rgb_to_hsl, C.hsl_to_rgb), (C.rgb_to_hsi, C.hsi_to_rgb)])
def test_round_trips_in_gamut(fwd, inv):
    x = np.concatenate([IN_GAMUT, EDGES[:12]]).reshape(-1, 2, 3)   # image-like leading shape
    np.testing.assert_allclose(inv(fwd(x)), x, atol=1e-6)


def test_round_trips_out_of_gamut_where_defined():
    x = OUT_OF_GAMUT
    np.testing.assert_allclose(C.xyz_to_rgb(C.rgb_to_xyz(x)), x, atol=1e-12)
    np.testing.assert_allclose(C.hsv_to_rgb(C.rgb_to_hsv(x)), x, atol=1e-9)
    np.testing.assert_allclose(C.hsl_to_rgb(C.rgb_to_hsl(x)), x, atol=1e-9)
    keep = x.max(axis=-1) > 0        # CMYK caps K at 1: all-negative triples become black
    np.testing.assert_allclose(C.cmyk_to_rgb(C.rgb_to_cmyk(x))[keep], x[keep], atol=1e-9)
    np.testing.assert_allclose(C.cmyk_to_rgb(C.rgb_to_cmyk(x[~keep])), 0.0, atol=0)


@pytest.mark.parametrize("x", [IN_GAMUT, OUT_OF_GAMUT, EDGES], ids=["in", "out", "edges"])
def test_agrees_with_colour_science(x):
    np.testing.assert_allclose(C.rgb_to_xyz(x), colour.RGB_to_XYZ(x, "sRGB"), atol=1e-12)
    # colour-science's XYZ -> sRGB is the standard's 4-decimal printed inverse; ours is exact
    np.testing.assert_allclose(C.xyz_to_rgb(C.rgb_to_xyz(x)),
                               colour.XYZ_to_RGB(C.rgb_to_xyz(x), "sRGB"), atol=5e-4)
    np.testing.assert_allclose(C.rgb_to_cmy(x), colour.RGB_to_CMY(x), atol=1e-15)
    with np.errstate(divide="ignore", invalid="ignore"):
        ref_cmyk = colour.CMY_to_CMYK(colour.RGB_to_CMY(x))
    ok = np.all(np.isfinite(ref_cmyk), axis=-1)
    np.testing.assert_allclose(C.rgb_to_cmyk(x)[ok], ref_cmyk[ok], atol=1e-9)
    for ours, theirs in ((C.rgb_to_hsv, colour.RGB_to_HSV), (C.rgb_to_hsl, colour.RGB_to_HSL)):
        a, b = ours(x), theirs(x)
        assert _hue_dist(a[..., 0], 360.0 * b[..., 0]).max() < 1e-9
        np.testing.assert_allclose(a[..., 1:], b[..., 1:], atol=1e-6)
    y = np.abs(x) % 1.0
    np.testing.assert_allclose(C.hsv_to_rgb(y * [360, 1, 1]), colour.HSV_to_RGB(y), atol=1e-12)
    np.testing.assert_allclose(C.hsl_to_rgb(y * [360, 1, 1]), colour.HSL_to_RGB(y), atol=1e-12)


def test_edge_case_conventions():
    black, white, grey = np.zeros(3), np.ones(3), np.full(3, 0.3)
    np.testing.assert_array_equal(C.rgb_to_hsv(black), [0, 0, 0])
    np.testing.assert_array_equal(C.rgb_to_hsl(white), [0, 0, 1])
    np.testing.assert_array_equal(C.rgb_to_hsv(grey), [0, 0, 0.3])   # undefined hue -> 0
    np.testing.assert_array_equal(C.rgb_to_hsi(black), [0, 0, 0])
    np.testing.assert_allclose(C.rgb_to_hsi(grey), [0, 0, 0.3], atol=1e-15)
    np.testing.assert_array_equal(C.rgb_to_cmyk(black), [0, 0, 0, 1])
    np.testing.assert_array_equal(C.rgb_to_cmyk(white), [0, 0, 0, 0])
    np.testing.assert_allclose(C.rgb_to_xyz(white), [0.9505, 1.0, 1.089], atol=1e-12)
    hue = C.rgb_to_hsv(np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1], [1, 0, 1]]))
    np.testing.assert_allclose(hue[:, 0], [0, 60, 120, 180, 240, 300], atol=1e-12)
    # hue stays in [0, 360) even when rounding would give exactly 360
    h = C.rgb_to_hsv(np.array([1.0, 0.0, 1e-17]))[0]
    assert 0.0 <= h < 360.0
    assert C.luminance(white) == pytest.approx(1.0, abs=1e-15)


def test_bad_shapes_are_workbench_errors():
    with pytest.raises(WorkbenchError, match="3 components"):
        C.rgb_to_hsv(np.zeros((4, 4)))
    with pytest.raises(WorkbenchError, match="4 components"):
        C.cmyk_to_rgb(np.zeros(3))
