"""Display modes and stale images during a camera drag (issue 18, item 5).

The GPU pass of ``workbench.app.ui.display_modes`` is checked in the test process's headless
context against ``core.display`` (the CLI's numbers); the drag itself runs in the window under
Xvfb (``sessions.DragCheck``, a subprocess as in test_ui.py).  Before: every frame of a drag
ran the indexed mode on the CPU (0.3-3 s for a 512 px panel: 1-6 fps), and a restarted ray
trace blanked its panel until its bands came.  The drag runs at full resolution
(``--drag-resolution full``: the probe compares pixels of the panels' size)."""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command

from workbench.app.ui.display_modes import LUT_SHIFT, ModeDisplay, clut_table, encoded8
from workbench.core.display import apply_display_mode, display_mode, nearest
from workbench.core.imageio import to_srgb8

ROOT = Path(__file__).resolve().parents[3]


def _image(h: int = 48, w: int = 64) -> np.ndarray:
    """A smooth linear image over [0, 1.1] with a dark corner (values past 1 clip)."""
    y, x = np.mgrid[0:h, 0:w] / np.array([h - 1, w - 1])[:, None, None]
    return np.stack([1.1 * x, y * y, 0.5 * (1 - x) * y + 0.02], -1).astype(np.float32)


def _run_pass(ctx, image: np.ndarray, mode: str, table=None) -> np.ndarray:
    md = ModeDisplay(ctx)
    h, w = image.shape[:2]
    src = ctx.texture((w, h), 3, np.ascontiguousarray(image).tobytes(), dtype="f4")
    dst = ctx.texture((w, h), 4)
    tex = None if table is None else md.table(("t", mode), table)
    md.run(src, False, dst, display_mode(mode), tex)
    out = np.frombuffer(dst.read(), np.uint8).reshape(h, w, 4)[..., :3].copy()
    for obj in (src, dst):
        obj.release()
    md.release()
    return out


@pytest.mark.parametrize("mode", ["direct16-555", "direct16-565", "direct16-565-bayer",
                                  "direct16-555-bayer"])
def test_gpu_direct_modes_are_the_cli_modes(gl_ctx, mode):
    image = _image()
    shown = _run_pass(gl_ctx, image, mode)
    cli = to_srgb8(apply_display_mode(image, mode))
    diff = np.abs(shown.astype(int) - cli.astype(int))
    # float32 pow on the GPU against float64: a level may flip at a rounding tie, rarely
    assert diff.max() <= 8 and (diff.max(-1) > 0).mean() < 0.005, (diff.max(), (diff > 0).mean())


def test_clut_table_holds_the_nearest_entry_of_each_cell_centre():
    palette = np.array([[0, 0, 0], [1, 1, 1], [1, 0, 0], [0.2, 0.6, 0.4]])
    t = clut_table(palette)
    n, step = 256 >> LUT_SHIFT, 1 << LUT_SHIFT
    assert t.shape == (n, n, n, 3)
    for r, g, b in [(0, 0, 0), (n - 1, 0, 0), (3, 20, 9), (n - 1, n - 1, n - 1)]:
        centre = (np.array([r, g, b]) * step + (step - 1) / 2) / 255
        want = palette[nearest(centre[None], palette)[0]]
        assert np.array_equal(t[b, g, r], np.round(want * 255).astype(np.uint8))


