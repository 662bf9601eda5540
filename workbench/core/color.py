"""Colour spaces of the course's first chapter ("La Couleur"), vectorised over ``(..., 3)`` arrays.

Every function takes an array whose last axis holds the three (or four, for CMYK) components
and returns an array of the same leading shape, in float64.  No function clips: the formulas
are applied as written, so an out-of-gamut input gives an out-of-range output that converts
back to the input (see each function for what the components then mean).  To show such a
colour, clip it with :func:`clip_to_gamut` (what a frame buffer does).

Spaces
------
linear RGB
    The workbench's image space: sRGB primaries and D65 white (IEC 61966-2-1), *linear*
    values (no transfer curve).  The sRGB transfer encoding lives in
    :mod:`workbench.core.imageio` (``srgb_encode``/``srgb_decode``) and is not repeated here.
CIE XYZ
    CIE 1931 tristimulus values, Y = relative luminance, white (1, 1, 1) RGB -> D65
    (0.9505, 1.0, 1.089).
CMY, CMYK
    Subtractive synthesis: C = 1 - R, M = 1 - G, Y = 1 - B; K = min(C, M, Y, 1) with the
    remaining inks rescaled by 1 / (1 - K) (black: K = 1 and C = M = Y = 0 by convention).
HSV, HSL
    Smith (1978) hexcone (hue, saturation, value) and Joblove & Greenberg (1978) double
    hexcone (hue, saturation, lightness).  Hue in degrees in [0, 360), saturation and
    value/lightness in [0, 1] for colours inside the RGB cube.  These are *perceptual-ish
    coordinates of whatever RGB triple they are given*: conventionally that is the encoded
    (display) RGB, so :mod:`workbench.core.harmony` converts HSV to encoded sRGB and then
    decodes it to linear.  The CMY family likewise applies to the RGB values it is given.
HSI
    Gonzalez & Woods, *Digital Image Processing*, section 6.2.3 (the course's "Teinte,
    Saturation, Luminance (HSI)"): intensity ``I = (R + G + B) / 3``, saturation
    ``S = 1 - 3 min(R, G, B) / (R + G + B)``, hue the angle around the grey axis from the red
    axis (arccos formula).  Hue in degrees in [0, 360) like HSV and HSL, S and I in [0, 1]
    for colours inside the RGB cube.  Unlike the hexcone hue of HSV/HSL, the HSI hue is the
    true angle, so the two hues agree only at multiples of 60 degrees.  The arccos is
    ill-conditioned near 0 and 180 degrees (G close to B): there the hue keeps about
    sqrt(eps) ~ 1.5e-8 rad, and RGB -> HSI -> RGB returns within 1e-7 instead of 1e-14.

Edge cases (tested against colour-science; HSI, which it lacks, against hand-worked values)
---------------------------------------------------------------------------------------------
* Black (0, 0, 0): HSV (0, 0, 0), HSL (0, 0, 0), HSI (0, 0, 0), CMY (1, 1, 1), CMYK (0, 0, 0, 1).
* White (1, 1, 1): HSV (0, 0, 1), HSL (0, 0, 1), HSI (0, 0, 1), CMYK (0, 0, 0, 0).
* Greys (R = G = B): the hue is undefined; it is set to 0 and the saturation to 0.
* Out of gamut (a component < 0 or > 1, e.g. from ``xyz_to_rgb`` of a spectral colour):
  no clipping.  The hue is still the angle of the triple around the grey axis; HSV
  saturation = (max - min) / max may exceed 1 or be negative (max < 0); HSL saturation =
  (max - min) / (1 - |2L - 1|) likewise.  Where that denominator is 0 the saturation is set
  to 0 (and the conversion back loses the chroma): HSV with max = 0 and min < 0, HSL with
  L = 0 or 1 but max != min.  HSI saturation = 1 - min / I likewise leaves [0, 1] (negative
  when min < 0 < I) and is set to 0 where I = 0 but max != min.  CMYK caps K at 1, so an RGB
  triple with every component < 0 becomes black.  Everywhere else the conversions invert
  exactly.
* The other way, a triple that looks valid (H in [0, 360), S and V/L/I in [0, 1]) is inside
  the RGB cube for HSV and HSL, but not always for HSI: at a given hue and saturation the
  cube's surface is reached below I = 1 (for a primary at S = 1, at I = 1/3), so e.g. HSI
  (0, 1, 0.5) gives RGB (1.5, 0, 0).  It is returned unclipped, like every out-of-gamut colour
  here; ``workbench colour convert`` reports it.
"""
from __future__ import annotations

