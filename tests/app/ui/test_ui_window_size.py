"""The window's size remembered between runs (issue #29, item 6): ``workbench ui`` without
``--window`` opens at the size the window had when last closed (``window.json`` under
``$WORKBENCH_CONFIG_DIR``), a resize included; a file that cannot be used gives one line and
the default size; a ``--window`` too small is refused in one line, exit 2.  Before: every run
opened at 1280x760 (hello_imgui's settings file is off)."""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

from ui_command import script_of, ui_command

ROOT = Path(__file__).resolve().parents[3]


def _run(xvfb, config: Path, out: Path, *args: str) -> tuple[subprocess.CompletedProcess, dict]:
    p = subprocess.run([*ui_command(), "whitted", "--methods", "phong", "--size", "32",
                        "--out", str(out), *args], cwd=ROOT,
                       env={**os.environ, "DISPLAY": xvfb, "WORKBENCH_CONFIG_DIR": str(config)},
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    return p, json.loads((out / "summary.json").read_text())


@pytest.mark.gl
def test_the_window_opens_at_the_size_it_was_closed_at(xvfb, tmp_path):
    config = tmp_path / "config"
    _, first = _run(xvfb, config, tmp_path / "a", "--window", "1000x640", "--frames", "3")
    assert first["window"] == [1000, 640]
    assert json.loads((config / "window.json").read_text()) == {"size": [1000, 640]}
    # no --window: the last size; resized by the user, the new one is kept
    _, second = _run(xvfb, config, tmp_path / "b", "--script", script_of("Resize"))
    assert second["script"] == {"opened": [1000, 640], "resized": [900, 560]}
    _, third = _run(xvfb, config, tmp_path / "c", "--frames", "3")
    assert third["window"] == [900, 560]


@pytest.mark.gl
def test_an_unusable_size_file_gives_one_line_and_the_default(xvfb, tmp_path):
    config = tmp_path / "config"
    config.mkdir()
    (config / "window.json").write_text('{"size": [10, "x"]}')
    p, summary = _run(xvfb, config, tmp_path / "a", "--frames", "3")
    assert summary["window"] == [1280, 760]
    lines = [x for x in p.stderr.splitlines() if "window.json" in x]
    assert len(lines) == 1 and "default size" in lines[0] and "Traceback" not in p.stderr
    assert json.loads((config / "window.json").read_text()) == {"size": [1280, 760]}


def test_a_window_too_small_is_refused_in_one_line(tmp_path):
    p = subprocess.run([*ui_command(), "whitted", "--window", "200x100"], cwd=tmp_path,
                       env={**os.environ, "DISPLAY": ":999"}, capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert p.stderr.strip().splitlines()[-1].endswith("--window must be at least 320x240 pixels, got 200x100")
