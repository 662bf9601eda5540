"""Every editable control of every bundled scene at its minimum, maximum and a middle value,
through the window's script interface (``workbench ui SCENE --script controls``,
``session_controls``): the window survives, no panel image ever holds NaN or
Inf, no control raises, the CPU panels still deliver, and the resident size stays within the
memory limit given with ``--max-memory``.  One scene in the default run (point lights, glass and
mirrors: 17 s); every bundled scene under ``slow`` (kinds and cornell take 2-3 minutes each: their
CPU panels restart at every control)."""
from __future__ import annotations

import json
import os
import subprocess

import pytest

from ui_command import script_of, ui_command
from workbench.core.memory import parse_size
from workbench.scene.library import bundled

pytestmark = pytest.mark.gl
MAX_MEMORY = "4G"
DEFAULT_RUN = ("whitted",)
SCENES = [pytest.param(p.stem, marks=() if p.stem in DEFAULT_RUN else pytest.mark.slow)
          for p in bundled()]


@pytest.mark.parametrize("name", SCENES)
def test_every_control_at_its_ends_and_middle(name, xvfb, tmp_path):
    p = subprocess.run([*ui_command(name, "--size", "32", "--script", script_of("Controls", "session_controls.py"),
                                    "--out", str(tmp_path), "--max-memory", MAX_MEMORY)],
                       cwd=tmp_path, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    assert "Traceback" not in p.stderr, p.stderr[-3000:]
    log = json.loads((tmp_path / "summary.json").read_text())["script"]
    labels = [label for label, _ in log["steps"]]
    assert any(label.startswith("materials kd=") for label in labels)
    assert any(label.startswith("camera") for label in labels)
    assert log["errors"] == []
    assert log["not_finite"] == []
    assert log["jobs_done"], "the CPU panels did not deliver after the last control"
    assert set(log["delivered"]) == set(log["methods"])
    assert 0 < log["peak_rss"] <= parse_size(MAX_MEMORY)
