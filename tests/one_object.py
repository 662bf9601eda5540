"""A scene file with one object of material ``m`` in front of the camera, for load checks of
one kind (written to a file and loaded: the same path as a user's scene)."""
from __future__ import annotations

HEAD = """[camera]
position = [0, 0, 6]
look_at = [0, 0, 0]
fov_y = 40.0
resolution = [32, 24]

[materials.m]
color = [0.8, 0.8, 0.8]

[[lights]]
type = "point"
position = [2, 3, 6]

[[objects]]
material = "m"
"""


def scene_text(obj: str) -> str:
    """The scene with the object's keys ``obj`` (TOML lines, without ``material``)."""
    return HEAD + obj + "\n"
