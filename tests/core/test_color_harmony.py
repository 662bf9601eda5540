"""Colour wheel and harmonies: hue spacing, colours, and what the wheel image shows."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.core import harmony as Hm
from workbench.core.color import rgb_to_hsv
from workbench.core.errors import WorkbenchError
from workbench.core.imageio import srgb_encode


def _circ(a, b):
    d = np.abs(np.asarray(a) - b) % 360.0
    return np.minimum(d, 360.0 - d)


@pytest.mark.parametrize("kind, step", [("complementary", 180), ("triad", 120), ("square", 90),
                                        ("hexagon", 60)])
@pytest.mark.parametrize("base", [0.0, 30.0, 359.5, -45.0, 725.0])
def test_harmony_hues_are_equally_spaced(kind, step, base):
    h = Hm.harmony_hues(base, kind)
    assert len(h) == 360 // step and np.all((h >= 0) & (h < 360))
    assert _circ(h[0], base) < 1e-9
    np.testing.assert_allclose(_circ(np.roll(h, -1), h), step, atol=1e-9)
    hsv = rgb_to_hsv(srgb_encode(Hm.harmony_colors(base, kind)))
    assert _circ(hsv[:, 0], h).max() < 1e-6
    np.testing.assert_allclose(hsv[:, 1:], 1.0, atol=1e-9)


def test_complement_of_red_is_cyan_on_the_hsv_wheel():
    np.testing.assert_allclose(srgb_encode(Hm.harmony_colors(0.0, "complementary")),
                               [[1, 0, 0], [0, 1, 1]], atol=1e-12)


def test_wheel_pixels_show_their_hue_and_the_markers_their_colour():
    size, base = 256, 30.0
    img = Hm.wheel_image(base, "square", size)
    assert img.shape == (size, size, 3) and img.dtype == np.float32 and np.isfinite(img).all()
    c, radius = (size - 1) / 2.0, 0.47 * size
    hsv = rgb_to_hsv(srgb_encode(img.astype(np.float64)))
    # on a circle outside the marker ring (0.72 R +- marker), hue = angle, saturation = r / R
    a = np.radians(np.arange(0, 360, 7.0))
    r = 0.9 * radius
    px, py = np.round(c + r * np.cos(a)).astype(int), np.round(c - r * np.sin(a)).astype(int)
    got = hsv[py, px]
    true_angle = np.degrees(np.arctan2(c - py, px - c)) % 360
    assert _circ(got[:, 0], true_angle).max() < 1.0      # 8-bit hue precision
    np.testing.assert_allclose(got[:, 1], np.hypot(px - c, c - py) / radius, atol=0.01)
    # marker centres hold the harmony colours
    for h, col in zip(Hm.harmony_hues(base, "square"), Hm.harmony_colors(base, "square")):
        t = np.radians(h)
        x, y = int(round(c + 0.72 * radius * np.cos(t))), int(round(c - 0.72 * radius * np.sin(t)))
        np.testing.assert_allclose(img[y, x], col, atol=1e-6)
    # outside the wheel: mid grey
    np.testing.assert_allclose(srgb_encode(img[0, 0].astype(np.float64)), 0.5, atol=1e-6)


def test_bad_harmony_input_is_a_workbench_error():
    with pytest.raises(WorkbenchError, match="unknown harmony"):
        Hm.harmony_hues(0, "pentagon")
    with pytest.raises(WorkbenchError, match="finite"):
        Hm.harmony_hues(float("nan"), "triad")
    with pytest.raises(WorkbenchError, match="16..8192"):
        Hm.wheel_image(0, "triad", size=4)
