"""The scene's texture maps as the numba kernels read them (:class:`..kernels.textures.Textures`):
a row per material in each of the colour, bump and opacity tables (columns
:class:`..kernels.columns.Tex`), the environment row (:class:`..kernels.columns.Env`) and every
image's RGBA pixels in one flat array, as :mod:`workbench.renderers.texturing` loads them
(colour images sRGB-decoded, bump and opacity images as stored)."""
from __future__ import annotations

import numpy as np

from ...core.columns import pack
from ...core.tol import tol
from ...scene.model import Scene
from ..kernels.columns import (ENV_IMAGE, ENV_NONE, ENV_SKY, PROJ_CYLINDRICAL, PROJ_PLANAR, PROJ_SOLID,
                               PROJ_SPHERICAL, PROJ_UV, TEX_BRICKS, TEX_CHECKER, TEX_COLS, TEX_CONSTANT, TEX_GRID,
                               TEX_IMAGE, TEX_MARBLE, TEX_NOISE, TEX_WAVES, TEX_WOOD, Env, Tex)
from ..kernels.textures import Textures, textures_marker

KINDS = {"checker": TEX_CHECKER, "bricks": TEX_BRICKS, "grid": TEX_GRID, "marble": TEX_MARBLE, "wood": TEX_WOOD,
         "image": TEX_IMAGE, "noise": TEX_NOISE, "waves": TEX_WAVES, "constant": TEX_CONSTANT}
PROJECTIONS = {"planar": PROJ_PLANAR, "cylindrical": PROJ_CYLINDRICAL, "spherical": PROJ_SPHERICAL, "uv": PROJ_UV,
               "solid": PROJ_SOLID}


def checkers_only(scene: Scene, materials) -> bool:
    """Whether the scene's maps are at most ``checker`` colours with the ``planar`` or ``solid``
    projection (no other texture, bump, opacity map nor environment): the kernels then compile
    the checker alone (and the path tracer evaluates these only)."""
    return scene.environment is None and all(
        m.bump is None and m.opacity is None
        and (m.texture is None or (m.texture.kind == "checker" and m.texture.projection in ("planar", "solid")))
        for m in materials)


class _Images:
    """The flat pixel array being built: each image once (by path and kind)."""

    def __init__(self):
        self.parts: list[np.ndarray] = []
        self.at: dict[tuple, tuple[int, int, int]] = {}
        self.size = 0

    def add(self, path: str, data: bool) -> tuple[int, int, int]:
        """(offset, width, height) of the image in the array."""
        from .. import texturing
        key = (path, data)
        if key not in self.at:
            img = np.asarray(texturing.image(path, data), dtype=np.float64)
            self.at[key] = (self.size, img.shape[1], img.shape[0])
            self.parts.append(img.reshape(-1))
            self.size += img.size
        return self.at[key]

    def array(self) -> np.ndarray:
        return np.concatenate(self.parts) if self.parts else np.zeros(4)


def _row(m, images: _Images, data: bool, **extra) -> np.ndarray:
    """The ``Tex`` row of a Texture, Bump or Opacity ``m``."""
    from ..texturing import frame
    sp, se, w = frame(m.pole, m.equator)
    off = wd = ht = 0
    if m.kind == "image":
        off, wd, ht = images.add(m.path, data)
    colors = getattr(m, "colors", ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
    return pack(Tex, kind=KINDS[m.kind], proj=PROJECTIONS[m.projection], scale=m.scale, center=m.center, sp=sp,
                se=se, w=w, color0=colors[0], color1=colors[1], image=off, image_w=wd, image_h=ht, **extra)


def texture_tables(scene: Scene, sd) -> Textures:
    """The :class:`Textures` record of a flattened scene ``sd`` (:class:`.flatten.SceneData`)."""
    from .. import texturing
    images = _Images()
    M = len(sd.materials)
    color, bump, opacity = np.zeros((M, TEX_COLS)), np.zeros((M, TEX_COLS)), np.zeros((M, TEX_COLS))
    for i, m in enumerate(sd.materials):
        if m.texture is not None:
            color[i] = _row(m.texture, images, False, width=m.texture.mortar, strength=0.0, value=0.0, alpha=0.0)
        if m.bump is not None:
            bump[i] = _row(m.bump, images, True, width=m.bump.mortar, strength=m.bump.strength, value=0.0, alpha=0.0)
        if m.opacity is not None:
            op = m.opacity
            has_alpha = op.kind == "image" and texturing.has_alpha(op.path)
            opacity[i] = _row(op, images, True, width=op.width, strength=0.0, value=op.value, alpha=has_alpha)
    env = scene.environment
    off = wd = ht = 0
    kind, horizon, zenith, ground = ENV_NONE, (0.0,) * 3, (0.0,) * 3, (0.0,) * 3
    if env is not None:
        kind, horizon, zenith, ground = ENV_SKY, env.horizon, env.zenith, env.ground
        if env.kind == "image":
            kind = ENV_IMAGE
            off, wd, ht = images.add(env.path, False)
    row = pack(Env, kind=kind, horizon=horizon, zenith=zenith, ground=ground, image=off, image_w=wd, image_h=ht,
               zero=tol.zero, bump_step=tol.bump_step)
    return Textures(color, bump, opacity, row, images.array(), np.ascontiguousarray(sd.has_uv, dtype=np.bool_),
                    textures_marker(not checkers_only(scene, sd.materials)))
