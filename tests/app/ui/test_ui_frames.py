"""GL panels kept on the GPU (``workbench.app.ui.panel_refresh``, ``panel_gpu``,
``panel_show``): under Xvfb the ``gpu_panels`` script (a subprocess, as in test_ui.py) checks
that a frame with nothing changed draws no GL panel and reads no pixels back, that a camera
change redraws each GL panel once, and that what imgui shows (the RGBA8 display texture) is
the CLI's image of the same camera within one 8-bit level; closing leaves no thread.  The lazy image store is tested on its own."""
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
from workbench.app.ui import camera as cam
from workbench.app.ui.images import PanelImages
from workbench.app.ui.state import panel_camera
from workbench.core.imageio import to_srgb8

ROOT = Path(__file__).resolve().parents[3]
RASTER = ("flat", "gouraud", "phong")
SIZE = 96


@pytest.fixture(scope="module")
def gpu_session(xvfb, tmp_path_factory):
    out = tmp_path_factory.mktemp("ui_frames")
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", "flat,gouraud,phong,raycast", "--size", str(SIZE),
                        "--script", script_of("GpuPanels"), "--out", str(out), "--frames", "200"],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    return out, json.loads((out / "summary.json").read_text())


pytestmark = pytest.mark.gl


def test_static_frames_draw_nothing_and_a_camera_change_redraws_once(gpu_session):
    _, summary = gpu_session
    log = summary["script"]
    start, static, orbit = log["frame2"], log["frame5"], log["frame7"]
    assert sorted(start["draws"]) == sorted(RASTER)
    assert all(start["draws"][m] >= 1 for m in RASTER)
    assert static["draws"] == start["draws"]          # frames 2..5: nothing changed
    # and no pixel came back from the GPU, but for the images the error plot took once its
    # reference was there (from the reference cache it can be at once: a read per GL panel)
    taken = set(static["plot_taken"]) - set(start["plot_taken"])
    assert 0 <= static["reads"] - start["reads"] <= len(taken & set(RASTER))
    assert orbit["draws"] == {m: static["draws"][m] + 1 for m in RASTER}


