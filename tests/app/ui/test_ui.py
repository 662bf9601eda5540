"""The UI under Xvfb: a scripted session (``sessions.Check``) runs in a
subprocess (GLFW and GL state never enter the pytest process) and writes each panel's image
per phase plus ``summary.json``; the assertions are here."""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command

from workbench.app.ui import camera as cam
from workbench.scene.io import load_scene

pytestmark = pytest.mark.gl
ROOT = Path(__file__).resolve().parents[3]
METHODS = ("flat", "gouraud", "phong", "raycast", "raytrace")
RASTER = ("flat", "gouraud", "phong")


@pytest.fixture(scope="module")
def session(xvfb, tmp_path_factory):
    """Run the check script once; returns (out folder, summary, completed process)."""
    out = tmp_path_factory.mktemp("ui")
    env = {**os.environ, "DISPLAY": xvfb}
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", ",".join(METHODS), "--size", "128",
                        "--script", script_of("Check"), "--out", str(out), "--frames", "2000"],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=400)
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None
    return out, summary, p  # (the README's screenshot comes from test_ui_screens.py)


def _img(out: Path, phase: str, m: str) -> np.ndarray:
    return np.load(out / f"{phase}_{m}.npy")


def _coverage(img: np.ndarray, background) -> np.ndarray:
    """Pixels that are not the background colour (objects drawn)."""
    return np.abs(img - np.asarray(background, np.float32)).max(-1) > 1e-3


def test_window_opens_exits_cleanly_no_threads(session):
    out, summary, p = session
    assert p.returncode == 0, p.stderr[-2000:]
    assert summary["frames"] >= 6
    assert summary["gl_renderer"].strip()
    assert summary["threads"] == ["MainThread"]
    assert summary["script"]["cpu_done"]


def test_every_panel_non_empty(session):
    out, summary, _ = session
    for m in METHODS:
        img = _img(out, "final", m)
        assert img.shape == (96, 128, 3) and np.isfinite(img).all()  # whitted's 4:3
        assert img.std() > 0.01, m  # not a flat colour
    shot = np.asarray(__import__("PIL.Image", fromlist=["Image"]).open(out / "ui.png"))
    assert shot.shape[0] > 100 and shot.std() > 10


def test_orbit_changes_all_raster_panels_consistently(session):
    out, _, _ = session
    bg = load_scene("whitted").background
    masks = {}
    for m in RASTER:
        before, after = _img(out, "before", m), _img(out, "orbit", m)
        assert np.abs(before - after).mean() > 0.01, m
        masks[m] = _coverage(after, bg)
    # silhouettes agree between the three shadings (tessellation edges aside)
    for m in ("flat", "gouraud"):
        assert (masks[m] != masks["phong"]).mean() < 0.02, m


def test_cpu_panel_follows_the_shared_camera(session):
    """The ray-cast panel (finished after the orbit) has the raster panels' silhouette."""
    out, _, _ = session
    bg = load_scene("whitted").background
    rc = _coverage(_img(out, "final", "raycast"), bg)
    ph = _coverage(_img(out, "final", "phong"), bg)
    assert (rc != ph).mean() < 0.03


def test_parameters_change_affected_panels_only(session):
    out, summary, _ = session
    # flat's tessellation knob: flat changes, gouraud and phong are bit-identical
    assert np.abs(_img(out, "orbit", "flat") - _img(out, "knob", "flat")).max() > 0.01
    for m in ("gouraud", "phong"):
        assert np.array_equal(_img(out, "orbit", m), _img(out, "knob", m)), m
    # ks of one material: phong changes, only where objects are (never the background)
    bg = load_scene("whitted").background
    k, s = _img(out, "knob", "phong"), _img(out, "ks", "phong")
    changed = np.abs(k - s).max(-1) > 1e-4
    assert changed.any()
    assert not (changed & ~_coverage(k, bg)).any()


