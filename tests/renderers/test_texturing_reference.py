"""The numpy texturing reference: projections against the course's formulas, poles and seams,
patterns, noise, bump and environment."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.core import noise

from workbench.renderers import texturing as tx
from workbench.scene.model import Bump, Environment, Material, Opacity, Texture


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_spherical_matches_course_formula_away_from_poles():
    rng = np.random.default_rng(1)
    N = _unit(rng, 500)
    pole, eq = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    N = N[np.abs(N @ pole) < 0.95]
    tex = Texture("checker", projection="spherical", pole=tuple(pole), equator=tuple(eq))
    uv = tx.project(tex, N)
    phi = np.arccos(-(N @ pole))  # course: phi = arccos(-N.Sp), v = phi / pi
    theta = np.arccos(np.clip(-(N @ eq) / np.sin(phi), -1, 1)) / (2 * np.pi)
    u_course = np.where(N @ np.cross(pole, eq) > 0, theta, 1 - theta)
    u = 1.0 - u_course  # DESIGN errata 8: the course's u runs clockwise seen from the pole
    assert np.allclose(uv[:, 1], phi / np.pi, atol=1e-12)
    assert np.allclose(uv[:, 0], u, atol=1e-7)


def test_spherical_poles_and_seam_are_finite_and_wrapped():
    tex = Texture("checker", projection="spherical")
    seam = np.array([[-1.0, 0.0, -1e-17], [-1.0, 0.0, 1e-17], [-1.0, 0.0, 0.0]])
    poles = np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1e-300, 1.0, 0.0], [0.0, 0.0, 0.0]])
    uv = tx.project(tex, np.vstack([seam, poles]))
    assert np.isfinite(uv).all()
    assert (uv[:, 0] >= 0).all() and (uv[:, 0] < 1).all()
    assert np.allclose(uv[3:5, 1], [1.0, 0.0])
    col = tx.surface_color(Material("m", texture=tex), np.vstack([seam, poles]), seam.repeat(3, 0)[:7])
    assert np.isfinite(col).all()


def test_planar_with_z_pole_is_object_xy():
    tex = Texture("checker", projection="planar", pole=(0, 0, 1), equator=(1, 0, 0))
    P = np.random.default_rng(2).normal(size=(20, 3))
    assert np.allclose(tx.project(tex, P), P[:, :2])


def test_checker_parity_and_colours():
    tex = Texture("checker", projection="planar", pole=(0, 0, 1), colors=((1, 0, 0), (0, 0, 1)))
    P = np.array([[0.5, 0.5, 0], [1.5, 0.5, 0], [-0.5, 0.5, 0], [1.5, 1.5, 3.0]])
    c = tx.texture_color(tex, P)
    assert np.allclose(c, [[1, 0, 0], [0, 0, 1], [0, 0, 1], [1, 0, 0]])


def test_noise_deterministic_in_range_and_continuous():
    p = np.random.default_rng(3).uniform(-50, 50, size=(2000, 3))
    a, b = tx.value_noise(p), tx.value_noise(p.copy())
    assert np.array_equal(a, b)
    assert a.min() >= 0 and a.max() < 1 and a.std() > 0.1
    # continuity: a 1e-6 move changes the value by O(1e-6)
    assert np.abs(tx.value_noise(p + 1e-6) - a).max() < 1e-4
    # lattice points take the hash value exactly
    ip = np.floor(p)
    assert np.allclose(tx.value_noise(ip), noise._hash3(*ip.astype(np.int64).T))


def test_bricks_mortar_fraction():
    tex = Texture("bricks", projection="planar", pole=(0, 0, 1), mortar=0.1)
    P = np.random.default_rng(4).uniform(0, 10, size=(40000, 3))
    frac = tx.pattern_value("bricks", tx.pattern_coords(tex, P), tex.mortar).mean()
    # mortar lines 0.1 wide: 10 % of a 1-wide brick, 20 % of a 0.5-high row
    assert frac == pytest.approx(1 - 0.9 * 0.8, abs=0.01)


def test_bump_waves_gradient_is_analytic():
    bump = Bump("waves", projection="planar", pole=(0, 0, 1), scale=1.0, strength=0.1)
    mat = Material("m", bump=bump)
    P = np.random.default_rng(5).uniform(-1, 1, size=(50, 3))
    P[:, 2] = 0
    N = np.tile([0.0, 0.0, 1.0], (50, 1))
    Np = tx.bump_normal(mat, P, N, N, np.eye(4))
    # d = 0.1 * (0.5 + 0.25 (sin 2pi x + sin 2pi y)); grad d = 0.1*0.25*2pi (cos 2pi x, cos 2pi y)
    g = 0.1 * 0.25 * 2 * np.pi * np.stack([np.cos(2 * np.pi * P[:, 0]), np.cos(2 * np.pi * P[:, 1]), 0 * P[:, 0]], -1)
    expect = (N - g) / np.linalg.norm(N - g, axis=1, keepdims=True)
    assert np.allclose(Np, expect, atol=2e-3)  # forward differences: O(step) = O(1e-3)


def test_bump_respects_object_scale():
    """A world transform that stretches x by 2 halves the world gradient along x."""
    bump = Bump("waves", projection="planar", pole=(0, 0, 1), strength=0.1)
    mat = Material("m", bump=bump)
    P = np.array([[0.0, 0.25, 0.0]])  # cos(0)=1 along x, cos(pi/2)=0 along y
    N = np.array([[0.0, 0.0, 1.0]])
    M = np.diag([2.0, 1.0, 1.0, 1.0])
    n1 = tx.bump_normal(mat, P, N, N, np.eye(4))
    n2 = tx.bump_normal(mat, P, N, N, M)
    assert n2[0, 0] / n2[0, 2] == pytest.approx(0.5 * n1[0, 0] / n1[0, 2], rel=1e-3)


def test_opacity_grid_and_constant():
    m = Material("m", opacity=Opacity("grid", projection="planar", pole=(0, 0, 1), width=0.2))
    a = tx.alpha(m, np.array([[0.1, 0.5, 0], [0.5, 0.5, 0], [0.5, 0.05, 0]]), None)
    assert np.array_equal(a, [1.0, 0.0, 1.0])
    assert np.allclose(tx.alpha(Material("c", opacity=Opacity("constant", value=0.7)), np.zeros((3, 3)), None), 0.7)


def test_environment_sky_and_latlong():
    env = Environment(zenith=(0, 0, 1), horizon=(1, 1, 1), ground=(0.2, 0.1, 0))
    c = tx.environment(env, np.array([[0, 1.0, 0], [1.0, 0, 0], [0, -1.0, 0]]))
    assert np.allclose(c, [[0, 0, 1], [1, 1, 1], [0.2, 0.1, 0]])
    d = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0, 0]])
    uv = tx.latlong_uv(d)
    assert np.isfinite(uv).all()
    assert np.allclose(uv, [[0.5, 0.5], [0.5, 1.0], [0.5, 0.0], [0.75, 0.5]])


def test_image_sampling_texel_centres_and_wrap():
    img = np.zeros((2, 4, 4), dtype=np.float32)
    img[1, 0] = 1.0  # bottom-left texel (v = 0 at the bottom row)
    uv = np.array([[0.125, 0.25], [0.0, 0.25], [1.0, 0.25]])
    s = tx.sample_image(img, uv)
    assert s[0, 0] == pytest.approx(1.0)
    assert s[1, 0] == pytest.approx(0.5) and s[2, 0] == pytest.approx(0.5)  # halfway to the wrapped texel


@pytest.mark.parametrize("kind", ["marble", "wood"])
def test_solid_textures_vary_and_stay_between_colours(kind):
    tex = Texture(kind, projection="solid", scale=2.0, colors=((1, 1, 1), (0.2, 0.1, 0.0)))
    P = np.random.default_rng(6).uniform(-1, 1, size=(3000, 3))
    c = tx.texture_color(tex, P)
    assert np.isfinite(c).all() and c.std(0).max() > 0.1
    assert (c <= 1 + 1e-12).all() and (c >= -1e-12).all()


def test_height_and_opacity_maps_are_data_colour_maps_are_srgb(tmp_path):
    # a uniform grey of 8-bit level 128: a colour map means linear 0.216 (sRGB decoded); a height or
    # opacity map holds values, 128 / 255 = 0.502, not a colour to decode
    from PIL import Image
    path = str(tmp_path / "grey.png")
    Image.fromarray(np.full((4, 4, 3), 128, dtype=np.uint8)).save(path)
    P = np.array([[0.3, 0.4, 0.0], [0.7, 0.1, 0.0]])
    common = dict(projection="planar", pole=(0, 0, 1), equator=(1, 0, 0), path=path)
    colour = tx.texture_color(Texture("image", **common), P)
    assert np.allclose(colour, 0.2158605, atol=1e-5)
    assert np.allclose(tx.height(Bump("image", **common), P), 128 / 255, atol=1e-6)
    m = Material("m", opacity=Opacity("image", **common))
    assert np.allclose(tx.alpha(m, P, np.tile([0.0, 0.0, 1.0], (2, 1)), None), 128 / 255, atol=1e-6)
