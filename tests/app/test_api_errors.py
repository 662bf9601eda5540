"""The public Python API answers bad arguments with a WorkbenchError whose message is the one line
the CLI prints (no other exception type, no numpy repr, no newline)."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.core.errors import WorkbenchError


@pytest.fixture(scope="module")
def scene():
    return workbench.load_scene("whitted")


CASES = {
    "load_scene: missing file": lambda s: workbench.load_scene("/nonexistent/scene.toml"),
    "load_scene: not a path": lambda s: workbench.load_scene(5),
    "render: unknown method": lambda s: workbench.render(s, "nosuch"),
    "render: negative width": lambda s: workbench.render(s, "phong", width=-1, height=4),
    "render: unknown option": lambda s: workbench.render(s, "phong", nosuch=1),
    "render: option below its range": lambda s: workbench.render(s, "raytrace", width=8, height=6, threshold=-1.0),
    "render: a name, not a scene": lambda s: workbench.render("whitted", "phong", width=8, height=6),
    "metrics: shapes differ": lambda s: workbench.compare.metrics(np.zeros((4, 4, 3)), np.zeros((5, 4, 3))),
    "metrics: NaN": lambda s: workbench.compare.metrics(np.full((4, 4, 3), np.nan), np.zeros((4, 4, 3))),
    "intersect: not (N, 3)": lambda s: workbench.raytrace.intersect(s, np.zeros((3, 2)), np.zeros((3, 3))),
    "form_factors: nothing": lambda s: workbench.radiosity.form_factors([], method="hemicube"),
    "solve: unknown solver": lambda s: workbench.radiosity.solve(np.eye(2), np.ones(2), np.ones(2), method="nosuch"),
    "solve: sizes differ": lambda s: workbench.radiosity.solve(np.eye(2), np.ones(3), np.ones(2)),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_api_call_is_one_workbench_error_line(case, scene):
    with pytest.raises(WorkbenchError) as e:
        CASES[case](scene)
    text = str(e.value)
    assert text and "\n" not in text and "np." not in text, text
