"""HSI (Gonzalez & Woods, *Digital Image Processing*, section 6.2.3) beside HSV and HSL: worked
values derived by hand from the published formulas, round trips both ways, the conventions of
``workbench.core.color`` (greys, black, out of the cube), and ``workbench colour convert`` run
as the console script.

Round-trip accuracy.  RGB -> HSI -> RGB on the 101^3 grid of the cube: max error 1.9e-14
(measured on x86-64).  The arccos of the hue formula is ill-conditioned near theta = 0 and 180
degrees: for G - B tiny against the chroma (e.g. (1, 0.5, 0.5 + 1e-8)) the argument rounds to
1 and the hue loses up to sqrt(eps) ~ 1.5e-8 rad, so the bound that holds for *every* colour of
the cube, on any CPU and libm, is 1e-6 (worst measured 2.0e-8 on a million colours crowded
around G = B); the grid itself holds to 1e-9.
"""
from __future__ import annotations

import subprocess

import numpy as np
import pytest

from ui_command import WORKBENCH
from workbench.core import color as C
from workbench.core.errors import WorkbenchError

GRID = np.stack(np.meshgrid(*[np.linspace(0.0, 1.0, 101)] * 3, indexing="ij"), -1).reshape(-1, 3)


def _hue_dist(a, b):
    d = np.abs(np.asarray(a) - b) % 360.0
    return np.minimum(d, 360.0 - d)


# (R, G, B) -> (H deg, S, I), each worked by hand from
#   I = (R + G + B) / 3,  S = 1 - 3 min / (R + G + B),
#   theta = arccos( [(R-G) + (R-B)] / 2 / sqrt((R-G)^2 + (R-B)(G-B)) ),  H = theta, or 360 - theta if B > G
WORKED = [
    # red: I = 1/3; S = 1 - 0 = 1; arccos(((1) + (1)) / 2 / sqrt(1 + 1*0)) = arccos(1) = 0
    ((1.0, 0.0, 0.0), (0.0, 1.0, 1 / 3)),
    # green: S = 1; arccos(((-1) + 0) / 2 / sqrt(1 + 0*1)) = arccos(-1/2) = 120; B = G -> 120
    ((0.0, 1.0, 0.0), (120.0, 1.0, 1 / 3)),
    # blue: S = 1; arccos((0 + (-1)) / 2 / sqrt(0 + (-1)(-1))) = arccos(-1/2) = 120; B > G -> 240
    ((0.0, 0.0, 1.0), (240.0, 1.0, 1 / 3)),
    # cyan: I = 2/3; S = 1; arccos(((-1) + (-1)) / 2 / sqrt(1 + (-1)*0)) = arccos(-1) = 180
    ((0.0, 1.0, 1.0), (180.0, 1.0, 2 / 3)),
    # mixed, B > G: sum 1.2, I = 0.4; S = 1 - 3 * 0.2 / 1.2 = 0.5;
    # arccos((0.4 + 0.2) / 2 / sqrt(0.16 + 0.2 * (-0.2))) = arccos(0.3 / sqrt(0.12)) = arccos(sqrt(3)/2) = 30;
    # B > G -> H = 360 - 30 = 330
    ((0.6, 0.2, 0.4), (330.0, 0.5, 0.4)),
    # the same with G and B swapped, B < G: H = theta = 30
    ((0.6, 0.4, 0.2), (30.0, 0.5, 0.4)),
    # grey: S = 1 - 3 * 0.5 / 1.5 = 0; the hue's denominator is 0: H = 0 by convention
    ((0.5, 0.5, 0.5), (0.0, 0.0, 0.5)),
    # black: R + G + B = 0, S and H undefined: both 0 by convention
    ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    # white: a grey, I = 1
    ((1.0, 1.0, 1.0), (0.0, 0.0, 1.0)),
]


@pytest.mark.parametrize("rgb, hsi", WORKED, ids=[str(r) for r, _ in WORKED])
def test_worked_values_both_ways(rgb, hsi):
    got = C.rgb_to_hsi(np.array(rgb))
    assert _hue_dist(got[0], hsi[0]) < 1e-9
    np.testing.assert_allclose(got[1:], hsi[1:], atol=1e-12)
    np.testing.assert_allclose(C.hsi_to_rgb(np.array(hsi)), rgb, atol=1e-12)


