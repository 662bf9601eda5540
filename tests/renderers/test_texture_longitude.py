"""Texture longitude runs eastward (DESIGN errata 8): a lat-long image whose western half
(u < 0.5) is red and eastern half (u > 0.5) green, mapped on a sphere, shows green at
longitude +90 degrees and red at -90 in every method."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.core.imageio import save_png
from workbench.renderers import texturing as tx
from workbench.scene.io import scene_from_dict

RED, GREEN = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
# pole y, equator x: the prime meridian (u = 0.5) at +x; east is counter-clockwise seen from
# +y (the right-hand rule about the pole), so longitude +90 is at -z and -90 at +z
EAST_90, WEST_90 = np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def halves(tmp_path_factory) -> str:
    img = np.zeros((32, 64, 3))
    img[:, :32] = RED
    img[:, 32:] = GREEN
    path = tmp_path_factory.mktemp("latlong") / "halves.png"
    save_png(path, img)
    return str(path)


def _scene(path: str, projection: str, eye) -> object:
    return scene_from_dict({
        "scene": {"background": [0.0, 0.0, 0.0], "ambient": [1.0, 1.0, 1.0]},
        "camera": {"position": list(4.0 * eye), "look_at": [0, 0, 0], "fov_y": 10.0, "resolution": [9, 9]},
        "materials": {"m": {"color": [1, 1, 1], "ka": 1.0, "kd": 0.0,
                            "texture": {"type": "image", "path": path, "projection": projection,
                                        "pole": [0, 1, 0], "equator": [1, 0, 0]}}},
        "lights": [],
        "objects": [{"type": "sphere", "radius": 1.0, "material": "m"}]})


@pytest.mark.parametrize("projection", ["spherical", "cylindrical"])
def test_reference_longitude_increases_eastward(projection):
    class M:
        center, pole, equator = (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)
    M.projection = projection
    lon = np.radians([-135.0, -90.0, -45.0, 0.0, 45.0, 90.0, 135.0])
    # longitude lambda about +y from +x: x cos(lambda) - z sin(lambda) (counter-clockwise seen from +y)
    d = np.stack([np.cos(lon), np.zeros_like(lon), -np.sin(lon)], -1)
    u = tx.project(M, d)[:, 0]
    assert np.all(np.diff(u) > 0.0), u
    assert np.allclose(u, 0.5 + lon / (2.0 * np.pi), atol=1e-12)


@pytest.mark.gl
@pytest.mark.parametrize("method", ["raycast", "raytrace", "phong", "gouraud"])
@pytest.mark.parametrize("projection", ["spherical", "cylindrical"])
def test_known_image_samples_east_and_west_in_every_method(halves, method, projection):
    for eye, want in ((EAST_90, GREEN), (WEST_90, RED)):
        img = workbench.render(_scene(halves, projection, eye), method).image
        c = img[4, 4]  # the pixel on the line of sight: the point at longitude +-90
        assert np.abs(c - want).max() <= 0.05, (method, eye, c)
