"""Progressive everything (issue #29, item 2), run as users run it: ``workbench ui`` under Xvfb
with the scripted sessions of ``session_progress.py``.

* Radiosity in the window shoots (progressive refinement, Cohen et al. 1988) and shows each
  round's image as it lands, with the unshot share of the emitted power (before: nothing until
  the solve ended).
* The long jobs show a progress bar with done/target and the time left.
* The methods of several steps (issue #29: "hybrid/mitsuba/povray panels show no progress
  bar") show each step's progress: the hybrid method's form-factor rows, its solve (which
  reports no amount done: an indeterminate bar with the time elapsed) and its ray-trace rows;
  POV-Ray's own "Rendered N of M pixels"; the Mitsuba child's samples per pixel.
* No job renders what is already rendered: the error plot's reference takes the path-traced
  panel's job of the same request (before: rendered again after the panel, about a minute with
  no progress shown), and a reference is stored in the CLI's reference cache and loaded from
  it by the next window.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command

import workbench
from workbench.app.ui.state import panel_camera
from workbench.compare.reference_cache import cache_entries

pytestmark = pytest.mark.gl
ROOT = Path(__file__).resolve().parents[3]
SIZE = 48


def _run(xvfb, out: Path, scene: str, methods: str, cache: Path, session: str = "progress") -> dict:
    out.mkdir()
    p = subprocess.run([*ui_command(), scene, "--methods", methods, "--size", str(SIZE),
                        "--script", script_of(session, "session_progress.py"), "--out", str(out)],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb, "WORKBENCH_REFERENCE_CACHE": str(cache)},
                       capture_output=True, text=True, timeout=580)
    assert p.returncode == 0, p.stderr[-2000:]
    log = json.loads((out / "summary.json").read_text())["script"]
    assert log["finished"], log.get("reference_message", log.get("jobs"))
    return log


def _unshot(detail: str) -> float:
    """``"unshot 3.1 %"`` -> 0.031."""
    word, value, pct = detail.split()
    assert (word, pct) == ("unshot", "%"), detail
    return float(value) / 100


def test_radiosity_shows_each_shooting_round_and_the_reference_is_the_panels_job(xvfb, tmp_path):
    log = _run(xvfb, tmp_path / "out", "cornell", "radiosity,pathtrace", tmp_path / "cache")
    out = tmp_path / "out"
    assert log["options"]["radiosity"]["solver"] == "progressive"

    # radiosity: several rounds shown before the solve ended, each a finite image, the last
    # the CLI's progressive-refinement image at the panel's camera
    shown = log["images"]["radiosity"]
    rounds = [k for k, s in enumerate(shown) if not s["job_done"] and s["status"].startswith("refining")]
    assert len(rounds) >= 3, shown[:5]
    images = [np.load(out / f"radiosity_{k}.npy") for k in range(len(shown))]
    assert all(np.isfinite(a).all() for a in images)
    scene = workbench.load_scene(ROOT / "scenes" / "cornell.toml")
    cam = panel_camera(scene.camera, SIZE)
    cli = workbench.render(scene.with_camera(cam), "radiosity", width=cam.width, height=cam.height,
                           solver="progressive").image
    assert shown[-1]["job_done"] and np.abs(images[-1] - cli).max() < 1e-4
    assert np.abs(images[rounds[0]] - cli).max() > 1e-2  # the first round is not the answer yet

    # its meter: shots done and the unshot energy falling, the bar drawn while it shoots, the
    # time left once the rate is known
    running = [f for f in log["frames"]["radiosity"] if f["done"] > 0 and not f["job_done"]]
    assert running and all(f["bar"] for f in running)
    assert any(f["status"].endswith(" left") for f in running)
    unshot = [_unshot(f["detail"]) for f in running]
    assert unshot[-1] < 0.5 * unshot[0]
    last = log["frames"]["radiosity"][-1]
    assert last["fraction"] == 1.0 and _unshot(last["detail"]) <= unshot[-1]

    # the path tracer: passes of done/256 spp with the time left, the bar while it refines
    frames = log["frames"]["pathtrace"]
    refining = [f for f in frames if f["done"] > 0 and not f["job_done"]]
    assert len(refining) >= 2 and all(f["bar"] and f["target"] == 256 for f in refining)
    assert all(f"{f['done']}/256 spp" in f["status"] for f in refining)
    assert any(f["status"].endswith(" left") for f in refining)
    assert frames[-1]["done"] == 256 and frames[-1]["job_done"]

    # the error plot's reference (the path tracer at 256 spp) is the panel's job: no job of its
    # own, the very image the panel shows
    assert log["reference"] == "pathtrace" and log["reference_shared"]
    assert log["reference_jobs_started"] == 0
    # while it refines the plot shows its bar: done/target and the time left
    bars = log["reference_bar"]
    assert bars and all("/256 spp" in b["message"] for b in bars)
    assert any(b["message"].endswith(" left") for b in bars)
    final = np.load(out / f"pathtrace_{len(log['images']['pathtrace']) - 1}.npy")
    assert np.array_equal(np.load(out / "reference.npy"), final)


def test_the_reference_is_stored_in_the_cache_and_the_next_window_loads_it(xvfb, tmp_path):
    cache = tmp_path / "cache"
    first = _run(xvfb, tmp_path / "first", "whitted", "phong", cache)
    assert first["reference"] == "raytrace" and first["reference_cached"] == "miss"
    assert first["reference_jobs_started"] == 1
    entries = cache_entries(cache)
    assert [(e["method"], e["width"]) for e in entries] == [("raytrace", SIZE)]
    second = _run(xvfb, tmp_path / "second", "whitted", "phong", cache)
    assert second["reference_cached"] == "hit" and "from the cache" in second["reference_message"]
    assert np.array_equal(np.load(tmp_path / "second" / "reference.npy"),
                          np.load(tmp_path / "first" / "reference.npy"))
    assert len(cache_entries(cache)) == 1


def _running(frames: list, phase: str) -> list:
    """The frames in which the job ran in ``phase`` (a prefix) with its bar drawn."""
    return [f for f in frames if f["phase"].startswith(phase) and f["bar"] and not f["job_done"]]


def test_hybrid_povray_and_mitsuba_show_each_step(xvfb, tmp_path):
    log = _run(xvfb, tmp_path / "out", "cornell_spheres", "hybrid,povray,mitsuba", tmp_path / "cache",
               "phases")
    frames = log["frames"]
    for m in ("hybrid", "mitsuba"):
        assert log["jobs"][m] == {"error": None, "done": True, "status": "done"}, m
    for m, fr in frames.items():  # no bar once a job is done
        assert not any(f["bar"] for f in fr if f["job_done"]), m

    # hybrid: the form factors' rows counted with the time left, then the solve, measured by
    # nothing: an indeterminate bar (a negative value) and the time elapsed
    hybrid = frames["hybrid"]
    rows = [f for f in _running(hybrid, "radiosity form factors") if 0 < f["done"] < f["target"]]
    assert rows and all(f["measured"] and f["bar_value"] == f["fraction"] for f in rows)
    # (the status line was written this frame before the script read the meter: a report may
    # have come between)
    assert all(re.match(rf"radiosity form factors: \d+/{f['target']} patches", f["status"]) for f in rows)
    assert any(f["status"].endswith(" left") for f in rows)
    solve = _running(hybrid, "radiosity solve")
    assert solve and all(not f["measured"] and f["bar_value"] < 0 for f in solve)
    said = [f["status"] for f in hybrid if f["status"].startswith("radiosity solve")]
    assert said and all(re.fullmatch(r"radiosity solve \(direct: no progress reported\): "
                                     r"\d+:\d\d elapsed", x) for x in said), said
    seen = [f["phase"].split(" (")[0] for f in hybrid if f["bar"]]
    order = ["radiosity form factors", "radiosity solve", "ray trace"]
    firsts = [seen.index(p) for p in order if p in seen]
    assert firsts == sorted(firsts) and len(firsts) >= 2, seen
    last = hybrid[-1]
    assert (last["phase"], last["done"], last["target"]) == ("ray trace", SIZE, SIZE)  # square camera

    # Mitsuba: its start-up reports no amount done (indeterminate), then samples per pixel
    mitsuba = frames["mitsuba"]
    starting = [f for f in _running(mitsuba, "Mitsuba") if not f["measured"]]
    assert starting and all(f["bar_value"] < 0 for f in starting)
    said = [f["status"] for f in mitsuba if re.match(r"Mitsuba [a-z]", f["status"])]
    assert said and all(re.search(r": \d+:\d\d elapsed$", x) for x in said), said
    last = mitsuba[-1]
    assert (last["phase"], last["done"], last["target"], last["unit"]) == ("Mitsuba", 64, 64, "spp")

    # POV-Ray: its own report, up to every pixel of the panel; where it is missing, the panel
    # says so in one line
    povray = frames["povray"]
    if shutil.which("povray") is None:
        assert "needs the POV-Ray 3.7 program" in log["jobs"]["povray"]["error"]
        return
    assert log["jobs"]["povray"] == {"error": None, "done": True, "status": "done"}
    assert _running(povray, "POV-Ray")
    last = povray[-1]
    assert (last["phase"], last["done"], last["target"]) == ("POV-Ray rendering", SIZE * SIZE, SIZE * SIZE)
