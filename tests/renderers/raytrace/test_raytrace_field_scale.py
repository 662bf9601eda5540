"""Implicit kinds are invariant under a scaling of their field (issue 26, item 4): a blob whose
strengths and threshold are multiplied by 1e30 (or 1e-30), and an isosurface whose function,
threshold and gradient bound are, define the same surface and render, in raytrace, the image
of factor 1 (shadow feelers included: no self-shadowing acne).  Bound: 4 of the 48 x 36
pixels may differ by more than 0.05 (a grazing ray at a silhouette)."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.renderers.base import render
from workbench.scene.io import scene_from_dict


def _object(kind: str, k: float) -> dict:
    if kind == "blob":
        return {"type": "blob", "threshold": 0.3 * k, "components": [
            {"center": [-0.4, 0.0, 0.0], "radius": 0.9, "strength": k},
            {"center": [0.5, 0.1, 0.0], "radius": 0.8, "strength": 1.5 * k},
            {"center": [0.0, 0.6, 0.2], "radius": 0.5, "strength": -0.5 * k}]}
    return {"type": "isosurface", "function": f"{k!r} * ((sqrt(x^2 + z^2) - 0.8)^2 + y^2)",
            "threshold": 0.09 * k, "max_gradient": 5.0 * k,
            "bounds": {"min": [-1.2, -0.35, -1.2], "max": [1.2, 0.35, 1.2]}, "transform": {"rotate": [-30, 0, 0]}}


def _scene(kind: str, k: float):
    return scene_from_dict({
        "scene": {"name": "field", "background": [0.2, 0.3, 0.5], "ambient": [0.15, 0.15, 0.15]},
        "camera": {"position": [0, 1, -5], "look_at": [0, 0, 0], "fov_y": 40.0, "resolution": [48, 36]},
        "lights": [{"type": "point", "position": [-3, 5, -3], "intensity": 0.9}],
        "materials": {"m": {"color": [0.8, 0.3, 0.2], "ka": 0.2, "kd": 0.7, "ks": 0.3, "shininess": 30.0}},
        "objects": [{**_object(kind, k), "material": "m"}]}, source="field")


@pytest.mark.parametrize("kind", ["blob", "isosurface"])
def test_scaled_field_renders_the_same_surface(kind):
    ref = render(_scene(kind, 1.0), "raytrace").image
    assert (np.abs(ref - np.array([0.2, 0.3, 0.5])).max(-1) > 0.05).sum() > 100  # the object is seen
    for k in (1e30, 1e-30):
        img = render(_scene(kind, k), "raytrace").image
        assert np.isfinite(img).all()
        off = int((np.abs(img - ref).max(-1) > 0.05).sum())
        assert off <= 4, (kind, k, off)
