"""UI features beyond the first window (tests/test_ui.py): the scene file browser, light
controls, the error plot, the radiosity patch view and the pyrender child process.  The state
functions are tested in-process (no window); a scripted session under Xvfb
(``workbench.app.ui.scripts.Features``) exercises the same functions through the window."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from workbench.app.ui.file_browser import go_to, listing, open_scene
from workbench.app.ui.state import new_state
from workbench.scene.library import SCENES_DIR

ROOT = Path(__file__).resolve().parents[1]


def _scene_folder(tmp_path: Path) -> Path:
    """A folder with a good scene, a bad one, a text file and a sub-folder."""
    (tmp_path / "sub").mkdir()
    (tmp_path / ".hidden").mkdir()
    good = (SCENES_DIR / "whitted.toml").read_text()
    (tmp_path / "good.toml").write_text(good)
    (tmp_path / "bad.toml").write_text(re.sub(r"fov_y\s*=\s*[0-9.]+", 'fov_y = "wide"', good))
    (tmp_path / "broken.toml").write_text("[scene\nname = ")
    (tmp_path / "notes.txt").write_text("not a scene")
    return tmp_path


def test_browser_lists_folders_and_scene_files(tmp_path):
    d = _scene_folder(tmp_path)
    dirs, files = listing(d)
    assert [p.name for p in dirs] == ["sub"]
    assert [p.name for p in files] == ["bad.toml", "broken.toml", "good.toml"]
    state = new_state("whitted")
    go_to(state.browser, d / "sub")
    assert state.browser.folder == (d / "sub").resolve() and not state.browser.failed
    go_to(state.browser, d / "good.toml")  # a file is not a folder: stay, say so
    assert state.browser.folder == (d / "sub").resolve() and state.browser.failed


def test_bad_scene_file_keeps_the_scene_and_says_why(tmp_path):
    d = _scene_folder(tmp_path)
    state = new_state("whitted")
    before = (state.scene, state.scene_path, state.scene_version, state.camera)
    for name, words in (("bad.toml", ("bad.toml", "fov_y")), ("broken.toml", ("broken.toml", "TOML"))):
        assert not open_scene(state, d / name)
        assert state.browser.failed and all(w in state.browser.message for w in words), \
            state.browser.message
        assert (state.scene, state.scene_path, state.scene_version, state.camera) == before
    assert open_scene(state, d / "good.toml")
    assert state.scene_path == (d / "good.toml").resolve() and not state.browser.failed
    assert state.scene_version == before[2] + 1


def test_light_edits_make_a_new_scene_and_refuse_bad_values():
    from workbench.core.errors import WorkbenchError
    from workbench.app.ui.state import light_fields, light_value, reset_lights, set_light_value
    state = new_state("whitted")
    base = state.scene
    assert light_fields(base.lights[0]) == ("position", "color", "intensity")
    set_light_value(state, 0, "position", (1.0, 2.0, 3.0))
    set_light_value(state, 1, "color", (0.2, 0.4, 0.6))
    assert state.scene.lights[0].position == (1.0, 2.0, 3.0)
    assert state.scene.lights[1].color == (0.2, 0.4, 0.6)
    assert state.scene.lights[1].position == base.lights[1].position
    assert state.scene.materials == base.materials and state.scene.objects == base.objects
    scene, version = state.scene, state.scene_version
    for k, name, v in ((0, "color", (1.0, -1.0, 0.0)), (0, "intensity", float("nan")),
                       (0, "direction", (0, 0, 1)), (5, "position", (0, 0, 0))):
        with pytest.raises(WorkbenchError):
            set_light_value(state, k, name, v)
    assert state.scene is scene and state.scene_version == version
    reset_lights(state)
    assert state.scene.lights == base.lights and state.scene_version == version + 1


def test_area_light_centre_moves_the_polygon():
    from workbench.app.ui.state import light_fields, light_value, set_light_value
    state = new_state("cornell", ["phong"])
    light = state.scene.lights[0]
    assert light_fields(light)[0] == "centre"
    c = np.asarray(light_value(light, "centre"))
    set_light_value(state, 0, "centre", tuple(c + [10.0, -20.0, 5.0]))
    moved = state.scene.lights[0]
    assert np.allclose(moved.vertices - light.vertices, [10.0, -20.0, 5.0])
    assert np.isclose(moved.area, light.area)


@pytest.fixture(scope="module")
def features(xvfb, tmp_path_factory):
    """Run the ``features`` script once on whitted; (out folder, summary, process)."""
    out = tmp_path_factory.mktemp("ui_features")
    _scene_folder((out / "scenes").mkdir() or out / "scenes")
    env = {**os.environ, "DISPLAY": xvfb}
    p = subprocess.run([sys.executable, "-m", "workbench.app.ui.main", "whitted",
                        "--methods", "flat,phong,raytrace", "--size", "96",
                        "--test-script", "features", "--out", str(out), "--frames", "3000"],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=400)
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None
    return out, summary, p


def _img(out: Path, phase: str, m: str) -> np.ndarray:
    return np.load(out / f"{phase}_{m}.npy")


def test_features_session_exits_cleanly(features):
    out, summary, p = features
    assert p.returncode == 0, p.stderr[-2000:]
    assert summary["threads"] == ["MainThread"] and summary["script"]["cpu_done"]


def test_browser_in_the_window(features):
    _, summary, _ = features
    log = summary["script"]
    assert log["listing"] == ["sub", "bad.toml", "broken.toml", "good.toml"]
    assert not log["bad"]["opened"] and log["bad"]["failed"] and log["bad"]["version_kept"]
    assert "fov_y" in log["bad"]["message"]
    assert log["good"]["opened"] and log["good"]["scene_path"].endswith("good.toml")


def test_moving_a_light_updates_gl_panels_at_once_and_restarts_cpu_jobs(features):
    out, summary, _ = features
    for m in ("flat", "phong"):  # the very next frame
        assert np.abs(_img(out, "lit0", m) - _img(out, "lit1_next_frame", m)).max() > 0.05, m
    # the ray tracer's restarted job ends with the moved light: its image changes too (the
    # shadow and shading move), and the next-frame image was still the old (or partial) one
    rt0, rt1 = _img(out, "lit0", "raytrace"), _img(out, "lit1", "raytrace")
    assert np.abs(rt0 - rt1).max() > 0.05
    assert np.abs(rt1 - _img(out, "lit1_next_frame", "raytrace")).max() > 0.05


def test_error_plot_points_are_the_compare_metrics(features):
    """Each method on screen gets a point whose error is compare.metrics against the compare
    module's reference for this scene (the ray tracer at its finest max_depth on whitted), and a
    knob change adds a point of the same method."""
    from workbench.compare.metrics import metrics
    from workbench.compare.reference import finest_options
    out, summary, _ = features
    plot = summary["script"]["plot"]
    assert plot["reference"] == "raytrace" and plot["ref_options"] == finest_options("raytrace")
    ref = np.load(out / "plot_reference.npy")
    for m in ("flat", "phong", "raytrace"):
        (point,) = plot["points"][m]
        expected = metrics(_img(out, "plot", m), ref)
        assert np.isclose(point["rmse"], expected["rmse"], rtol=1e-6, atol=1e-9), m
        assert np.isclose(point["flip"], expected["flip"], rtol=1e-4, atol=1e-6), m
        assert point["seconds"] > 0
    # Phong has no reflection, refraction or shadows: further from the reference than the
    # ray tracer at max_depth 5
    assert plot["points"]["raytrace"][0]["rmse"] < plot["points"]["phong"][0]["rmse"]
    flat = summary["script"]["plot_knob"]
    assert len(flat) == 2 and len({p["options"]["tessellation"] for p in flat}) == 2
    assert flat[0]["rmse"] != flat[1]["rmse"]
