"""A CSG tree deeper than the kernels' interval-list stack is refused with a clear message
(numba does not check bounds: it would write past its scratch arrays)."""
from __future__ import annotations

import pytest

import workbench
from workbench.scene.io import scene_from_dict


def _chain(n: int) -> dict:
    node = {"type": "sphere", "radius": 0.3, "center": [0.1 * n, 0, 0]}
    for k in range(n - 1):
        node = {"type": "csg", "op": "union", "left": {"type": "sphere", "radius": 0.3,
                                                         "center": [0.1 * k, 0, 0]}, "right": node}
    node["material"] = "m"
    return {"camera": {"position": [0, 0, -5], "look_at": [0, 0, 0], "resolution": [8, 8]},
            "materials": {"m": {}}, "objects": [node]}


def test_deep_right_nested_csg_is_refused():
    with pytest.raises(workbench.WorkbenchError, match="interval lists"):
        workbench.render(scene_from_dict(_chain(24)), "raycast")


def test_csg_within_the_stack_renders():
    r = workbench.render(scene_from_dict(_chain(8)), "raycast")
    assert r.image.max() > 0 and r.stats["nonfinite_pixels"] == 0