def test_inverse_sectors_worked_by_hand():
    hsi = np.array([
        [60.0, 1.0, 0.5],     # sector RG, h = 60: B = 0.5 (1 - 1) = 0; R = 0.5 (1 + cos 60 / cos 0) = 0.75; G = 1.5 - 0.75
        [180.0, 1.0, 1 / 3],  # sector GB, h = 60: R = 0; G = (1 + cos 60 / cos 0) / 3 = 0.5; B = 1 - 0.5
        [300.0, 0.5, 0.4],    # sector BR, h = 60: G = 0.2; B = 0.4 (1 + 0.5 * 0.5 / 1) = 0.5; R = 1.2 - 0.7
        [-30.0, 0.5, 0.4],    # hue taken modulo 360: 330, sector BR, h = 90: G = 0.2; B = 0.4 (1 + 0) = 0.4; R = 0.6
    ])
    want = [[0.75, 0.75, 0.0], [0.0, 0.5, 0.5], [0.5, 0.2, 0.5], [0.6, 0.2, 0.4]]
    np.testing.assert_allclose(C.hsi_to_rgb(hsi), want, atol=1e-12)


def test_a_valid_looking_hsi_triple_can_leave_the_cube_and_is_not_clipped():
    # H = 0, S = 1, I = 0.5: B = 0; R = 0.5 (1 + cos 0 / cos 60) = 1.5; G = 1.5 - 1.5 = 0
    np.testing.assert_allclose(C.hsi_to_rgb(np.array([0.0, 1.0, 0.5])), [1.5, 0.0, 0.0], atol=1e-12)
    # HSV and HSL keep such triples inside the cube: the module's one documented difference
    for to_rgb in (C.hsv_to_rgb, C.hsl_to_rgb):
        assert np.abs(to_rgb(np.array([0.0, 1.0, 0.5]))).max() <= 1.0


def test_rgb_hsi_rgb_over_the_dense_grid():
    x = GRID.reshape(101, 101, 101, 3)          # image-like leading shape
    err = np.abs(C.hsi_to_rgb(C.rgb_to_hsi(x)) - x).max()
    assert err < 1e-9, err                      # measured 1.9e-14


def test_rgb_hsi_rgb_near_the_ill_conditioned_hue():
    """Colours with G - B from 1e-16 to 1e-4 of the chroma, where arccos loses sqrt(eps)."""
    rng = np.random.default_rng(20261122)
    x = rng.uniform(0.0, 1.0, (200000, 3))
    x[:, 2] = np.clip(x[:, 1] + rng.uniform(-1, 1, len(x)) * 10.0 ** rng.uniform(-16, -4, len(x)), 0, 1)
    err = np.abs(C.hsi_to_rgb(C.rgb_to_hsi(x)) - x).max()
    assert err < 1e-6, err                      # measured 1.7e-8


def test_hsi_rgb_hsi_where_defined():
    """Over H in [0, 360) by 1 degree, S and I in (0, 1]: the hue is defined (S > 0, I > 0); the
    RGB between may leave the cube.  Hue error measured 1.2e-6 degree (at S = 0.01, H = 0: the
    arccos again), S and I 5e-16."""
    h, s, i = np.meshgrid(np.arange(360.0), np.linspace(0.01, 1, 50), np.linspace(0.01, 1, 50),
                          indexing="ij")
    hsi = np.stack([h, s, i], -1)
    back = C.rgb_to_hsi(C.hsi_to_rgb(hsi))
    assert _hue_dist(back[..., 0], hsi[..., 0]).max() < 1e-4
    np.testing.assert_allclose(back[..., 1:], hsi[..., 1:], atol=1e-9)


def test_undefined_hue_and_saturation_come_back_as_zero():
    hsi = np.array([[123.0, 0.0, 0.7],      # S = 0: the grey 0.7, whatever the hue
                    [200.0, 0.8, 0.0]])     # I = 0: black
    rgb = C.hsi_to_rgb(hsi)
    np.testing.assert_allclose(rgb, [[0.7] * 3, [0.0] * 3], atol=1e-12)
    np.testing.assert_allclose(C.rgb_to_hsi(rgb), [[0, 0, 0.7], [0, 0, 0]], atol=1e-12)


def test_hue_is_the_angle_around_the_grey_axis():
    """Independent of the arccos formula: the angle of the chroma in the plane normal to grey,
    red at 0 and green at 120: atan2(sqrt(3) (G - B), 2R - G - B).  It agrees with the HSV
    hexcone hue at multiples of 60 degrees only."""
    rng = np.random.default_rng(7)
    x = rng.uniform(0.0, 1.0, (20000, 3))
    r, g, b = x.T
    angle = np.degrees(np.arctan2(np.sqrt(3.0) * (g - b), 2 * r - g - b)) % 360.0
    assert _hue_dist(C.rgb_to_hsi(x)[:, 0], angle).max() < 1e-6
    six = np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1], [1, 0, 1]], float)
    np.testing.assert_allclose(C.rgb_to_hsi(six)[:, 0], C.rgb_to_hsv(six)[:, 0], atol=1e-9)
    assert _hue_dist(C.rgb_to_hsi(x)[:, 0], C.rgb_to_hsv(x)[:, 0]).max() > 1.0