def test_gpu_indexed_drag_view_uses_the_clut_within_one_cell(gl_ctx):
    """During a drag an indexed panel maps each pixel through the 3D table: every colour is
    a CLUT entry, and the entry is the nearest one up to the cell's size (a point x of a cell
    of centre c maps to p = nearest(c): |x - p| <= |x - q| + 2 |x - c| for the true nearest q)."""
    image = _image()
    palette = np.unique(encoded8(apply_display_mode(image, "indexed16-mediancut")).reshape(-1, 3),
                        axis=0)
    shown = _run_pass(gl_ctx, image, "indexed16-mediancut", palette).reshape(-1, 3)
    entries = np.round(palette * 255).astype(np.uint8)
    assert all((entries == c).all(-1).any() for c in np.unique(shown, axis=0))
    x = encoded8(image).reshape(-1, 3)
    q = palette[nearest(x, palette)]
    p = shown / 255.0
    half_cell = np.sqrt(3) * ((1 << LUT_SHIFT) - 1) / 2 / 255
    slack = np.linalg.norm(x - p, axis=-1) - np.linalg.norm(x - q, axis=-1)
    assert slack.max() <= 2 * half_cell + 1e-6
    assert (slack > 1e-9).mean() < 0.1  # mostly the nearest entry itself


@pytest.mark.gl
def test_drag_with_an_indexed_mode_and_a_ray_traced_panel(xvfb, tmp_path):
    p = subprocess.run([*ui_command(), "whitted",
                        "--methods", "flat,phong,raytrace", "--size", "96", "--drag-resolution", "full",
                        "--script", script_of("DragCheck"), "--out", str(tmp_path)],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=400)
    assert p.returncode == 0, p.stderr[-2000:]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["threads"] == ["MainThread"]
    log = summary["script"]
    assert log["exact_before_drag"] and log["exact_after_rest"], log
    drag = log["drag"][1:]  # the first entry shows the frame before the drag's first draw
    assert len(drag) >= 6
    for frame in drag:
        # no exact (CPU) computation during the drag: the GPU's CLUT view, 16 entries at most
        assert frame["exact_started"] == 0
        assert set(frame["kinds"].values()) == {"fast"}, frame["kinds"]
        assert max(frame["colours"].values()) <= 16
        # the ray-traced panel keeps its image; the probe reads what each panel holds (its
        # one-pixel read equals the full image's pixel), not zeros
        assert frame["raytrace_kept"]
        for m, values in frame["probe"].items():
            assert np.allclose(values, frame["probe_full"][m], atol=1e-6), m
        assert np.abs(frame["probe"]["raytrace"]).max() > 0
    # the restarted ray trace drew its bands over the old image: no row went black
    assert log["raytrace_black_rows"] == 0
    for m in ("flat", "phong"):  # at rest, exactly the CLI's mode
        assert np.array_equal(np.load(tmp_path / f"shown_{m}.npy"), np.load(tmp_path / f"cli_{m}.npy"))


@pytest.mark.gl
def test_the_difference_pauses_and_says_so_while_the_cameras_differ(xvfb, tmp_path):
    """Issue #29, item 7: during a drag the Phong panel follows the camera while the ray
    tracer's keeps its previous image; the difference view then keeps the map of the last
    camera both had (not one of a moving raster against a still ray trace) and says so; once
    the ray trace at the new camera is done it is live again: the map of the two panels."""
    from workbench.compare.metrics import error_map
    out = tmp_path / "ui"
    p = subprocess.run([*ui_command(), "whitted", "--methods", "phong,raytrace", "--size", "64",
                        "--script", script_of("DiffPause"), "--out", str(out)],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=400)
    assert p.returncode == 0, p.stderr[-2000:]
    log = json.loads((out / "summary.json").read_text())["script"]
    assert log["before_status"] is None and log["after_status"] is None
    assert len(log["drag"]) == 3
    for frame in log["drag"]:
        assert frame["kept"], frame  # the map of before the drag, not recomputed
        assert frame["status"].startswith("paused: phong and raytrace show different cameras "
                                          "(raytrace re-renders)"), frame
    for phase in ("before", "after"):
        ph, rt, diff = (np.load(out / f"{phase}_{m}.npy") for m in ("phong", "raytrace", "difference"))
        assert np.abs(diff - error_map(ph, rt, "abs")).max() <= 1e-6, phase
    # the drag moved the camera: the maps before and after are of different images
    assert np.abs(np.load(out / "before_phong.npy") - np.load(out / "after_phong.npy")).max() > 0.05