import numpy as np

from .errors import WorkbenchError
from .tol import tol

#: Linear sRGB -> CIE XYZ (IEC 61966-2-1:1999, eq. (6) as printed, 4 decimals; the row for Y
#: gives the Rec. 709 luminance weights 0.2126, 0.7152, 0.0722, which sum to 1).
XYZ_FROM_RGB = np.array([[0.4124, 0.3576, 0.1805],
                         [0.2126, 0.7152, 0.0722],
                         [0.0193, 0.1192, 0.9505]])
#: CIE XYZ -> linear sRGB: the exact inverse of :data:`XYZ_FROM_RGB` (the standard prints
#: it rounded to 4 decimals, which does not invert the forward matrix to better than 1e-4).
RGB_FROM_XYZ = np.linalg.inv(XYZ_FROM_RGB)
#: Luminance weights of linear sRGB (the Y row of :data:`XYZ_FROM_RGB`).
LUMINANCE_WEIGHTS = XYZ_FROM_RGB[1].copy()


def _as3(a, n: int = 3) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 0 or a.shape[-1] != n:
        raise WorkbenchError(f"colour array must have {n} components on its last axis, "
                             f"got shape {a.shape}")
    return a


def _safe_div(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    """num / den, 0 where |den| <= tol.zero (the documented convention for undefined ratios)."""
    ok = np.abs(den) > tol.zero
    return np.where(ok, num / np.where(ok, den, 1.0), 0.0)


def rgb_to_xyz(rgb) -> np.ndarray:
    """Linear sRGB ``(..., 3)`` -> CIE XYZ ``(..., 3)`` (``XYZ = M rgb``, IEC 61966-2-1)."""
    return _as3(rgb) @ XYZ_FROM_RGB.T


def xyz_to_rgb(xyz) -> np.ndarray:
    """CIE XYZ ``(..., 3)`` -> linear sRGB ``(..., 3)``; out-of-gamut colours give components
    < 0 or > 1, returned as they are."""
    return _as3(xyz) @ RGB_FROM_XYZ.T


def luminance(rgb) -> np.ndarray:
    """Relative luminance Y of linear sRGB ``(..., 3)`` -> ``(...)``."""
    return _as3(rgb) @ LUMINANCE_WEIGHTS


def clip_to_gamut(rgb) -> np.ndarray:
    """Clip each component to [0, 1] (what an 8-bit frame buffer keeps)."""
    return np.clip(_as3(rgb), 0.0, 1.0)


def rgb_to_cmy(rgb) -> np.ndarray:
    """RGB ``(..., 3)`` -> CMY ``(..., 3)``: ``(C, M, Y) = 1 - (R, G, B)`` (subtractive synthesis)."""
    return 1.0 - _as3(rgb)


def cmy_to_rgb(cmy) -> np.ndarray:
    """CMY ``(..., 3)`` -> RGB ``(..., 3)``: ``1 - (C, M, Y)``."""
    return 1.0 - _as3(cmy)


def cmy_to_cmyk(cmy) -> np.ndarray:
    """CMY ``(..., 3)`` -> CMYK ``(..., 4)`` with full grey-component replacement.

    ``K = min(C, M, Y, 1)``, ``C' = (C - K) / (1 - K)`` (same for M, Y); for K = 1 (black)
    C' = M' = Y' = 0.  K is capped at 1 (no more than full black ink), so a colour "blacker
    than black" (every RGB component < 0) maps to plain black (0, 0, 0, 1).
    """
    cmy = _as3(cmy)
    k = np.minimum(cmy.min(axis=-1), 1.0)
    inks = _safe_div(cmy - k[..., None], (1.0 - k)[..., None])
    return np.concatenate([inks, k[..., None]], axis=-1)


def cmyk_to_cmy(cmyk) -> np.ndarray:
    """CMYK ``(..., 4)`` -> CMY ``(..., 3)``: ``C = C' (1 - K) + K``."""
    cmyk = _as3(cmyk, 4)
    k = cmyk[..., 3:]
    return cmyk[..., :3] * (1.0 - k) + k


def rgb_to_cmyk(rgb) -> np.ndarray:
    """RGB ``(..., 3)`` -> CMYK ``(..., 4)`` (:func:`rgb_to_cmy` then :func:`cmy_to_cmyk`)."""
    return cmy_to_cmyk(rgb_to_cmy(rgb))


def cmyk_to_rgb(cmyk) -> np.ndarray:
    """CMYK ``(..., 4)`` -> RGB ``(..., 3)``."""
    return cmy_to_rgb(cmyk_to_cmy(cmyk))


def _hue_chroma(rgb: np.ndarray):
    """Hue in degrees [0, 360), max, min and chroma ``max - min`` of ``(..., 3)`` RGB.

    Hexcone hue (Smith 1978): 60 deg * ((G - B)/C mod 6 | (B - R)/C + 2 | (R - G)/C + 4)
    for max = R | G | B; 0 where C = 0 (greys).
    """
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    mx, mn = rgb.max(axis=-1), rgb.min(axis=-1)
    c = mx - mn
    h = np.where(mx == r, _safe_div(g - b, c) % 6.0,
                 np.where(mx == g, _safe_div(b - r, c) + 2.0, _safe_div(r - g, c) + 4.0))
    h = np.where(c > tol.zero, (60.0 * h) % 360.0, 0.0)
    return np.where(h >= 360.0, 0.0, h), mx, mn, c   # x % 360 rounds to 360 for x -> 0-


def rgb_to_hsv(rgb) -> np.ndarray:
    """RGB ``(..., 3)`` -> HSV ``(..., 3)``: hue in degrees, ``S = (max - min) / max``, ``V = max``."""
    h, mx, _, c = _hue_chroma(_as3(rgb))
    return np.stack([h, _safe_div(c, mx), mx], axis=-1)


def hsv_to_rgb(hsv) -> np.ndarray:
    """HSV ``(..., 3)`` -> RGB ``(..., 3)``.

    Channel n (5, 3, 1 for R, G, B): ``V - V S max(0, min(k, 4 - k, 1))`` with
    ``k = (n + H / 60) mod 6``; hue taken modulo 360.
    """
    hsv = _as3(hsv)
    h, s, v = hsv[..., 0] % 360.0, hsv[..., 1], hsv[..., 2]
    n = np.array([5.0, 3.0, 1.0])
    k = (n + h[..., None] / 60.0) % 6.0
    w = np.clip(np.minimum(k, 4.0 - k), 0.0, 1.0)
    return v[..., None] - (v * s)[..., None] * w


def rgb_to_hsl(rgb) -> np.ndarray:
    """RGB ``(..., 3)`` -> HSL ``(..., 3)``: ``L = (max + min) / 2``,
    ``S = (max - min) / (1 - |2L - 1|)`` (Joblove & Greenberg 1978)."""
    h, mx, mn, c = _hue_chroma(_as3(rgb))
    lum = 0.5 * (mx + mn)
    return np.stack([h, _safe_div(c, 1.0 - np.abs(2.0 * lum - 1.0)), lum], axis=-1)


def hsl_to_rgb(hsl) -> np.ndarray:
    """HSL ``(..., 3)`` -> RGB ``(..., 3)``.

    Channel n (0, 8, 4 for R, G, B): ``L - a max(-1, min(k - 3, 9 - k, 1))`` with
    ``a = S min(L, 1 - L)`` and ``k = (n + H / 30) mod 12``.
    """
    hsl = _as3(hsl)
    h, s, lum = hsl[..., 0] % 360.0, hsl[..., 1], hsl[..., 2]
    a = s * np.minimum(lum, 1.0 - lum)
    n = np.array([0.0, 8.0, 4.0])
    k = (n + h[..., None] / 30.0) % 12.0
    w = np.clip(np.minimum(k - 3.0, 9.0 - k), -1.0, 1.0)
    return lum[..., None] - a[..., None] * w


def _hsi_hue(rgb: np.ndarray) -> np.ndarray:
    """HSI hue in degrees [0, 360) of ``(..., 3)`` RGB (Gonzalez & Woods, section 6.2.3).

    ``theta = arccos( [(R - G) + (R - B)] / 2 / sqrt((R - G)^2 + (R - B)(G - B)) )``,
    ``H = theta`` if ``B <= G`` else ``360 - theta``; 0 where the square root (a multiple of the
    distance to the grey axis) is 0 (greys).  The arccos argument is clipped to [-1, 1] against
    rounding.
    """
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    den = np.sqrt(np.maximum((r - g) ** 2 + (r - b) * (g - b), 0.0))
    theta = np.degrees(np.arccos(np.clip(_safe_div(0.5 * ((r - g) + (r - b)), den), -1.0, 1.0)))
    h = np.where(den > tol.zero, np.where(b > g, 360.0 - theta, theta), 0.0)
    return np.where(h >= 360.0, 0.0, h)       # 360 - theta with theta rounded to 0


def rgb_to_hsi(rgb) -> np.ndarray:
    """RGB ``(..., 3)`` -> HSI ``(..., 3)`` (Gonzalez & Woods, section 6.2.3).

    ``H`` from :func:`_hsi_hue` in degrees, ``S = 1 - 3 min(R, G, B) / (R + G + B)``,
    ``I = (R + G + B) / 3``.  Greys have H = 0 and S = 0; black is (0, 0, 0).  S is computed
    as ``(I - min) / I`` and set to 0 where ``|I| <= tol.zero`` (see the module's edge cases).
    """
    rgb = _as3(rgb)
    i = rgb.mean(axis=-1)
    return np.stack([_hsi_hue(rgb), _safe_div(i - rgb.min(axis=-1), i), i], axis=-1)


def hsi_to_rgb(hsi) -> np.ndarray:
    """HSI ``(..., 3)`` -> RGB ``(..., 3)`` by the three 120-degree sectors (Gonzalez & Woods,
    section 6.2.3).  Hue taken modulo 360, then ``h = H - 120 k`` in sector ``k = 0, 1, 2``:

    * the sector's smallest channel (B, R, G for k = 0, 1, 2): ``I (1 - S)``;
    * its leading channel (R, G, B): ``I [1 + S cos h / cos(60 - h)]``;
    * the third (G, B, R): ``3 I`` minus the other two.

    No clipping: a triple outside the RGB cube (possible for H, S, I each in range, e.g.
    (0, 1, 0.5) -> (1.5, 0, 0)) is returned as computed.
    """
    hsi = _as3(hsi)
    hue, s, i = hsi[..., 0] % 360.0, hsi[..., 1], hsi[..., 2]
    k = np.minimum(hue // 120.0, 2.0)      # hue % 360 can round to 360.0
    h = np.radians(hue - 120.0 * k)
    low = i * (1.0 - s)
    lead = i * (1.0 + s * np.cos(h) / np.cos(np.pi / 3.0 - h))
    by_role = np.stack([lead, 3.0 * i - (lead + low), low], axis=-1)   # (leading, third, smallest)
    role = (np.arange(3) - k[..., None].astype(np.intp)) % 3          # channel c has role (c - k) mod 3
    return np.take_along_axis(by_role, role, axis=-1)


#: The colour spaces offered by name (``workbench colour convert``): name -> (component labels,
#: RGB -> space, space -> RGB).  Hues (H) are in degrees.
SPACES = {
    "rgb": (("R", "G", "B"), _as3, _as3),
    "xyz": (("X", "Y", "Z"), rgb_to_xyz, xyz_to_rgb),
    "cmy": (("C", "M", "Y"), rgb_to_cmy, cmy_to_rgb),
    "cmyk": (("C", "M", "Y", "K"), rgb_to_cmyk, cmyk_to_rgb),
    "hsv": (("H", "S", "V"), rgb_to_hsv, hsv_to_rgb),
    "hsl": (("H", "S", "L"), rgb_to_hsl, hsl_to_rgb),
    "hsi": (("H", "S", "I"), rgb_to_hsi, hsi_to_rgb),
}


def space_labels(name: str) -> tuple[str, ...]:
    """The component labels of the colour space ``name`` (a key of :data:`SPACES`)."""
    if name not in SPACES:
        raise WorkbenchError(f"unknown colour space {name!r}: expected one of {', '.join(SPACES)}")
    return SPACES[name][0]


def convert(values, source: str, target: str) -> np.ndarray:
    """Colours ``(..., n)`` in space ``source`` -> space ``target`` (names of :data:`SPACES`),
    through RGB; unclipped, like every conversion here."""
    for name in (source, target):
        space_labels(name)                 # an unknown name is refused before any work
    return SPACES[target][1](SPACES[source][2](values))
