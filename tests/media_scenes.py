"""A hypertexture alone against a black background, no light and no ambient (what the media
tests render: the emission-absorption march, its raster twin, the tracking), as TOML text."""
from __future__ import annotations


def medium_toml(*, distance: float, resolution: tuple[int, int], name: str = "medium", **keys) -> str:
    """The scene with the camera ``distance`` from the medium's centre (fov 30 degrees) and the
    hypertexture's ``keys`` (values as TOML text: ``noise='"none"'``, ``size=0.6``)."""
    obj = "\n".join(f"{k} = {v}" for k, v in keys.items())
    return f"""
[scene]
name = "{name}"
background = [0.0, 0.0, 0.0]
ambient = [0.0, 0.0, 0.0]
[camera]
position = [0.0, 0.0, {-distance}]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
resolution = [{resolution[0]}, {resolution[1]}]
[materials.m]
color = [1.0, 1.0, 1.0]
[[objects]]
type = "hypertexture"
material = "m"
base = "sphere"
{obj}
"""
