"""Pixels covered by some object, as each method sees them (test helper).

Coverage is where the method's ``RenderResult.depth`` is finite: the ray caster's primary hit,
the raster methods' depth buffer.  Scenes are written with a black background and no
environment, so the colour plays no part.
"""
from __future__ import annotations

import numpy as np

import workbench


def coverage(scene, method: str, width: int, height: int, **options) -> np.ndarray:
    """(H, W) bool: the pixels where ``method`` saw an object."""
    r = workbench.render(scene, method, width=width, height=height, **options)
    assert r.depth is not None, f"{method} gives no depth"
    assert np.isfinite(r.image).all(), f"{method}: non-finite pixels"
    return np.isfinite(r.depth)


def iou(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two masks (1 when both are empty)."""
    union = np.logical_or(a, b).sum()
    return 1.0 if union == 0 else float(np.logical_and(a, b).sum() / union)


def scene_dict(objects, *, camera=None, materials=None, lights=None) -> dict:
    """A scene dictionary around ``objects`` (black background, one white material ``m``)."""
    return {
        "scene": {"background": [0.0, 0.0, 0.0], "ambient": [0.2, 0.2, 0.2]},
        "camera": camera or {"position": [0, 0, 6], "look_at": [0, 0, 0], "fov_y": 40.0,
                             "resolution": [64, 48]},
        "materials": materials or {"m": {"color": [0.8, 0.8, 0.8], "ka": 0.2, "kd": 0.7}},
        "lights": lights if lights is not None else [{"type": "point", "position": [2, 3, 6]}],
        "objects": objects,
    }
