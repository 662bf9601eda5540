"""What a user sees (issue 18, item 9): the default view of ``workbench ui`` in a 1280 x 720
window under Xvfb, dumped from the X server by ``xwd`` (``sessions.Screens``, a subprocess as in
test_ui.py).  The screenshot must hold the panels at the scene camera's aspect, the difference
panel and the error plot, with nothing past the window's edges.  With
``WORKBENCH_UPDATE_SCREENSHOT=1`` it becomes the README's screenshot (docs/images/ui.png)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command
from PIL import Image

from workbench.app.ui.screenshot import read_xwd

pytestmark = pytest.mark.gl
ROOT = Path(__file__).resolve().parents[3]
WINDOW = (1280, 720)
IMPLOT_COLOURS = ((76, 114, 176), (221, 132, 82))
"""The first colours of implot's default colour map: the plot's first two methods."""


@pytest.fixture(scope="module")
def screen(xvfb, tmp_path_factory):
    if shutil.which("xwd") is None:
        pytest.fail("xwd missing: workbench.sh installs x11-apps")
    out = tmp_path_factory.mktemp("screens")
    update = bool(os.environ.get("WORKBENCH_UPDATE_SCREENSHOT"))
    # 128 px panels (shown scaled up) keep the ray trace and the plot's reference short; the
    # README's screenshot is the real default (256 px)
    size = [] if update else ["--size", "128"]
    p = subprocess.run([*ui_command(), "whitted",
                        "--window", f"{WINDOW[0]}x{WINDOW[1]}", "--script", script_of("Screens"),
                        "--out", str(out), *size],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=400)
    assert p.returncode == 0, p.stderr[-2000:]
    log = json.loads((out / "summary.json").read_text())["script"]
    if update:
        shutil.copy(out / "screen.png", ROOT / "docs" / "images" / "ui.png")
    return out, log, np.asarray(Image.open(out / "screen.png"))[..., :3].astype(int)


def test_read_xwd_decodes_a_truecolor_dump():
    h, w = 2, 3
    pixels = np.array([[0x00FF0000, 0x0000FF00, 0x000000FF], [0x00102030, 0, 0x00FFFFFF]], "<u4")
    head = np.zeros(25, ">u4")
    head[:25] = [100 + 4, 7, 2, 24, w, h, 0, 0, 32, 0, 32, 32, 4 * w, 4, 0xFF0000, 0xFF00, 0xFF,
                 8, 0, 0, w, h, 0, 0, 0]
    data = head.tobytes() + b"win\0" + pixels.tobytes()
    rgb = read_xwd(data)
    assert rgb.tolist() == [[[255, 0, 0], [0, 255, 0], [0, 0, 255]],
                            [[0x10, 0x20, 0x30], [0, 0, 0], [255, 255, 255]]]
    with pytest.raises(ValueError):
        read_xwd(data[:50])


def test_the_screen_is_the_window_and_nothing_runs_past_its_edges(screen):
    _, log, shot = screen
    assert not log["timed_out"]
    assert shot.shape == (WINDOW[1], WINDOW[0], 3)
    assert log["cut"] == []  # every widget's right edge inside its window
    for name, win in log["windows"].items():
        if win.get("drawn"):
            (x, y), (w, h) = win["pos"], win["size"]
            assert x >= 0 and y >= 0 and x + w <= WINDOW[0] + 0.5 and y + h <= WINDOW[1] + 0.5, name


def _on_screen(out: Path, shot: np.ndarray, name: str, rect) -> float:
    """Share of the item's pixels on screen that show its display texture (scaled nearest)."""
    x0, y0, x1, y1 = (round(v) for v in rect)
    shown = np.load(out / f"shown_{name}.npy").astype(int)
    h, w = shown.shape[:2]
    iy = np.minimum(((np.arange(y1 - y0) + 0.5) * h / (y1 - y0)).astype(int), h - 1)
    ix = np.minimum(((np.arange(x1 - x0) + 0.5) * w / (x1 - x0)).astype(int), w - 1)
    return float((shot[y0:y1, x0:x1] == shown[iy][:, ix]).all(-1).mean())


def test_panels_and_difference_on_screen_at_the_cameras_aspect(screen):
    out, log, shot = screen
    assert log["methods"] == ["phong", "raytrace"]  # the first view: the comparison
    cw, ch = log["camera"]
    assert abs(cw / ch - 4 / 3) < 0.01  # whitted's camera
    rects = dict(log["blits"])
    assert set(rects) == {"phong", "raytrace", "difference"}
    for name, (x0, y0, x1, y1) in rects.items():
        assert abs((x1 - x0) / (y1 - y0) - cw / ch) < 0.03, name
        assert (x1 - x0) >= cw, name  # at least at the render size, not a thumbnail
        assert _on_screen(out, shot, name, rects[name]) > 0.97, name
    assert log["windows"]["Difference"]["drawn"]


def test_error_plot_on_screen(screen):
    _, log, shot = screen
    win = log["windows"]["Error plot"]
    assert win["drawn"]
    assert log["plot_points"] == {"phong": 1, "raytrace": 1}
    (x, y), (w, h) = win["pos"], win["size"]
    region = shot[round(y):round(y + h), round(x):round(x + w)]
    for colour in IMPLOT_COLOURS:  # each method's legend entry and marker
        assert (region == colour).all(-1).sum() >= 20, colour
