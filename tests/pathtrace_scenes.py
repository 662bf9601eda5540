"""Small scenes shared by the path tracer's tests (written to a TOML file and loaded, so they go
through the same validation as a user's scene)."""
from __future__ import annotations

import workbench

PLANE = """
[scene]
name = "plane"
background = [0.0, 0.0, 0.0]
ambient = [0.0, 0.0, 0.0]
[camera]
position = [0.0, 3.0, 4.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
resolution = [16, 12]
[materials.matte]
color = [1.0, 0.5, 0.25]
kd = 0.7
ka = 0.0
[[objects]]
type = "plane"
material = "matte"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
size = [40.0, 40.0]
"""


def scene(tmp_path, text, name="t"):
    """Load the scene ``text`` (TOML) through a file in ``tmp_path``."""
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return workbench.load_scene(str(p))
