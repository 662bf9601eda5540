"""Spectral -> RGB conversion: bundled CMF table, white point, Cornell data and scene file."""
from __future__ import annotations


import numpy as np
import pytest

import workbench
from workbench.core import spectral
from workbench.core.color import luminance
from published import entry
from workbench.core.errors import WorkbenchError

colour = pytest.importorskip("colour")
CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]


def _refs(rid):
    return entry(rid)["expected"]


def test_bundled_cmf_table_is_colour_science_cie1931():
    wl, cmf = spectral.cmfs()
    np.testing.assert_array_equal(wl, CMFS.wavelengths)
    np.testing.assert_allclose(cmf, CMFS.values, rtol=1e-15, atol=0)


def test_bundled_cornell_spectra_match_published_data():
    data = _refs("CORNELL-data")
    wl, refl = spectral.cornell_reflectances()
    np.testing.assert_array_equal(wl, np.arange(400, 701, 4))
    for name in ("white", "green", "red"):
        np.testing.assert_array_equal(refl[name], data[name])
    light = {float(k): v for k, v in data["light_emission_spectrum_nm"].items()}
    assert dict(spectral.CORNELL_LIGHT_EMISSION) == light


@pytest.mark.parametrize("illuminant", [None, ([400.0, 550.0, 700.0], [0.2, 3.0, 9.0])])
def test_flat_spectrum_gives_the_white_point(illuminant):
    wl = np.array([380.0, 780.0])
    for c in (1.0, 0.5):
        rgb = spectral.reflectance_to_rgb(wl, [c, c], illuminant)
        np.testing.assert_allclose(rgb, [c, c, c], atol=1e-12)
    # an equal-energy emission has the chromaticity of E, not D65: x = y = 1/3
    xyz = spectral.spectrum_to_xyz(wl, [1.0, 1.0])
    np.testing.assert_allclose(xyz[:2] / xyz.sum(), [1 / 3, 1 / 3], atol=1e-4)


def test_xyz_agrees_with_colour_science_integration():
    wl, refl = spectral.cornell_reflectances()
    shape = colour.SpectralShape(360, 830, 1)
    extra = dict(extrapolator=colour.Extrapolator,
                 extrapolator_kwargs={"method": "Constant", "left": None, "right": None})
    for rho in refl.values():
        sd = colour.SpectralDistribution(dict(zip(wl, rho)), interpolator=colour.LinearInterpolator)
        sd = sd.align(shape, interpolator=colour.LinearInterpolator, **extra)
        ref = colour.sd_to_XYZ(sd, CMFS, colour.sd_ones(shape), method="Integration") / 100
        mine = spectral.spectrum_to_xyz(wl, rho) / CMFS.values[:, 1].sum()
        np.testing.assert_allclose(mine, ref, atol=1e-9)


def test_light_white_balance_makes_one_bounce_exact():
    """light_rgb * rho_rgb (under the light) == rgb(light * rho), channel by channel."""
    wl, refl = spectral.cornell_reflectances()
    lw, lv = (np.array(x) for x in zip(*spectral.CORNELL_LIGHT_EMISSION))
    light_rgb = spectral.spectrum_to_rgb(lw, lv)
    grid = np.arange(360.0, 831.0)
    for rho in refl.values():
        rho_rgb = spectral.reflectance_to_rgb(wl, rho, (lw, lv))
        direct = spectral.spectrum_to_rgb(grid, np.interp(grid, wl, rho) * np.interp(grid, lw, lv))
        np.testing.assert_allclose(light_rgb * rho_rgb, direct, rtol=1e-12)


def test_cornell_scene_file_holds_the_recomputed_values():
    scene = workbench.load_scene("cornell")
    ref = spectral.cornell_rgb("light")
    for name in ("white", "red", "green"):
        np.testing.assert_allclose(scene.materials[name].color, ref[name], atol=1e-6)
    (light,) = scene.lights
    np.testing.assert_allclose(np.asarray(light.color) * light.intensity, ref["light"], rtol=1e-6)
    # exposure kept: same luminance as the former RGB light (17, 12, 4)
    assert luminance(ref["light"]) == pytest.approx(luminance([17.0, 12.0, 4.0]), rel=1e-12)


def test_cornell_colours_are_plausible():
    """Walls keep their hue; reflectances in (0, 1); white is near-neutral under both illuminants."""
    for il in spectral.ILLUMINANTS:
        v = spectral.cornell_rgb(il)
        assert np.argmax(v["red"]) == 0 and np.argmax(v["green"]) == 1
        for name in ("white", "red", "green"):
            assert np.all((v[name] > 0) & (v[name] < 1))
        assert np.ptp(v["white"]) < 0.02
    assert np.argmax(v["light"]) == 0 and np.all(v["light"] > 0)


def test_bad_spectra_are_workbench_errors():
    with pytest.raises(WorkbenchError, match="increasing"):
        spectral.spectrum_to_xyz([500.0, 400.0], [1.0, 1.0])
    with pytest.raises(WorkbenchError, match="finite"):
        spectral.spectrum_to_xyz([400.0, 500.0], [1.0, np.nan])
    with pytest.raises(WorkbenchError, match="luminance"):
        spectral.emission_to_rgb([400.0, 700.0], [0.0, 0.0], 1.0)
    with pytest.raises(WorkbenchError, match="illuminant"):
        spectral.cornell_rgb("d65")