def test_out_of_the_cube_round_trips_where_the_intensity_is_not_zero():
    rng = np.random.default_rng(11)
    x = rng.uniform(-0.5, 1.5, (20000, 3))
    keep = np.abs(x.mean(axis=-1)) > 1e-6
    err = np.abs(C.hsi_to_rgb(C.rgb_to_hsi(x[keep])) - x[keep]).max()
    assert err < 1e-6, err                      # measured 5.9e-13
    # I = 0 but not black: S = 1 - min / I is undefined, set to 0 (the chroma is lost)
    np.testing.assert_allclose(C.rgb_to_hsi(np.array([0.5, -0.25, -0.25])), [0, 0, 0], atol=1e-12)


def test_shapes_and_hue_range():
    assert C.rgb_to_hsi(np.zeros((2, 3, 3))).shape == (2, 3, 3)
    assert C.hsi_to_rgb(np.zeros((4, 3))).shape == (4, 3)
    h = C.rgb_to_hsi(np.concatenate([GRID, [[1.0, 0.0, 1e-17]]]))[:, 0]
    assert h.min() >= 0.0 and h.max() < 360.0
    with pytest.raises(WorkbenchError, match="3 components"):
        C.rgb_to_hsi(np.zeros((4, 4)))
    with pytest.raises(WorkbenchError, match="3 components"):
        C.hsi_to_rgb(np.zeros(2))


def test_convert_goes_through_rgb_between_any_two_spaces():
    rgb = np.array([0.6, 0.2, 0.4])
    np.testing.assert_allclose(C.convert(rgb, "rgb", "hsi"), [330, 0.5, 0.4], atol=1e-12)
    for name in C.SPACES:
        there = C.convert(rgb, "rgb", name)
        assert there.shape[-1] == len(C.space_labels(name))
        np.testing.assert_allclose(C.convert(there, name, "hsi"), [330, 0.5, 0.4], atol=1e-9)
    with pytest.raises(WorkbenchError, match="unknown colour space 'hsx'"):
        C.convert(rgb, "rgb", "hsx")


# ------------------------------------------------------------------ the console script


def _workbench(*args, cwd):
    return subprocess.run([WORKBENCH, *args], capture_output=True, text=True, cwd=cwd, timeout=120)


def test_convert_to_hsi(tmp_path):
    p = _workbench("colour", "convert", "0.6", "0.2", "0.4", "--to", "hsi", cwd=tmp_path)
    assert p.returncode == 0 and p.stderr == "", p.stderr
    assert p.stdout == "hsi   H 330 deg  S 0.5  I 0.4\n"


def test_convert_to_every_space_lists_hsi_beside_hsv_and_hsl(tmp_path):
    p = _workbench("color", "convert", "0", "0", "1", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    lines = {ln.split()[0]: ln for ln in p.stdout.splitlines()}
    assert list(lines) == list(C.SPACES)
    assert lines["hsi"] == "hsi   H 240 deg  S 1  I 0.333333"
    assert lines["hsv"] == "hsv   H 240 deg  S 1  V 1"
    assert lines["hsl"] == "hsl   H 240 deg  S 1  L 0.5"


def test_convert_from_hsi_reports_a_colour_outside_the_cube(tmp_path):
    p = _workbench("colour", "convert", "0", "1", "0.5", "--from", "hsi", "--to", "rgb", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    first, note = p.stdout.splitlines()
    assert first == "rgb   R 1.5  G 0  B 0"
    assert "outside the RGB cube" in note and "unclipped" in note and "1, 0, 0" in note
    inside = _workbench("colour", "convert", "60", "1", "0.5", "--from", "hsi", "--to", "rgb", cwd=tmp_path)
    assert inside.stdout == "rgb   R 0.75  G 0.75  B 0\n"


@pytest.mark.parametrize("args, words", [
    (["1", "2", "--to", "hsi"], ["--from rgb takes 3 components", "got 2"]),
    (["0", "1", "0.5", "0.1", "--from", "hsi"], ["--from hsi takes 3 components", "H S I"]),
    (["nan", "0", "0", "--to", "hsi"], ["finite number", "'nan'"]),
    (["1", "x", "0", "--to", "hsi"], ["expected a number", "'x'"]),
    (["1", "0", "0", "--to", "hsx"], ["--to 'hsx' is not a colour space", "hsi"]),
    (["1", "0", "0", "--from", "tsl"], ["--from 'tsl' is not a colour space", "hsi"]),
])
def test_bad_input_is_one_line_and_exit_2(args, words, tmp_path):
    p = _workbench("colour", "convert", *args, cwd=tmp_path)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2 and p.stdout == "", (p.stdout, p.stderr)
    assert len(lines) == 1 and lines[0].startswith("workbench: error: "), p.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])


def test_the_help_names_every_space(tmp_path):
    p = _workbench("colour", "convert", "--help", cwd=tmp_path)
    assert p.returncode == 0
    for name in C.SPACES:
        assert name in p.stdout, name
