"""The window's export (issue 18, item 7), under Xvfb: the panels as displayed plus their linear
data, the not-applicable panel skipped with a note, and a scene file with the overrides and the
camera written in whose replay through ``workbench render`` gives the exported images (a
window session and two CLI renders, ~35 s: marked slow; test_ui.py's session checks the
displayed PNGs in the default run).
Before: the PNGs ignored the display modes, a not-applicable panel was a black PNG, and the
material and light overrides were only listed (``workbench compare`` cannot apply them)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command
from PIL import Image

from workbench.app.ui.export import toml_text
from workbench.core.display import apply_display_mode
from workbench.core.imageio import to_srgb8

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def exported(xvfb, tmp_path_factory):
    out = tmp_path_factory.mktemp("export")
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", "phong,raytrace,radiosity", "--size", "64",
                        "--script", script_of("ExportCheck"), "--out", str(out)],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=400)
    assert p.returncode == 0, p.stderr[-2000:]
    return out, json.loads((out / "summary.json").read_text())["script"]


def test_toml_text_round_trips():
    import tomllib
    data = {"scene": {"name": "a \"b\"", "ambient": [0.1, 0.2, 0.3]},
            "camera": {"position": [0.0, 1.5, -2.0], "resolution": [64, 48]},
            "materials": {"red": {"kd": 0.5, "texture": {"kind": "checker", "scale": 4}}},
            "lights": [{"type": "point", "position": [1.0, 2.0, 3.0]}],
            "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1e-3}]}
    assert tomllib.loads(toml_text(data)) == data


@pytest.mark.slow
@pytest.mark.gl
def test_export_skips_the_panel_that_does_not_apply_and_says_where(exported):
    out, log = exported
    folder = (out / "export").resolve()
    settings = json.loads((folder / "settings.json").read_text())
    assert "radiosity" in settings["skipped"] and "NotApplicable" in settings["skipped"]["radiosity"]
    assert not (folder / "radiosity.png").exists()
    assert str(folder) in log["status"] and "skipped: radiosity" in log["status"]
    assert sorted(log["exported"]) == sorted(["phong.png", "phong.npy", "raytrace.png",
                                              "raytrace.npy", "difference.png", "difference.npy",
                                              "scene.toml", "settings.json"])
    # the PNG as displayed: phong through its indexed mode, from the exported linear data
    linear = np.load(folder / "phong.npy")
    png = np.asarray(Image.open(folder / "phong.png"))[..., :3]
    assert settings["display"]["phong"] == "indexed16-mediancut"
    assert np.array_equal(png, to_srgb8(apply_display_mode(linear, "indexed16-mediancut")))
    assert len(np.unique(png.reshape(-1, 3), axis=0)) <= 16 < len(np.unique(to_srgb8(linear).reshape(-1, 3), axis=0))


@pytest.mark.slow
@pytest.mark.gl
def test_export_replayed_through_the_cli_gives_the_same_images(exported, tmp_path):
    out, _ = exported
    folder = (out / "export").resolve()
    settings = json.loads((folder / "settings.json").read_text())
    assert [c[4] for c in settings["replay"]] == ["phong", "raytrace"]
    for cmd in settings["replay"]:
        m = cmd[4]
        args = cmd[2:]
        args[args.index("-o") + 1] = str(tmp_path / f"{m}.png")
        args[args.index("--npy") + 1] = str(tmp_path / f"{m}.npy")
        p = subprocess.run([sys.executable, "-m", "workbench.app.cli", "render", *args],
                           cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr[-2000:]
        ui, cli = np.load(folder / f"{m}.npy"), np.load(tmp_path / f"{m}.npy")
        assert ui.shape == cli.shape == (48, 64, 3)
        # the window's GL context and the CLI's headless one: float32 rounding apart
        assert np.abs(ui - cli).max() <= 1e-4, m
        a = np.asarray(Image.open(folder / f"{m}.png")).astype(int)
        b = np.asarray(Image.open(tmp_path / f"{m}.png")).astype(int)
        assert (np.abs(a - b).max(-1) > 0).mean() <= 0.01, m


@pytest.mark.gl
def test_an_export_while_the_path_tracer_refines_records_what_it_had(xvfb, tmp_path):
    """Issue #29, item 5: a path-traced panel exported while it refines records the spp and
    passes its image has (not the knob's target, 256) and that it had not converged; its
    replay renders that many spp, which gives the exported image (the sampler is seeded by
    the sample's index, so passes of another size give the same sums)."""
    from workbench.app.ui.jobs import PASS_SAMPLES
    out = tmp_path / "ui"
    p = subprocess.run([*ui_command(), "cornell", "--methods", "phong,pathtrace", "--size", "96",
                        "--script", script_of("ExportRefining"), "--out", str(out)],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=400)
    assert p.returncode == 0, p.stderr[-2000:]
    log = json.loads((out / "summary.json").read_text())["script"]
    assert "exported" in log, log  # the panel was seen refining
    folder = (out / "export").resolve()
    settings = json.loads((folder / "settings.json").read_text())
    rec = settings["panels"]["pathtrace"]
    w, h = settings["camera"]["width"], settings["camera"]["height"]
    per_pass = max(1, PASS_SAMPLES // (w * h))
    assert rec["state"] == "refining" and rec["converged"] is False and rec["target_spp"] == 256
    assert rec["passes"] >= 2 and rec["spp"] == rec["passes"] * per_pass < 256
    assert rec["noise"] > 0 and rec == log["progress"]
    assert settings["panels"]["phong"] == {"state": "done"}
    assert settings["options"]["pathtrace"]["spp"] == rec["spp"]
    cmd = next(c for c in settings["replay"] if c[4] == "pathtrace")
    assert f"spp={rec['spp']}" in cmd and "spp=256" not in cmd
    assert f"pathtrace at {rec['spp']}/256 spp (not converged)" in log["status"]
    args = cmd[2:]
    args[args.index("-o") + 1] = str(tmp_path / "pt.png")
    args[args.index("--npy") + 1] = str(tmp_path / "pt.npy")
    r = subprocess.run([str(Path(ui_command()[0])), "render", *args], cwd=tmp_path,
                       capture_output=True, text=True, timeout=400)
    assert r.returncode == 0, r.stderr[-2000:]
    ui, cli = np.load(folder / "pathtrace.npy"), np.load(tmp_path / "pt.npy")
    assert np.isfinite(ui).all() and ui.shape == cli.shape == (h, w, 3)
    assert np.abs(ui - cli).max() <= 1e-5


def test_a_gl_panel_exported_at_a_drags_lower_resolution_says_so():
    """An export taken while a GL panel shows a drag's smaller image (issue #29, items 1 and 5)
    records it as ``reduced`` with both sizes, and its note says so; at full size it is done."""
    from types import SimpleNamespace

    from workbench.app.ui.export import panel_record, progress_note

    state = SimpleNamespace(kinds={"flat": "gl"}, images={"flat": np.zeros((6, 8, 3), np.float32)},
                            camera=SimpleNamespace(width=16, height=12))
    record = panel_record(state, "flat")
    assert record == {"state": "reduced", "size": [8, 6], "full_size": [16, 12]}
    assert progress_note("flat", record) == "flat at 8x6 of 16x12 (drawn during a camera drag)"
    state.images["flat"] = np.zeros((12, 16, 3), np.float32)
    assert panel_record(state, "flat") == {"state": "done"} and progress_note("flat", {"state": "done"}) == ""
