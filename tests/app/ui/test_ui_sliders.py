"""Material and light sliders on the GL panels (``workbench.app.ui.panel_refresh`` with
``RasterSession.update``): under Xvfb the ``slider_frames`` script (a subprocess, as in
test_ui.py) changes a material's kd and light 0's position every frame for six frames.  Each
frame must show the new values (the panel image changes, and the last one is the CLI image of
the edited scene), no GL program may be compiled after the first edited frame, each panel is
drawn once per frame, and once the values rest the panels go back to the literal programs
with the same image."""
from __future__ import annotations

import json
import os
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command

import workbench
from sessions import slider_step
from workbench.app.ui.state import new_state

ROOT = Path(__file__).resolve().parents[3]
RASTER = ("flat", "gouraud", "phong")
SIZE = 96
EDITS = range(3, 9)

pytestmark = pytest.mark.gl


@pytest.fixture(scope="module")
def slider_session(xvfb, tmp_path_factory):
    out = tmp_path_factory.mktemp("ui_sliders")
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", ",".join(RASTER), "--size", str(SIZE),
                        "--script", script_of("SliderFrames"), "--out", str(out), "--frames", "2000"],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    summary = json.loads((out / "summary.json").read_text())
    return out, {f["name"]: f for f in summary["script"]["frames"]}


def _scene_after(k: int):
    """The scene the UI shows after edit ``k`` (the script's slider_step on a fresh state)."""
    state = new_state("whitted", list(RASTER), SIZE)
    slider_step(state, k, "material+light")
    return replace(state.scene, camera=state.camera)


def test_no_program_compiled_per_slider_frame(slider_session):
    _, frames = slider_session
    first = frames[f"edit{EDITS[0]}"]["compiles"]
    assert first >= frames["start"]["compiles"]
    for k in EDITS:
        assert frames[f"edit{k}"]["compiles"] == first, k  # uniforms only after the first
        assert all(frames[f"edit{k}"]["live"].values())
    for k in EDITS[1:]:  # one draw per panel per frame, in the same session
        assert frames[f"edit{k}"]["draws"] == {m: frames[f"edit{k - 1}"]["draws"][m] + 1 for m in RASTER}


def test_each_slider_frame_shows_its_values(slider_session):
    out, _ = slider_session
    prev = {m: np.load(out / f"start_{m}.npy") for m in RASTER}
    for k in EDITS:
        for m in RASTER:
            img = np.load(out / f"edit{k}_{m}.npy")
            assert np.abs(img - prev[m]).max() > 1e-3, (k, m)
            prev[m] = img
    scene = _scene_after(EDITS[-1])
    for m in RASTER:
        cli = workbench.render(scene, m, width=scene.camera.width,
                               height=scene.camera.height).image  # with stand-ins, as the panels
        assert np.abs(np.load(out / f"edit{EDITS[-1]}_{m}.npy") - cli).max() <= 1e-4, m


def test_rested_values_are_compiled_back_in(slider_session):
    out, frames = slider_session
    settled = frames["settled"]
    assert not any(settled["live"].values())
    assert settled["compiles"] > frames[f"edit{EDITS[-1]}"]["compiles"]  # the literal programs
    scene = _scene_after(EDITS[-1])
    for m in RASTER:
        img = np.load(out / f"settled_{m}.npy")
        cli = workbench.render(scene, m, width=scene.camera.width,
                               height=scene.camera.height).image  # with stand-ins, as the panels
        assert np.abs(img - cli).max() <= 1e-6, m
        assert np.abs(img - np.load(out / f"edit{EDITS[-1]}_{m}.npy")).max() <= 1e-4, m