def test_ray_tree_of_a_pixel_matches_the_raytrace_panel(session):
    """The ray tree (reference Python tracer) of a pixel gives the raytrace panel's value."""
    out, summary, _ = session
    rt = summary["script"]["ray_tree"]
    i, j = rt["pixel"]
    assert np.allclose(rt["color"], _img(out, "final", "raytrace")[i, j], atol=2e-3)
    assert rt["n_children"] >= 1
    # the inspector names the hit object as the scene does (or by kind), then its index
    assert rt["object_shown"].startswith(rt["object_name"] or "sphere ") and "(#" in rt["object_shown"], rt


def test_export_writes_panels_and_settings(session):
    from PIL import Image

    from workbench.core.display import apply_display_mode
    from workbench.core.imageio import to_srgb8
    out, summary, _ = session
    exp = out / "export"
    settings = json.loads((exp / "settings.json").read_text())
    assert settings["methods"] == list(METHODS)
    assert settings["material_overrides"] == {summary["script"]["material"]: {
        "ks": 1.0 if summary["script"]["ks_before"] < 0.5 else 0.0}}
    shown = summary["script"]["display"]
    for m in METHODS:
        png = np.asarray(Image.open(exp / f"{m}.png"))
        linear = _img(out, "final", m)
        assert np.array_equal(np.load(exp / f"{m}.npy"), linear)  # the linear data too
        if m == shown["method"]:  # as displayed (before: the display mode was ignored)
            linear = apply_display_mode(linear, "indexed2-mediancut")
        assert np.array_equal(png, to_srgb8(linear)), m
    assert (exp / "difference.png").exists()
    assert settings["display"][shown["method"]] == "indexed2-mediancut"


def test_panel_display_mode_quantises_only_what_is_shown(session):
    _, summary, _ = session
    d = summary["script"]["display"]
    assert d["colours"] <= 2 < d["image_colours"]


def test_camera_functions_are_consistent():
    c = load_scene("whitted").camera
    back = cam.orbit(cam.orbit(c, 0.3, 0.2), -0.3, -0.2)
    assert np.allclose(back.position, c.position, atol=1e-9)
    _, _, _, d = cam.orbit_parameters(c)
    assert np.isclose(cam.orbit_parameters(cam.orbit(c, 1.0, 0.5))[3], d)
    assert np.isclose(cam.orbit_parameters(cam.zoom(c, 0.5))[3], d / 2)
    p = cam.pan(c, 0.1, -0.2)
    assert np.allclose(np.subtract(p.position, c.position), np.subtract(p.look_at, c.look_at))
    assert cam.orbit_parameters(cam.orbit(c, 0.0, 10.0))[2] <= cam.PITCH_LIMIT + 1e-12


def test_linked_view_zoom_keeps_the_point_under_the_mouse():
    v = cam.zoom_view((1.0, 0.5, 0.5), 4.0, (0.3, 0.6))
    (u0, v0), (u1, v1) = cam.view_window(v)
    assert np.isclose(u1 - u0, 0.25) and np.isclose((0.3 - u0) / (u1 - u0), 0.3)
    assert np.isclose((0.6 - v0) / (v1 - v0), 0.6)
    back = cam.pan_view(cam.pan_view(v, 0.1, -0.05), -0.1, 0.05)
    assert np.allclose(cam.view_window(back), cam.view_window(v))
    assert np.allclose(cam.view_window((2.0, 0.0, 1.0)), ((0.0, 0.5), (0.5, 1.0)))  # kept inside
    assert cam.zoom_view(v, 1e-3, (0.5, 0.5))[0] == 1.0


