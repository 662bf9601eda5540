"""UI features beyond the first window (tests/app/ui/test_ui.py): the scene file browser, light
controls, the error plot, the radiosity patch view and the pyrender child process.  The state
functions are tested in-process (no window); a scripted session under Xvfb
(``sessions.Features``) exercises the same functions through the window."""
from __future__ import annotations

import json
import os
import re
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command

import workbench
from workbench.app.ui.file_browser import go_to, listing, open_scene
from workbench.app.ui.state import new_state
from workbench.scene.library import SCENES_DIR

ROOT = Path(__file__).resolve().parents[3]


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


def test_browser_lists_a_folder_again_only_after_a_while_or_a_change(tmp_path):
    from workbench.app.ui.file_browser import RELIST_SECONDS, Browser, cached_listing
    d = _scene_folder(tmp_path)
    b = Browser(folder=d)
    assert [p.name for p in cached_listing(b, now=100.0)[1]] == ["bad.toml", "broken.toml", "good.toml"]
    (d / "new.toml").write_text("")
    assert len(cached_listing(b, now=100.0 + 0.5 * RELIST_SECONDS)[1]) == 3  # not listed again yet
    assert len(cached_listing(b, now=100.0 + RELIST_SECONDS)[1]) == 4
    go_to(b, d / "sub")
    assert cached_listing(b, now=100.0 + RELIST_SECONDS) == ([], [])  # a new folder: listed at once


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
    from workbench.app.ui.state import light_fields, reset_lights, set_light_value
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
    # the ray tracer compiled here first (the window shares the numba cache): on a cold cache
    # under load the window's job compiled past the script's 120 s wait for the moved light
    workbench.render(workbench.load_scene("whitted"), "raytrace", width=8, height=8)
    _scene_folder((out / "scenes").mkdir() or out / "scenes")
    env = {**os.environ, "DISPLAY": xvfb}
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", "flat,phong,raytrace", "--size", "96",
                        "--script", script_of("Features"), "--out", str(out), "--frames", "3000"],
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
        # the error split: each also against its matched reference, the same metrics against
        # that reference (raytrace's is the full reference itself: max_depth 12 on whitted, and
        # so is Phong's with its stand-ins, on by default: the Whitted ray tracer they
        # approximate); flat's below its total error (it misses reflection, refraction and
        # shadows, which its matched reference, the bare local model, also leaves out)
        matched = np.load(out / f"plot_matched_{m}.npy")
        assert np.isclose(point["rmse_matched"], metrics(_img(out, "plot", m), matched)["rmse"],
                          rtol=1e-6, atol=1e-9), m
        if m == "flat":
            assert point["rmse_matched"] < point["rmse"]
        else:
            assert point["rmse_matched"] == point["rmse"], m
    # Phong's stand-ins only approximate reflection, refraction and shadows: further from the
    # reference than the ray tracer at max_depth 5
    assert plot["points"]["raytrace"][0]["rmse"] < plot["points"]["phong"][0]["rmse"]
    # the reference is of the current scene (the moved light), not of an earlier one: the ray
    # tracer at depth 5 is within a few levels of it (a light moved by 3 units is not)
    assert plot["points"]["raytrace"][0]["rmse"] < 0.02
    assert np.sqrt(np.mean((np.clip(_img(out, "lit0", "raytrace"), 0, 1) - np.clip(ref, 0, 1)) ** 2)) > 0.02
    flat = summary["script"]["plot_knob"]
    assert len(flat) == 2 and len({p["options"]["tessellation"] for p in flat}) == 2
    assert flat[0]["rmse"] != flat[1]["rmse"]


def _hinge_agreement(net: np.ndarray, surface: np.ndarray) -> list:
    """Across each edge shared by the top face and a half side in the unfolded item buffer: the
    fraction of pixel pairs (both seeing a patch) that see the same surface."""
    res = net.shape[0] // 2
    a, b = res // 2, 3 * res // 2
    out = []
    for x, y in ((net[a:b, a - 1], net[a:b, a]), (net[a:b, b], net[a:b, b - 1]),
                 (net[a - 1, a:b], net[a, a:b]), (net[b, a:b], net[b - 1, a:b])):
        seen = (x > 0) & (y > 0)
        out.append(float((surface[x[seen] - 1] == surface[y[seen] - 1]).mean()) if seen.sum() > 8 else None)
    return out


