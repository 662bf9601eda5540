"""The chromatic circle and the course's colour harmonies ("Cercle chromatique", "Harmonisation
de couleurs par contraste"), on the HSV hue circle.

A harmony of n colours is n hues equally spaced around the circle from a base hue:
complementary pair (n = 2, 180 deg apart), triad (3, 120 deg), square (4, 90 deg), hexagon
(6, 60 deg).  The course draws its examples on the painters' red-yellow-blue wheel (red and
green complementary; yellow, blue, red a triad); on the HSV wheel used here (additive
primaries, hue 0 = red, 120 = green, 240 = blue) the complement of red is cyan, and the triad
from yellow (60) is yellow, cyan (180), magenta (300).

HSV is applied to *encoded* sRGB values (what a paint program's colour picker shows); the
functions return linear RGB like every image of the workbench, so that ``save_png`` shows the
exact HSV colour.
"""
from __future__ import annotations

import numpy as np

from .color import clip_to_gamut, hsv_to_rgb
from .errors import WorkbenchError
from .imageio import srgb_decode
from .memory import check_limit

#: Harmony name -> number of colours.
HARMONIES = {"complementary": 2, "triad": 3, "square": 4, "hexagon": 6}

_MARKER_RING = 0.72     # markers' distance from the centre, fraction of the wheel's radius
_MARKER_RADIUS = 0.055  # markers' radius, fraction of the image size


def harmony_hues(base_hue: float, kind: str) -> np.ndarray:
    """Hues in degrees ``(n,)`` of a harmony: ``(base + 360 k / n) mod 360``, k = 0..n-1."""
    if kind not in HARMONIES:
        raise WorkbenchError(f"unknown harmony {kind!r} (expected one of {', '.join(HARMONIES)})")
    base = float(base_hue)
    if not np.isfinite(base):
        raise WorkbenchError(f"base hue must be a finite number of degrees, got {base_hue!r}")
    n = HARMONIES[kind]
    return (base + 360.0 * np.arange(n) / n) % 360.0


def harmony_colors(base_hue: float, kind: str, saturation: float = 1.0,
                   value: float = 1.0) -> np.ndarray:
    """Linear RGB ``(n, 3)`` of a harmony's colours at the given HSV saturation and value."""
    h = harmony_hues(base_hue, kind)
    hsv = np.stack([h, np.full_like(h, saturation), np.full_like(h, value)], -1)
    return srgb_decode(clip_to_gamut(hsv_to_rgb(hsv)))


WHEEL_BYTES_PER_PIXEL = 320
"""Working memory per pixel of :func:`wheel_image`: the pixel grid and its distances (five
float64 planes), the HSV and RGB images and the compositing's temporaries (float64 RGB each)."""


def wheel_image(base_hue: float = 0.0, kind: str = "triad", size: int = 256,
                value: float = 1.0, *, max_memory=None) -> np.ndarray:
    """The HSV chromatic circle with a harmony marked: linear float32 ``(size, size, 3)``.

    Pixel at angle a (degrees, counter-clockwise from the +x axis, y up) and distance r from the
    centre, inside the wheel of radius R, has hue a, saturation r / R and the given value;
    outside is mid grey.  Each harmony colour is a disk of that colour (outlined black on white)
    on the ring at 0.72 R, and the disks are joined by black lines (a diameter, a triangle, a
    square, a hexagon).  Edges are anti-aliased by pixel coverage.  The work
    (:data:`WHEEL_BYTES_PER_PIXEL`) is checked against the memory limit (``max_memory``,
    :func:`.memory.memory_limit`) first.
    """
    hues = harmony_hues(base_hue, kind)
    if not (16 <= int(size) <= 8192):
        raise WorkbenchError(f"wheel size must be within 16..8192 pixels, got {size!r}")
    size = int(size)
    check_limit(size * size * WHEEL_BYTES_PER_PIXEL, f"a {size}x{size} colour wheel", max_memory)
    c = (size - 1) / 2.0
    radius = 0.47 * size
    yy, xx = np.mgrid[0:size, 0:size].astype(np.float64)
    dx, dy = xx - c, c - yy
    dist = np.hypot(dx, dy)
    hsv = np.stack([np.degrees(np.arctan2(dy, dx)) % 360.0, np.minimum(dist / radius, 1.0),
                    np.full_like(dist, value)], -1)
    img = _over(np.full((size, size, 3), 0.5), hsv_to_rgb(hsv), _cover(radius - dist))
    ang = np.radians(hues)
    pts = np.stack([c + _MARKER_RING * radius * np.cos(ang), c - _MARKER_RING * radius * np.sin(ang)], -1)
    line = 0.004 * size + 0.5
    for i in range(len(pts) if len(pts) > 2 else 1):
        d = _segment_distance(xx, yy, pts[i], pts[(i + 1) % len(pts)])
        img = _over(img, np.zeros(3), _cover(line - d))
    r_m = _MARKER_RADIUS * size
    colors = hsv_to_rgb(np.stack([hues, np.ones_like(hues), np.full_like(hues, value)], -1))
    for (px, py), col in zip(pts, colors):
        d = np.hypot(xx - px, yy - py)
        img = _over(img, np.ones(3), _cover(r_m + 2 * line - d))
        img = _over(img, np.zeros(3), _cover(r_m + line - d))
        img = _over(img, col, _cover(r_m - d))
    return srgb_decode(clip_to_gamut(img)).astype(np.float32)


def _cover(signed_distance: np.ndarray) -> np.ndarray:
    """Pixel coverage ``(H, W)`` in [0, 1] from a signed distance to an edge (positive inside)."""
    return np.clip(signed_distance + 0.5, 0.0, 1.0)


def _over(img: np.ndarray, color, alpha: np.ndarray) -> np.ndarray:
    return img * (1.0 - alpha[..., None]) + np.asarray(color) * alpha[..., None]


def _segment_distance(xx, yy, a, b) -> np.ndarray:
    """Distance ``(H, W)`` from each pixel centre to the segment [a, b] (a != b: distinct hues)."""
    ab = np.asarray(b) - np.asarray(a)
    t = np.clip(((xx - a[0]) * ab[0] + (yy - a[1]) * ab[1]) / float(ab @ ab), 0.0, 1.0)
    return np.hypot(xx - a[0] - t * ab[0], yy - a[1] - t * ab[1])