@pytest.mark.slow
def test_radiosity_panels_in_the_window(xvfb, tmp_path):
    """Radiosity and hybrid (no tiles: they finish in the background) restart with each change
    and end with non-empty images; no thread left."""
    env = {**os.environ, "DISPLAY": xvfb}
    p = subprocess.run([*ui_command(), "cornell",
                        "--methods", "phong,radiosity,hybrid", "--size", "64",
                        "--script", script_of("Check"), "--out", str(tmp_path)],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["threads"] == ["MainThread"] and summary["script"]["cpu_done"]
    ph, ph_before = _img(tmp_path, "final", "phong"), _img(tmp_path, "before", "phong")
    for m in ("radiosity", "hybrid"):
        img = np.clip(_img(tmp_path, "final", m), 0, 1)
        assert img.std() > 0.01
        # rendered with the orbited camera: closer to phong after the orbit than before it
        assert np.abs(img - np.clip(ph, 0, 1)).mean() < np.abs(img - np.clip(ph_before, 0, 1)).mean()


def test_docking_layout_and_status_bar(session):
    """Every window is docked; one tab per dock space is in front (the parameters, not the lights
    and colour wheel sharing their space); the status bar names the GL renderer and each
    method's time."""
    _, summary, _ = session
    win = summary["script"]["windows"]
    assert all(w["exists"] and w["docked"] for w in win.values()), win
    for label in ("Scene", "Methods", "Parameters", "Panels", "Difference", "Error plot"):
        assert win[label]["drawn"] and min(win[label]["size"]) > 100, label
    for label in ("Lights", "Colour wheel", "Ray tree"):  # tabs behind the first of their space
        assert not win[label]["drawn"], label
    # the panels window holds the widest part of the window
    assert win["Panels"]["size"][0] > max(win["Scene"]["size"][0], win["Difference"]["size"][0])
    status = summary["script"]["status_bar"]
    assert status.startswith(summary["gl_renderer"])
    for m in METHODS:
        assert f"| {m} " in status and status.split(f"| {m} ")[1].split(" ms")[0].isdigit(), m


@pytest.mark.parametrize("argv", [["whitted", "--methods", "nosuch"], ["nosuchscene"],
                                  ["whitted", "--size", "4"], ["whitted", "--frames", "0"],
                                  ["whitted", "--script", script_of("nosuch")],
                                  ["whitted", "--script", "check"],
                                  ["whitted", "--script", "nosuch.py:Check"],
                                  ["whitted", "--script", "README.md:Check"],
                                  ["whitted", "--script", script_of("CPU_WAIT_SECONDS")],
                                  ["whitted", "--window", "0x600"]])
def test_workbench_ui_refuses_bad_input_with_one_line(argv, xvfb):
    """``workbench ui`` says what is wrong in one line and exits 2 before opening a window."""
    p = subprocess.run([*ui_command(), *argv], cwd=ROOT, env={**os.environ, "DISPLAY": xvfb},
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("workbench: error: "), p.stderr


def test_a_session_file_that_fails_to_load_is_one_line(tmp_path, xvfb):
    """A user's session file that raises while it loads (here a syntax error) is reported in one
    line naming the file and the error, exit 2, nothing written to ``--out``."""
    bad = tmp_path / "mine.py"
    bad.write_text("def Session(out):\n    return lambda state: None\ndef (:\n")
    out = tmp_path / "out"
    p = subprocess.run([*ui_command("whitted", "--script", f"{bad}:Session", "--out", str(out))],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 2, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "mine.py failed to load (SyntaxError" in lines[0], p.stderr
    assert not out.exists()


def test_a_users_session_file_drives_the_window(tmp_path, xvfb):
    """The documented form of ``--script``: a file of the user's own, outside the repository,
    whose session records the frame count in its log and quits at frame 3."""
    mine = tmp_path / "mine.py"
    mine.write_text(
        "class Session:\n"
        "    def __init__(self, out):\n"
        "        self.log = {'frames': []}\n"
        "    def __call__(self, state):\n"
        "        self.log['frames'].append(state.frame)\n"
        "        state.quit = state.frame >= 3\n")
    out = tmp_path / "out"
    p = subprocess.run([*ui_command("whitted", "--methods", "flat", "--size", "32",
                                    "--script", f"{mine}:Session", "--out", str(out))],
                       cwd=tmp_path, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    log = json.loads((out / "summary.json").read_text())["script"]
    assert log["frames"][-1] == 3 and log["frames"] == sorted(log["frames"]), log
