"""Cross-method: ``raycast`` of an analytic sphere with the shared local model is the limit of
the GLSL ``phong`` method on finer and finer tessellations of that sphere."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.scene.io import scene_from_dict


@pytest.mark.gl
def test_phong_converges_to_raycast_as_tessellation_grows(gl_ctx):
    sc = scene_from_dict({
        "scene": {"background": [0.0, 0.0, 0.0], "ambient": [0.2, 0.2, 0.2]},
        "camera": {"position": [0, 0, -5], "look_at": [0, 0, 0], "fov_y": 35.0, "resolution": [96, 96]},
        "materials": {"m": {"color": [0.9, 0.5, 0.2], "ka": 0.3, "kd": 0.7, "ks": 0.4, "shininess": 30.0}},
        "lights": [{"type": "point", "position": [3, 4, -5], "intensity": 0.9}],
        "objects": [{"type": "sphere", "radius": 1.3, "material": "m"}]})
    exact = workbench.render(sc, "raycast").image
    rmse = []
    for level in (2, 4, 8, 16):
        img = workbench.render(sc, "phong", tessellation=level).image
        rmse.append(float(np.sqrt(np.mean((img - exact) ** 2))))
    # stated error (measured: RMSE 0.027, 0.013, 5.1e-4, 1.3e-4 at levels 2, 4, 8, 16): the
    # silhouette and the interpolated normals converge as the polygons shrink
    assert all(b < a for a, b in zip(rmse, rmse[1:])), rmse
    assert rmse[0] < 0.05 and rmse[-1] < 5e-4, rmse