@pytest.mark.gl
def test_patch_pick_item_buffer_and_row(gl_ctx):
    """The picked patch is the one under the pixel; the unfolded item buffer is continuous
    across the top face's edges (a surface seen at the edge of the top face goes on in the
    folded-out side); the row is the hemicube's and is drawn on the patches."""
    from workbench.app.ui import patch_view as pv
    state = new_state("cornell", ["phong", "radiosity"], 96)
    patches = pv.scene_patches(state)
    for ij, surface in (((20, 48), "ceiling"), ((92, 30), "floor"), ((50, 10), "left_wall")):
        pick = pv.select_patch(state, *ij)
        assert state.patch_pick is pick and pick.surface == surface
        # the patch's projected corners surround the pixel centre
        xy, _ = state.camera.project(pick.patches.corners[pick.patch])
        x, y = ij[1] + 0.5, ij[0] + 0.5
        assert xy[:, 0].min() - 1 <= x <= xy[:, 0].max() + 1 and xy[:, 1].min() - 1 <= y <= xy[:, 1].max() + 1
        assert len(pick.row) == len(patches) and pick.row[pick.patch] == 0.0  # flat: F_ii = 0
        assert 0.3 < pick.row.sum() <= 1.0 + 1e-9   # the box is open at the front
        net = pv.unfold(pick.item)
        assert net.shape == (2 * pick.resolution,) * 2
        # ids in the item buffer are the row's patches: F_ij > 0 exactly where j is seen
        seen = np.unique(pick.item[pick.item > 0]) - 1
        assert set(seen) == set(np.nonzero(pick.row > 0)[0])
        agree = [a for a in _hinge_agreement(net, patches.surface) if a is not None]
        assert len(agree) >= 2 and min(agree) > 0.9, agree
    # a mirrored side flap breaks the continuity (the test can fail)
    pick = pv.select_patch(state, 20, 48)
    net = pv.unfold(pick.item)
    res = pick.resolution
    net[:res // 2, res // 2:3 * res // 2] = net[:res // 2, res // 2:3 * res // 2][:, ::-1]
    assert min(a for a in _hinge_agreement(net, patches.surface) if a is not None) < 0.5
    # the row image shows the picked patch in its colour at the picked pixel
    img = pv.row_image(state, pick)
    i, j = (np.array([20, 48]) * pv.VIEW_SIZE / 96).astype(int)
    assert np.abs(img[i, j] / 255.0 - pv.SELECTED).max() < 0.02
    # a pixel outside the box sees no patch: nothing is picked
    assert pv.patch_ids(patches, state.camera)[0, 0] == -1
    assert pv.select_patch(state, 0, 0) is None and state.patch_pick is None


@pytest.fixture(scope="module")
def radiosity_session(xvfb, tmp_path_factory):
    """Run the ``radiosity`` script once on the Cornell box; (out folder, summary, process)."""
    out = tmp_path_factory.mktemp("ui_radiosity")
    env = {**os.environ, "DISPLAY": xvfb}
    p = subprocess.run([*ui_command(), "cornell",
                        "--methods", "phong,radiosity", "--size", "64",
                        "--script", script_of("Radiosity"), "--out", str(out), "--frames", "3000"],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=400)
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None
    return out, summary, p


def test_patch_view_in_the_window(radiosity_session):
    out, summary, p = radiosity_session
    assert p.returncode == 0, p.stderr[-2000:]
    assert summary["threads"] == ["MainThread"] and summary["script"]["cpu_done"]
    pick = summary["script"]["pick"]
    assert pick["surface"] == "ceiling" and 0.5 < pick["row_sum"] <= 1.0 + 1e-9
    win = summary["script"]["windows"]
    assert win["Patch view"]["drawn"] and not win["Error plot"]["drawn"]
    assert _img(out, "final", "radiosity").std() > 0.01


@pytest.fixture(scope="module")
def pyrender_session(xvfb, tmp_path_factory):
    """Run the ``pyrender`` script once on whitted; (out folder, summary, process)."""
    out = tmp_path_factory.mktemp("ui_pyrender")
    env = {**os.environ, "DISPLAY": xvfb}
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", "phong,pyrender", "--size", "96",
                        "--script", script_of("Pyrender"), "--out", str(out), "--frames", "5000"],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=400)
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None
    return out, summary, p


def test_pyrender_panel_from_a_child_process(pyrender_session):
    """pyrender renders in a child process, follows the shared camera (its silhouette is the
    Phong panel's after an orbit), shows "rendering..." meanwhile, and the child is gone after
    the window closes."""
    from workbench.scene.io import load_scene
    out, summary, p = pyrender_session
    assert p.returncode == 0, p.stderr[-2000:]
    log = summary["script"]
    assert log["error"] is None and "rendering" in log["status_while_rendering"]
    assert log["plotted"] == ["phong", "pyrender"]  # its error against the reference too
    assert summary["threads"] == ["MainThread"] and summary["child_processes"] == []
    assert not Path(f"/proc/{log['child_pid']}").exists()
    bg = np.asarray(load_scene("whitted").background, np.float32)
    before, after = _img(out, "before", "pyrender"), _img(out, "orbit", "pyrender")
    assert np.isfinite(after).all() and np.abs(before - after).mean() > 0.01
    cover = lambda img: np.abs(img - bg).max(-1) > 0.02  # pyrender's image is 8-bit
    assert (cover(after) != cover(_img(out, "orbit", "phong"))).mean() < 0.03


def test_pyrender_child_that_dies_is_reported_not_raised():
    """A killed child: the panel says so, later requests send nothing, closing still joins."""
    from workbench.app.ui.pyrender_proc import DIED, PyrenderProcess
    state = new_state("whitted", ["phong"], 32)
    proc = PyrenderProcess()
    proc.process.kill()
    proc.process.join(10)
    proc.request(1, state.scene, state.camera, {"tessellation": 1})
    deadline = time.time() + 10
    while proc.error is None and time.time() < deadline:
        proc.poll()
    assert proc.error == DIED and not proc.busy
    proc.request(2, state.scene, state.camera, {"tessellation": 1})
    assert not proc.busy
    proc.close()
    assert not proc.process.is_alive()
