"""Spectra to linear sRGB through the CIE 1931 colour-matching functions (course: "composition
spectrale"), and the Cornell box's measured spectra converted for the bundled scene.

Conversion
----------
A spectrum S(lambda) (radiance, or reflectance times an illuminant) has the CIE 1931 XYZ
tristimulus values (CIE 015:2018, eq. 7.1, as a Riemann sum on the 1 nm table)::

    X = sum S(l) xbar(l) dl,   Y = sum S(l) ybar(l) dl,   Z = sum S(l) zbar(l) dl,

over 360..830 nm with dl = 1 nm, and linear sRGB ``rgb(S) = M^-1 XYZ``
(:func:`workbench.core.color.xyz_to_rgb`).  Tabulated spectra are interpolated linearly
onto the 1 nm grid and held constant beyond their first and last samples (the Cornell data
stop at 400 and 700 nm; the tails add < 1 % of Y).

Reflectances.  An RGB renderer multiplies a light's RGB by a surface's RGB, so a
reflectance rho(lambda) is given the per-channel ratio (a von Kries white balance done in
the sRGB channels)::

    rho_rgb = rgb(rho * E) / rgb(E)

for an illuminant E.  By construction a flat reflectance rho = c maps to (c, c, c) for every
illuminant: a flat 1.0 spectrum is the white point (1, 1, 1).  Two illuminants are offered:

* ``"equal_energy"`` (E = 1): the surface's own colour, independent of the light;
* ``"light"`` (E = the scene's emitter): the light's spectrum weights the reflectance, so that
  ``light_rgb * rho_rgb`` equals ``rgb(light * rho)`` exactly for light reflected once.  The
  bundled Cornell box uses this one (its only emitter is this light).

Emitters.  ``rgb(S)`` of the light, scaled by one factor so that its luminance Y (the Y row of
the sRGB matrix) equals a chosen value: the published emission is relative, so its absolute
level is a choice; the workbench keeps the level of the RGB light it had before (Tungsten's
(17, 12, 4), Y = 12.485) so that image exposure does not change.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from .color import LUMINANCE_WEIGHTS, xyz_to_rgb
from .errors import WorkbenchError

DATA_DIR = Path(__file__).resolve().parent / "data"
CMF_FILE = DATA_DIR / "cie1931_2deg.csv"
CORNELL_FILE = DATA_DIR / "cornell_box_spectra.csv"

#: Relative emission spectrum of the Cornell box light (Cornell data page): nm -> value,
#: linear interpolation between the points.
CORNELL_LIGHT_EMISSION = ((400.0, 0.0), (500.0, 8.0), (600.0, 15.6), (700.0, 18.4))
#: Luminance given to the converted light: that of Tungsten's RGB (17, 12, 4).
CORNELL_LIGHT_LUMINANCE = float(LUMINANCE_WEIGHTS @ np.array([17.0, 12.0, 4.0]))
ILLUMINANTS = ("equal_energy", "light")


def _read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if not ln.startswith("#")]
    return lines[0].split(","), np.loadtxt(lines[1:], delimiter=",", ndmin=2)


@lru_cache(maxsize=1)
def cmfs() -> tuple[np.ndarray, np.ndarray]:
    """The bundled CIE 1931 2 deg table: wavelengths ``(N,)`` in nm and xbar, ybar, zbar ``(N, 3)``."""
    _, table = _read_csv(CMF_FILE)
    return table[:, 0], table[:, 1:4]


def cornell_reflectances() -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The Cornell box's measured reflectances: wavelengths ``(76,)`` and ``{name: (76,)}``."""
    names, table = _read_csv(CORNELL_FILE)
    return table[:, 0], {n: table[:, i] for i, n in enumerate(names) if i > 0}


def _on_grid(wavelengths, values) -> np.ndarray:
    """Spectrum ``(M,)`` (or ``(..., M)``) resampled on the CMF grid ``(..., N)`` (linear, ends held)."""
    wl = np.asarray(wavelengths, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if wl.ndim != 1 or v.shape[-1] != wl.size or wl.size < 2 or np.any(np.diff(wl) <= 0):
        raise WorkbenchError("a spectrum needs increasing wavelengths (M,) and values (..., M); "
                             f"got {wl.shape} and {v.shape}")
    if not np.all(np.isfinite(v)):
        raise WorkbenchError("spectrum values must be finite")
    grid, _ = cmfs()
    return np.apply_along_axis(lambda row: np.interp(grid, wl, row), -1, v)


def spectrum_to_xyz(wavelengths, values) -> np.ndarray:
    """CIE XYZ ``(..., 3)`` of a spectrum ``(..., M)`` sampled at ``wavelengths (M,)`` nm.

    Unnormalised: ``X = sum S xbar dl`` with dl = 1 nm, in the spectrum's units times nm.
    """
    _, cmf = cmfs()
    return _on_grid(wavelengths, values) @ cmf


def spectrum_to_rgb(wavelengths, values) -> np.ndarray:
    """Linear sRGB ``(..., 3)`` of an emission spectrum (unnormalised, see :func:`spectrum_to_xyz`)."""
    return xyz_to_rgb(spectrum_to_xyz(wavelengths, values))


def emission_to_rgb(wavelengths, values, luminance: float) -> np.ndarray:
    """Linear sRGB ``(3,)`` of an emitter's spectrum ``(M,)``, scaled so that its Y = ``luminance``."""
    rgb = spectrum_to_rgb(wavelengths, values)
    y = float(LUMINANCE_WEIGHTS @ rgb)
    if y <= 0.0:
        raise WorkbenchError("emission spectrum has no luminance (zero over the visible range)")
    return rgb * (luminance / y)


def reflectance_to_rgb(wavelengths, reflectance, illuminant=None) -> np.ndarray:
    """Linear sRGB ``(..., 3)`` of reflectances ``(..., M)``: ``rgb(rho E) / rgb(E)`` per channel.

    Parameters
    ----------
    wavelengths : (M,) nm
    reflectance : (..., M)
    illuminant : None or (wavelengths (K,), values (K,))
        ``None`` is the equal-energy illuminant E = 1.  A flat reflectance c gives (c, c, c)
        whatever the illuminant (the white-point normalisation).
    """
    grid, cmf = cmfs()
    rho = _on_grid(wavelengths, reflectance)
    e = np.ones_like(grid) if illuminant is None else _on_grid(*illuminant)
    white = xyz_to_rgb(e @ cmf)
    if np.any(white <= 0.0):
        raise WorkbenchError(f"illuminant has a non-positive sRGB channel {white}: cannot "
                             "white-balance reflectances under it")
    return xyz_to_rgb((rho * e) @ cmf) / white


def cornell_rgb(illuminant: str = "light",
                light_luminance: float = CORNELL_LIGHT_LUMINANCE) -> dict[str, np.ndarray]:
    """The Cornell box's measured spectra as linear sRGB: ``{"white", "red", "green", "light"}``.

    ``illuminant`` is ``"light"`` (reflectances white-balanced under the box's own light: what
    the bundled scene uses) or ``"equal_energy"``; the light's RGB has luminance
    ``light_luminance``.
    """
    if illuminant not in ILLUMINANTS:
        raise WorkbenchError(f"illuminant must be one of {ILLUMINANTS}, got {illuminant!r}")
    light = tuple(np.array(x) for x in zip(*CORNELL_LIGHT_EMISSION))
    wl, refl = cornell_reflectances()
    out = {name: reflectance_to_rgb(wl, rho, light if illuminant == "light" else None)
           for name, rho in refl.items()}
    out["light"] = emission_to_rgb(*light, light_luminance)
    return out
