"""Generate the bundled texture images (deterministic; run from the repository root):

    .venv/bin/python scenes/assets/make_assets.py

* ``earth_latlong.png`` (256 x 128): an "earth-like" lat-long map for the globe scene: oceans,
  continents from fractal value noise on the unit sphere (so the map has no seam), ice caps.
  Row 0 is the north pole (v = 1 of the spherical projection), column 0 is u = 0.
* ``sky_latlong.png`` (256 x 128): a lat-long environment with a sky gradient, noisy clouds,
  a sun and a ground of two tones, for the environment-mapping scene.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from workbench.core.imageio import save_png
from workbench.renderers import texturing as tx

HERE = Path(__file__).resolve().parent


def _directions_globe(w: int, h: int) -> np.ndarray:
    """Unit directions of pixel centres under the spherical projection (pole y, equator x)."""
    u = (np.arange(w) + 0.5) / w
    v = 1.0 - (np.arange(h) + 0.5) / h
    U, V = np.meshgrid(u, v)
    phi = V * np.pi  # 0 at the -pole
    theta = U * 2.0 * np.pi
    # inverse of texturing.project: d.Sp = -cos(phi), d.(-Se) = sin(phi) cos(theta),
    # d.(-W) = sin(phi) sin(theta) (u increases eastward, DESIGN errata 8)
    sp, se, w_ = tx.frame((0.0, 1.0, 0.0), (1.0, 0.0, 0.0))
    d = (-np.cos(phi)[..., None] * sp - (np.sin(phi) * np.cos(theta))[..., None] * se
         - (np.sin(phi) * np.sin(theta))[..., None] * w_)
    return d.reshape(-1, 3)


def earth(w: int = 256, h: int = 128) -> np.ndarray:
    d = _directions_globe(w, h)
    n = tx.fbm(2.2 * d + 10.0) + 0.5 * tx.fbm(6.0 * d - 3.0)
    lat = np.abs(d[:, 1])
    ocean = np.array([0.02, 0.08, 0.3]) * (1.0 + 0.6 * np.clip(n + 0.3, 0, 1))[:, None]
    green = np.array([0.08, 0.3, 0.05])
    desert = np.array([0.55, 0.42, 0.2])
    dry = np.clip((1.0 - 2.5 * np.abs(lat - 0.35)) * 2.0 + tx.fbm(9.0 * d) * 2.0, 0, 1)[:, None]
    land = green * (1 - dry) + desert * dry
    img = np.where((n > 0.08)[:, None], land, ocean)
    ice = (lat + 0.1 * tx.fbm(5.0 * d) > 0.95)[:, None]
    img = np.where(ice, np.array([0.85, 0.88, 0.9]), img)
    return img.reshape(h, w, 3)


def sky(w: int = 256, h: int = 128) -> np.ndarray:
    u = (np.arange(w) + 0.5) / w
    v = 1.0 - (np.arange(h) + 0.5) / h
    U, V = np.meshgrid(u, v)
    lon = (U - 0.5) * 2 * np.pi
    lat = (V - 0.5) * np.pi
    # inverse of texturing.latlong_uv: u = 0.5 + atan2(x, -z) / 2pi, v = 0.5 + asin(y) / pi
    d = np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)], -1).reshape(-1, 3)
    y = d[:, 1:2]
    base = tx.environment(tx.Environment(zenith=(0.15, 0.3, 0.85), horizon=(0.8, 0.85, 0.95),
                                         ground=(0.3, 0.25, 0.2)), d)
    clouds = np.clip(2.5 * tx.fbm(np.c_[3 * d[:, 0], 8 * d[:, 1], 3 * d[:, 2]]) + 0.2, 0, 1)[:, None]
    base = np.where(y > 0, base * (1 - 0.7 * clouds) + 0.9 * clouds * 0.7, base)
    checker = ((np.floor(4 * d[:, 0] / np.maximum(-y[:, 0], 0.05)) + np.floor(4 * d[:, 2] / np.maximum(-y[:, 0], 0.05))) % 2)[:, None]
    base = np.where(y < -0.02, base * (0.7 + 0.5 * checker), base)
    sun_dir = np.array([0.5, 0.6, -0.62]) / np.linalg.norm([0.5, 0.6, -0.62])
    sun = (d @ sun_dir > 0.995)[:, None]
    return np.where(sun, 8.0, base).reshape(h, w, 3)


if __name__ == "__main__":
    save_png(HERE / "earth_latlong.png", earth())
    save_png(HERE / "sky_latlong.png", sky())
    print("wrote", HERE / "earth_latlong.png", HERE / "sky_latlong.png")
