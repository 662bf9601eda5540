"""Self-crossing 2D outlines (the kinds drawn from one: a lathe's linear profile, a prism's
polygon) are refused at load in one line naming the two segments that meet, through
``workbench.load_scene`` and the console script (exit 2); before, a lathe took any profile and
rendered an inside that depended on the method.  Simple outlines, convex or not, still load."""
from __future__ import annotations

import subprocess

import pytest

import workbench
from one_object import scene_text
from ui_command import WORKBENCH
from workbench.core.errors import WorkbenchError

BAD = {  # id -> (object keys, the words the line must hold)
    "lathe open, crossing": ('type = "lathe"\npoints = [[0.5, 0], [1, 1], [0.5, 1], [1, 0]]',
                             ["points", "segment 0 ([0.5, 0.0] -> [1.0, 1.0]) meets segment 2"]),
    "lathe closed by repeat, figure eight": ('type = "lathe"\npoints = [[0.5, 0], [1, 1], [0.5, 1], [1, 0], [0.5, 0]]',
                                             ["points", "segment 0", "segment 2"]),
    "lathe closed on the axis, folds back": ('type = "lathe"\npoints = [[0, 0], [1, 0], [1, 1], [1, 0.5], [0, 1]]',
                                             ["points", "segment 1", "segment 2"]),
    "prism bow tie": ('type = "prism"\npolygon = [[0, 0], [1, 0], [0, 1], [1, 1]]\nheights = [0, 1]',
                      ["polygon", "edge 1", "edge 3"]),
    "prism folds back": ('type = "prism"\npolygon = [[0, 0], [2, 0], [1, 0], [1, 1]]\nheights = [0, 1]',
                         ["polygon", "edge 0", "edge 1"]),
}
GOOD = {
    "lathe zigzag": 'type = "lathe"\npoints = [[0, 0], [1, 0], [0.2, 1], [1, 1], [0, 2]]',
    "lathe ring closed by repeat": 'type = "lathe"\npoints = [[0.5, 0], [1, 0], [1, 1], [0.5, 1], [0.5, 0]]',
    "prism concave": 'type = "prism"\npolygon = [[0, 0], [2, 0], [2, 2], [1, 1], [0, 2]]\nheights = [0, 1]',
}


def _write(tmp_path, obj):
    p = tmp_path / "s.toml"
    p.write_text(scene_text(obj), encoding="utf-8")
    return p


@pytest.mark.parametrize("case", sorted(BAD))
def test_self_crossing_outline_is_refused_in_one_line(case, tmp_path):
    obj, words = BAD[case]
    with pytest.raises(WorkbenchError) as e:
        workbench.load_scene(_write(tmp_path, obj))
    msg = str(e.value)
    assert "\n" not in msg and "[[objects]] #1." in msg, msg
    for w in words:
        assert w in msg, msg


@pytest.mark.parametrize("case", sorted(GOOD))
def test_simple_outline_loads(case, tmp_path):
    assert len(workbench.load_scene(_write(tmp_path, GOOD[case])).objects) == 1


@pytest.mark.parametrize("case", ["lathe open, crossing", "prism bow tie"])
def test_cli_refuses_with_exit_2(case, tmp_path):
    out = tmp_path / "x.png"
    p = subprocess.run([WORKBENCH, "render", str(_write(tmp_path, BAD[case][0])), "-m", "raycast",
                        "--size", "16x12", "-o", str(out)], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2, p.stderr[-2000:]
    assert len(lines) == 1 and lines[0].startswith("workbench: error: ") and "meets" in lines[0], p.stderr
    assert not out.exists()
