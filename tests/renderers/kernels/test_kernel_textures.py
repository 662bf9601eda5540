"""The numba texture maps (:mod:`workbench.renderers.kernels.textures`) against the numpy
reference (:mod:`workbench.renderers.texturing`) on random points: every colour pattern under
every projection, image textures, every bump kind, every opacity kind and both environments."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numba as nb
import numpy as np
import pytest

from workbench.renderers import texturing
from workbench.renderers.kernels.textures import alpha, bump_normal, environment, texture_color
from workbench.renderers.raytrace.maps import texture_tables
from workbench.scene.model import Bump, Environment, Material, Opacity, Texture

ASSETS = Path(__file__).resolve().parents[3] / "scenes" / "assets"
EARTH, SKY = str(ASSETS / "earth_latlong.png"), str(ASSETS / "sky_latlong.png")
N = 400
TOL = 1e-9


@nb.njit
def _evaluate(tx, xf, P, uv, D, bg, col, nrm, alp, env):
    for i in range(P.shape[0]):
        x, y, z = P[i, 0], P[i, 1], P[i, 2]
        if tx.color[0, 0] > 0:
            col[i, 0], col[i, 1], col[i, 2] = texture_color(tx, 0, 0, x, y, z, uv[i, 0], uv[i, 1])
        if tx.bump[0, 0] > 0:
            nrm[i, 0], nrm[i, 1], nrm[i, 2] = bump_normal(tx, xf, 0, 0, x, y, z, tx.has_uv[0],
                                                          nrm[i, 0], nrm[i, 1], nrm[i, 2])
        if tx.opacity[0, 0] > 0:
            alp[i] = alpha(tx, 0, 0, x, y, z, uv[i, 0], uv[i, 1])
        env[i, 0], env[i, 1], env[i, 2] = environment(tx, D[i, 0], D[i, 1], D[i, 2], bg)


def _points(seed):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(N, 3)) * 1.7
    P[:7] = [[0, 1, 0], [0, -1, 0], [0, 0, 0], [-1, 0, 0], [-1, 0, 1e-17], [1e-300, 2, 0], [0.3, 0, -2]]  # poles, seam
    D = rng.normal(size=(N, 3))
    D[:3] = [[0, 1, 0], [0, -1, 0], [0, 0, -1]]
    W = np.eye(4)
    W[:3, :3] = rng.normal(size=(3, 3)) + 2 * np.eye(3)
    W[:3, 3] = rng.normal(size=3)
    return P, rng.uniform(-2, 3, size=(N, 2)), D, W, rng.normal(size=(N, 3))


def _both(material, env=None, mesh_uv=False, seed=0):
    """(numba, numpy) colour, bumped normal, alpha and environment radiance at random points."""
    P, uv, D, W, Nw = _points(seed)
    sd = SimpleNamespace(materials=[material], has_uv=np.array([mesh_uv]))
    tx = texture_tables(SimpleNamespace(environment=env), sd)
    xf = np.ascontiguousarray(np.linalg.inv(W)[:3].reshape(1, 12))
    col, nrm, alp, rad = np.zeros((N, 3)), Nw.copy(), np.ones(N), np.zeros((N, 3))
    bg = np.array([0.1, 0.2, 0.3])
    _evaluate(tx, xf, P, uv, D, bg, col, nrm, alp, rad)
    u = uv if mesh_uv else None
    ref = dict(env=texturing.environment(env, D) if env is not None else np.broadcast_to(bg, D.shape))
    if material.texture is not None:
        ref["col"] = texturing.texture_color(material.texture, P, u)
    if material.bump is not None:
        ref["nrm"] = texturing.bump_normal(material, P, Nw, Nw, W, u)
    if material.opacity is not None:
        ref["alp"] = texturing.alpha(material, P, Nw, u)
    return dict(col=col, nrm=nrm, alp=alp, env=rad), ref


def _check(got, ref):
    for key, want in ref.items():
        assert np.isfinite(got[key]).all(), key
        assert np.abs(got[key] - want).max() <= TOL, (key, np.abs(got[key] - want).max())


FRAME = dict(center=(0.2, -0.1, 0.3), pole=(0.3, 1.0, -0.2), equator=(1.0, 0.2, 0.4))
PROJECTIONS = ("planar", "cylindrical", "spherical", "solid", "uv")


@pytest.mark.parametrize("kind", ["checker", "bricks", "grid", "marble", "wood"])
@pytest.mark.parametrize("projection", PROJECTIONS)
def test_patterns_match_the_reference(kind, projection):
    tex = Texture(kind, projection=projection, scale=2.5, colors=((0.9, 0.5, 0.1), (0.1, 0.3, 0.8)), mortar=0.11,
                  **FRAME)
    _check(*_both(Material("m", texture=tex)))


@pytest.mark.parametrize("projection, mesh_uv", [("planar", False), ("spherical", False), ("uv", True),
                                                 ("uv", False), ("cylindrical", False)])
def test_image_textures_match_the_reference(projection, mesh_uv):
    tex = Texture("image", projection=projection, scale=1.5, path=EARTH, **FRAME)
    _check(*_both(Material("m", texture=tex), mesh_uv=mesh_uv))


@pytest.mark.parametrize("kind, path", [("bricks", None), ("noise", None), ("waves", None), ("image", EARTH)])
@pytest.mark.parametrize("projection", ["planar", "spherical", "solid", "uv"])
def test_bump_maps_match_the_reference(kind, path, projection):
    if kind == "image" and projection == "solid":
        return
    bump = Bump(kind, projection=projection, scale=3.0, strength=0.7, path=path, mortar=0.1, **FRAME)
    _check(*_both(Material("m", bump=bump)))


def test_a_uv_bump_on_a_mesh_with_uvs_leaves_the_normal():
    _check(*_both(Material("m", bump=Bump("waves", projection="uv")), mesh_uv=True))


def _rgba(tmp_path):
    from PIL import Image
    rng = np.random.default_rng(5)
    path = tmp_path / "cutout.png"
    Image.fromarray(rng.integers(0, 256, size=(9, 13, 4), dtype=np.uint8), "RGBA").save(path)
    texturing.image.cache_clear()
    texturing.has_alpha.cache_clear()
    return str(path)


@pytest.mark.parametrize("kind", ["constant", "grid", "checker", "image", "image_alpha"])
def test_opacity_maps_match_the_reference(kind, tmp_path):
    path = _rgba(tmp_path) if kind == "image_alpha" else EARTH
    op = Opacity(kind.split("_")[0], value=0.35, projection="planar", scale=2.0, path=path, width=0.3, **FRAME)
    _check(*_both(Material("m", opacity=op), mesh_uv=False))


@pytest.mark.parametrize("env", [Environment("sky", zenith=(0.1, 0.2, 0.9), horizon=(0.9, 0.8, 0.7),
                                             ground=(0.3, 0.2, 0.1)), Environment("image", path=SKY)])
def test_environments_match_the_reference(env):
    _check(*_both(Material("m"), env=env))