def test_shown_panels_are_the_cli_images(gpu_session):
    out, summary = gpu_session
    scene = workbench.load_scene("whitted")
    orbited = cam.orbit(panel_camera(scene.camera, SIZE), 0.3, 0.1)
    H, W = orbited.height, orbited.width
    assert (W, H) == (SIZE, SIZE * 3 // 4)  # whitted's 4:3, not a square crop
    assert np.allclose(summary["script"]["position"], orbited.position)
    for m in RASTER:
        shown = np.load(out / f"shown_{m}.npy")
        assert shown.shape == (H, W, 4) and (shown[..., 3] == 255).all()
        # the panels draw what the CLI draws with their options (Gouraud's and Phong's
        # stand-ins on by default: environment maps, blending, shadow maps on whitted)
        cli = workbench.render(replace(scene, camera=orbited), m, width=W, height=H).image
        expected = to_srgb8(cli)
        assert expected.std() > 10, m  # a real picture, not a flat colour
        assert np.abs(shown[..., :3].astype(int) - expected).max() <= 1, m


def test_panels_are_copied_into_the_window_where_imgui_laid_them_out(gpu_session):
    """The last frame's screenshot holds each panel's display texture at its item rectangle
    (blitted under imgui's drawing, top row on top)."""
    from PIL import Image
    out, summary = gpu_session
    shot = np.asarray(Image.open(out / "ui.png"))[..., :3].astype(int)
    rects = dict(summary["script"]["blits"])
    assert set(RASTER) | {"difference"} <= set(rects)
    for m in [*RASTER, "difference"]:
        x0, y0, x1, y1 = (round(v) for v in rects[m])
        shown = np.load(out / f"shown_{m}.npy")[..., :3].astype(int)
        h, w = shown.shape[:2]
        assert abs((x1 - x0) / (y1 - y0) - w / h) < 0.03, m  # the camera's aspect
        # scaled to the item by a nearest blit: window pixel (y, x) shows texel
        # (floor((y + 0.5) h / height), floor((x + 0.5) w / width)), up to rounding at edges
        iy = np.minimum(((np.arange(y1 - y0) + 0.5) * h / (y1 - y0)).astype(int), h - 1)
        ix = np.minimum(((np.arange(x1 - x0) + 0.5) * w / (x1 - x0)).astype(int), w - 1)
        expected = shown[iy][:, ix]
        assert (shot[y0:y1, x0:x1] == expected).all(-1).mean() > 0.97, m


def test_difference_view_on_the_gpu_is_the_cpu_error_map(gpu_session):
    from workbench.app.ui.panels import colour_scale
    from workbench.compare.metrics import error_map
    out, _ = gpu_session
    flat, phong = np.load(out / "image_flat.npy"), np.load(out / "image_phong.npy")
    err, shown = np.load(out / "image_difference.npy"), np.load(out / "shown_difference.npy")
    expected = error_map(flat, phong, "abs")
    assert expected.max() > 0.05  # flat and phong differ (faceted spheres)
    assert np.abs(err - expected).max() < 1e-5
    colours = colour_scale(expected, float(expected.max()))
    # same colour, or the neighbouring entry of the table where v / vmax rounds differently
    off = np.abs(shown[..., :3].astype(int) - colours).max(-1)
    step = np.abs(np.diff(colour_scale(np.linspace(0, 1, 256)[None], 1.0)[0].astype(int), axis=0)).max()
    assert off.max() <= step and (off > 0).mean() < 1e-3


def test_closing_leaves_no_thread(gpu_session):
    _, summary = gpu_session
    assert summary["threads"] == ["MainThread"]


def test_panel_images_read_pending_entries_once():
    calls = []
    images = PanelImages()

    def read():
        calls.append(1)
        return np.full((2, 2, 3), len(calls), np.float32)

    images.set_pending("flat", read)
    v = images.version("flat")
    assert "flat" in images and calls == [] and images.reads == 0  # membership reads nothing
    assert images["flat"][0, 0, 0] == 1 and images.get("flat")[0, 0, 0] == 1
    assert calls == [1] and images.reads == 1 and images.version("flat") == v
    images.set_pending("flat", read)                    # a new draw: read again on access
    assert images.version("flat") == v + 1 and images["flat"][0, 0, 0] == 2
    images["raycast"] = np.zeros((2, 2, 3), np.float32)
    assert sorted(images) == ["flat", "raycast"] and len(images) == 2
    del images["flat"]
    assert "flat" not in images and images.version("flat") == v + 2
    with pytest.raises(KeyError):
        images["flat"]


def test_job_restarts_wait_for_the_request_to_settle():
    """A changed request cancels the running job at once but starts its own only once it has
    stayed the same for ``settle`` seconds; a request that keeps changing (a drag) starts
    nothing; the first request of a method starts at once."""
    import time

    from workbench.app.ui.jobs import JobBoard
    scene = workbench.load_scene("whitted")
    board = JobBoard(settle=0.3)
    c0 = scene.camera.with_resolution(16, 16)
    first = board.request(scene, c0, "raycast", {}, tiled=True)
    assert board.count == 1 and not first.cancelled.is_set()
    first.thread.join(60)
    t0 = time.perf_counter()
    for k in range(1, 4):  # three different cameras in a row: the first job is cancelled
        job = board.request(scene, cam.orbit(c0, 0.1 * k, 0.0), "raycast", {}, tiled=True)
        assert job is first and first.cancelled.is_set()
    assert board.count == 1 and board.busy()  # a restart is pending
    last = cam.orbit(c0, 0.3, 0.0)
    while board.request(scene, last, "raycast", {}, tiled=True) is first:
        time.sleep(0.01)
    assert time.perf_counter() - t0 >= 0.3 and board.count == 2
    assert board.current["raycast"].key[1] == last
    board.join_all(60)
    assert not any(j.thread.is_alive() for j in board.started)


def test_job_board_forgets_ended_jobs_and_notifies():
    """A long session starts hundreds of jobs: the board keeps only the current ones and those
    still running (each holds its scene and images), and ``notify`` is called from the job's
    thread when tiles and the image arrive (the window wakes its idle loop with it)."""
    import threading

    from workbench.app.ui.jobs import JobBoard
    scene = workbench.load_scene("whitted")
    calls = []
    board = JobBoard(notify=lambda: calls.append(threading.current_thread().name))
    c0 = scene.camera.with_resolution(8, 8)
    for k in range(12):
        job = board.request(scene, cam.orbit(c0, 0.05 * k, 0.0), "raycast", {}, tiled=True)
        job.thread.join(60)
        assert job.image is not None
        board.request(scene, cam.orbit(c0, 0.05 * k, 0.0), "raycast", {}, tiled=True)
    assert board.count == 12 and len(board.started) == 1
    assert board.started[0] is board.current["raycast"]
    assert len(calls) >= 12 and set(calls) == {"ui-job-raycast"}
    board.join_all(60)


def test_a_request_back_at_a_cancelled_job_starts_it_again():
    """The error plot's reference stayed on "rendering the reference..." after a drag and a
    camera reset: the reset camera's request matched the job cancelled by the drag, and the
    board kept answering with that stopped job.  Now a cancelled job that had not ended is
    started again; one that had ended gives its image (and is no longer counted busy)."""
    from workbench.app.ui.jobs import JobBoard
    scene = workbench.load_scene("whitted")
    workbench.render(scene, "raytrace", width=8, height=8)  # compiled before: a job compiling
    # the kernels on a cold cache ran its one band to the end before it looked at the flag
    board = JobBoard()
    c0 = scene.camera.with_resolution(64, 64)
    first = board.request(scene, c0, "raytrace", {}, tiled=True)
    first.cancelled.set()  # the camera moved away (the plot's track cancels)
    first.thread.join(60)
    assert first.image is None
    again = board.request(scene, c0, "raytrace", {}, tiled=True)  # camera reset
    assert again is not first and not again.cancelled.is_set()
    again.thread.join(60)
    assert again.image is not None
    again.cancelled.set()  # cancelled after it ended
    assert board.request(scene, c0, "raytrace", {}, tiled=True) is again
    assert not board.busy()
    board.join_all(60)


def test_probe_reads_one_pixel_not_the_panel(gpu_session):
    """The pixel probe's read of a drawn GL panel is the pixel of the full read-back (same
    float32 value, row 0 on top) and does not read the whole image back."""
    out, summary = gpu_session
    probe = summary["script"]["probe"]
    assert probe["full_reads"] == 0 and probe["pixel_reads"] == 3 * len(probe["pixels"])
    for m in ("flat", "phong"):
        image = np.load(out / f"image_{m}.npy")
        for i, j, v in probe["pixels"][m]:
            assert np.array_equal(np.float32(v), image[i, j]), (m, i, j)
    assert len({tuple(p[2]) for p in probe["pixels"]["phong"]}) > 1  # not one colour


def test_panel_images_pixel_keeps_pending_entries():
    images = PanelImages()
    full = np.arange(2 * 3 * 3, dtype=np.float32).reshape(2, 3, 3)
    images.set_pending("flat", lambda: full, pixel=lambda i, j, shape: full[i, j] if shape == (2, 3) else None)
    assert np.array_equal(images.pixel("flat", 1, 2, (2, 3)), full[1, 2])
    assert images.pixel("flat", 0, 0, (4, 4)) is None
    assert images.reads == 0 and images.pixel_reads == 2  # still pending
    images["raycast"] = full  # a plain entry: indexed, size checked
    assert np.array_equal(images.pixel("raycast", 0, 1, (2, 3)), full[0, 1])
    assert images.pixel("raycast", 0, 1, (3, 3)) is None
    images.set_pending("gouraud", lambda: full)  # no pixel reader: the image is read once
    assert np.array_equal(images.pixel("gouraud", 1, 1, (2, 3)), full[1, 1]) and images.reads == 1


def test_frames_are_capped_only_while_a_background_job_runs():
    from workbench.app.ui.main import frame_rest
    from workbench.app.ui.state import FPS_CAP_WHILE_JOB
    assert FPS_CAP_WHILE_JOB > 30.0  # the window must keep 30 fps
    assert frame_rest(10.0, 10.005, 40.0, True) == pytest.approx(0.020)
    assert frame_rest(10.0, 10.030, 40.0, True) == 0.0  # a slow frame is not delayed further
    assert frame_rest(10.0, 10.005, 40.0, False) == 0.0
    assert frame_rest(10.0, 10.005, 0.0, True) == 0.0
    assert frame_rest(None, 10.005, 40.0, True) == 0.0


def test_a_job_is_not_taken_for_a_later_scene_and_removed_panels_are_cancelled():
    """Every light or material edit builds a new Scene: a job keyed on the old scene's id must
    never match a later scene (the job keeps its scene, so the id cannot be reused while it is
    current); a panel taken off the screen has its job cancelled and forgotten."""
    import gc
    from dataclasses import replace

    from workbench.app.ui.jobs import JobBoard
    base = workbench.load_scene("whitted")
    c0 = base.camera.with_resolution(8, 8)
    board = JobBoard(settle=0.0)
    job = board.request(replace(base), c0, "raycast", {}, tiled=True)  # its scene has no other owner
    job.thread.join(60)
    for _ in range(50):  # later scenes, each freed at once: none may match the job's key
        gc.collect()
        later = replace(base)
        assert later is not job.scene
        assert (id(later), c0, "raycast", ()) != job.key
    board.keep_only(["flat"])
    assert "raycast" not in board.current and job.cancelled.is_set() and not board.busy()
    board.join_all(60)


def test_path_tracer_panel_refines_pass_by_pass(monkeypatch):
    """The pathtrace panel's job is progressive: one sample per pixel per pass here, each
    pass's running image and noise shown (``notify`` each time), ending at the ``spp`` option
    with exactly the image of a session given all samples at once (same seed); a cancel stops
    it between passes."""
    from workbench.app.ui import jobs
    from workbench.renderers.pathtrace.session import PathTraceSession
    scene = workbench.load_scene("cornell")
    c = scene.camera.with_resolution(16, 16)
    monkeypatch.setattr(jobs, "PASS_SAMPLES", 16 * 16)
    seen = []
    board = jobs.JobBoard()
    job = board.request(scene, c, "pathtrace", {"spp": 8}, tiled=False)
    board.notify = None
    job.notify = lambda: seen.append((job.spp, job.noise))
    job.thread.join(120)
    assert job.error is None and job.progressive and job.spp == 8
    assert [s for s, _ in seen if s][-1] == 8 and len({s for s, _ in seen}) >= 6  # passes shown
    noises = [n for _, n in seen if n is not None]
    assert noises and noises[-1] == job.noise
    whole = PathTraceSession(replace(scene, camera=c), 16, 16).add_samples(8)
    assert np.array_equal(job.image, whole)
    stopped = board.request(scene, cam.orbit(c, 0.2, 0.0), "pathtrace", {"spp": 10**6}, tiled=False)
    stopped.cancelled.set()
    stopped.thread.join(120)
    assert stopped.image is None and stopped.spp < 10**6


def test_panel_images_tell_their_size_without_reading():
    """A scene switch changes the panels' aspect while a CPU or child panel still holds the
    previous scene's image: the difference view asks each image's size first (it crashed the
    window on two sizes)."""
    images = PanelImages()
    images["raytrace"] = np.zeros((96, 96, 3), np.float32)
    images.set_pending("phong", lambda: np.zeros((72, 96, 3), np.float32), shape=(72, 96))
    assert not images.has_shape("raytrace", (72, 96)) and images.has_shape("raytrace", (96, 96))
    assert images.has_shape("phong", (72, 96)) and not images.has_shape("phong", (96, 96))
    assert images.reads == 0  # a GL panel drawn before a switch, then hidden: still pending
