"""A camera drag shows the images a fresh render at each camera gives (issue 18, item 5).

During a drag the GL panels draw every frame without waiting for their draws, are drawn into
the window straight from their linear images (one pass per panel, no display texture), and
the difference view's colour scale comes from a maximum reduced on the GPU; once the camera
rests each panel is drawn once more, timed, and shown from its display texture.  The
``drag_rest`` script (``sessions.DragRest``, a subprocess under Xvfb as in test_ui.py) drags
for six frames; here the panels' linear images, the window as the X server showed it in the
drag's last frame and the rested window are compared with the CLI's render at the final
camera.  The drag runs at full resolution (``--drag-resolution full``); the adapted
resolution's drag is checked by test_ui_drag_resolution.py."""
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
from workbench.app.ui.colours import colour_scale
from workbench.app.ui.state import panel_camera
from workbench.compare.metrics import error_map
from workbench.core.display import apply_display_mode
from workbench.core.imageio import to_srgb8

ROOT = Path(__file__).resolve().parents[3]
RASTER = ("flat", "gouraud", "phong")
SIZE, FRAMES = 96, 6
DISPLAY = {"gouraud": "direct16-565-bayer"}
"""The display mode the ``drag_rest`` script sets (the other panels: direct24)."""

pytestmark = pytest.mark.gl


@pytest.fixture(scope="module")
def drag(xvfb, tmp_path_factory):
    out = tmp_path_factory.mktemp("ui_drag_rest")
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", ",".join(RASTER), "--size", str(SIZE), "--drag-resolution", "full",
                        "--script", script_of("drag_rest"), "--out", str(out), "--frames", "100"],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    summary = json.loads((out / "summary.json").read_text())
    scene = workbench.load_scene("whitted")
    c = panel_camera(scene.camera, SIZE)
    for _ in range(FRAMES):
        c = cam.orbit(c, 0.05, 0.02)
    cli = {m: workbench.render(replace(scene, camera=c), m, width=c.width, height=c.height).image
           for m in RASTER}  # the panels' options are the CLI's defaults (stand-ins on)
    return out, summary["script"], c, cli


def _on_screen(shot: np.ndarray, rect, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(window pixels in ``rect``, ``image`` scaled to them by a nearest blit: window pixel
    (y, x) shows texel (floor((y + 0.5) h / height), floor((x + 0.5) w / width)))."""
    x0, y0, x1, y1 = (round(v) for v in rect)
    h, w = image.shape[:2]
    iy = np.minimum(((np.arange(y1 - y0) + 0.5) * h / (y1 - y0)).astype(int), h - 1)
    ix = np.minimum(((np.arange(x1 - x0) + 0.5) * w / (x1 - x0)).astype(int), w - 1)
    return shot[y0:y1, x0:x1], image[iy][:, ix]


def test_panels_after_a_drag_are_a_fresh_render_at_the_final_camera(drag):
    out, log, c, cli = drag
    assert np.allclose(log["position"], c.position)
    for m in RASTER:
        image = np.load(out / f"image_{m}.npy")
        assert image.shape == (c.height, c.width, 3)
        assert to_srgb8(cli[m]).std() > 10, m  # a real picture
        assert np.abs(to_srgb8(image).astype(int) - to_srgb8(cli[m])).max() <= 1, m


def test_the_window_shows_them_during_the_drag_and_at_rest(drag):
    """The drag's last frame (panels drawn from their linear images and encoded by the
    window's sRGB framebuffer, Gouraud's through a dithered 16-bit mode, the difference from
    the GPU's maximum) and the rested frame
    (display textures copied) both show the CLI's images through their modes and the CLI
    images' error map (flat against Gouraud, the view's first pair)."""
    from PIL import Image
    out, log, c, cli = drag
    err = error_map(cli["flat"], cli["gouraud"], "abs")
    assert err.max() > 0.01
    colours = colour_scale(err, float(err.max())).astype(int)
    step = np.abs(np.diff(colour_scale(np.linspace(0, 1, 256)[None], 1.0)[0].astype(int), axis=0)).max()
    assert log["window_srgb"]  # Mesa's window encodes sRGB: the drag used display_linear.frag
    during = np.asarray(Image.open(out / "drag_screen.png"))[..., :3].astype(int)
    rest = np.asarray(Image.open(out / "ui.png"))[..., :3].astype(int)
    for shot, rects in ((during, dict(log["drag_rects"])), (rest, dict(log["rest_rects"]))):
        assert set(RASTER) | {"difference"} <= set(rects)
        for m in RASTER:
            shown = apply_display_mode(cli[m], DISPLAY[m]) if m in DISPLAY else cli[m]
            got, want = _on_screen(shot, rects[m], to_srgb8(shown).astype(int))
            # equal but where a level rounds the other way (float32 pow on the GPU: a 16-bit
            # level, 8 levels of 255, at a rare tie) or the scaling's edges fall
            assert (np.abs(got - want).max(-1) <= 1).mean() > 0.97, m
        got, want = _on_screen(shot, rects["difference"], colours)
        assert (np.abs(got - want).max(-1) <= step).mean() > 0.97


def test_a_drag_draws_each_panel_once_a_frame_and_once_more_timed_at_rest(drag):
    _, log, _, _ = drag
    assert log["draws"] == {m: FRAMES + 1 for m in RASTER}, log["draws"]
    assert all(log["timed"].values()) and all(t > 0 for t in log["timings"].values())


def test_difference_statistics_reduced_on_the_gpu_are_the_map_s(window_ctx):
    """The colour scale's maximum and the printed mean come from display_stats.frag's
    reduction, not from a read-back of the map: the same maximum, and the sum up to float32
    rounding (at most one rounding per term added: |error| <= n eps sum); the map itself is
    read whole or one value at a time (the probe) only when asked."""
    from workbench.app.ui.display_passes import DisplayPasses
    from workbench.app.ui.panel_gpu import read_value, read_values
    bound = window_ctx.fbo  # the passes end on the stand-in screen, which the fixture releases
    passes = DisplayPasses(window_ctx)
    rng = np.random.default_rng(3)
    for w, h in [(512, 384), (13, 7), (1, 1)]:
        values = rng.random((h, w)).astype(np.float32) ** 3
        tex = window_ctx.texture((w, h), 1, values.tobytes(), dtype="f4")
        stats = passes.statistics(tex)
        assert stats.size == (1, 1)
        vmax, total = np.frombuffer(stats.read(), np.float32)[:2]
        assert vmax == values.max(), (w, h)
        exact = values.astype(np.float64).sum()
        assert abs(total - exact) <= values.size * np.finfo(np.float32).eps * exact, (w, h)
        assert np.array_equal(read_values(tex), values)
        i, j = h // 2, w - 1
        assert read_value(tex, i, j, (h, w))[0] == values[i, j]
        assert read_value(tex, i, j, (h + 1, w)) is None
        tex.release()
    passes.release()
    bound.use()
