"""A study point whose estimate is above the memory limit is a refusal, not a failure: listed
as ``over_memory`` with the estimate, the study goes on and exits 0 (the bundled ``mesh`` scene
with radiosity, 82k patches, needs about 300 GiB: ``study mesh`` exited 1).  Through the console
script, as users run it."""
from __future__ import annotations

import json
import subprocess

from ui_command import WORKBENCH
import workbench
from workbench.renderers.base import convert_options, get_renderer


def test_study_lists_points_over_the_limit_and_exits_0(tmp_path):
    scene = workbench.load_scene("cornell")
    need = {m: get_renderer(m).estimate_bytes(scene, 16, 12, **convert_options(get_renderer(m), {}))
            for m in ("raycast", "radiosity")}
    assert need["raycast"] < need["radiosity"]
    limit = (need["raycast"] + need["radiosity"]) // 2  # raycast fits, radiosity's default does not
    out = subprocess.run([WORKBENCH, "study", "cornell", "--quick", "--size", "16x12", "--methods",
                          "raycast,radiosity", "--reference", "raycast", "--repeat", "1",
                          "--max-memory", str(limit), "--out", str(tmp_path / "s")],
                         capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "Traceback" not in out.stderr
    points = json.loads((tmp_path / "s" / "study.json").read_text())["points"]
    status = {(p["method"], p["value"]): p["status"] for p in points}
    assert "failed" not in status.values()
    over = [p for p in points if p["status"] == "over_memory"]
    assert over and all(p["method"] == "radiosity" and "above the limit" in p["reason"] for p in over)
    assert all(s == "ok" for (m, _), s in status.items() if m == "raycast")
    assert "over_memory: method 'radiosity'" in out.stdout
