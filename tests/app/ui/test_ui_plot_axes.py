"""The error plot's axes and hover (issue #29, item 4): at 1024x600 the ticks were a run of
overlapping labels, and a panel that is its own reference (error 0) was drawn at 1e-6, the
axis stretched down to it.  The window under Xvfb (``sessions.PlotHover``) and the axis
functions with made-up label sizes."""
from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ui_command import script_of, ui_command

from workbench.app.ui.plot_axes import (ERROR_DECADES, error_label, error_limits, hover_text,
                                        log_ticks, nearest_point, time_label)

ROOT = Path(__file__).resolve().parents[3]


def _fits(values, labels, length, lo, hi, size_of, gap):
    px = [length * math.log10(v / lo) / math.log10(hi / lo) for v in values]
    return all(b - a >= (size_of(la) + size_of(lb)) / 2 + gap
               for a, b, la, lb in zip(px, px[1:], labels, labels[1:]))


def test_log_ticks_are_as_dense_as_their_labels_allow():
    size_of = lambda t: 7.0 * len(t)  # noqa: E731  (7 px a character)
    lo, hi = 0.3, 4e4  # 0.3 ms to 40 s
    counts = []
    for length in (60.0, 120.0, 300.0, 2000.0):
        values, labels = log_ticks(lo, hi, length, size_of, time_label, gap=6.0)
        assert all(lo <= v <= hi for v in values) and values == sorted(values)
        assert _fits(values, labels, length, lo, hi, size_of, 6.0), length
        counts.append(len(values))
    assert counts == sorted(counts) and counts[0] < counts[-1]
    # 2000 px holds 1-2-5 in each of the 5 decades; 300 px only decades ("1 ms" ... "10 s")
    assert counts[-1] > 6
    values, labels = log_ticks(lo, hi, 300.0, size_of, time_label, gap=6.0)
    assert labels == ["1 ms", "10 ms", "100 ms", "1 s", "10 s"]
    # an axis holding no 1-2-5 value gets its middle labelled
    assert log_ticks(2.1, 4.9, 300.0, size_of, time_label)[0] == [pytest.approx(math.sqrt(2.1 * 4.9))]


def test_labels_of_times_and_errors():
    assert [time_label(x) for x in (0.05, 2.0, 250.0, 1500.0, 1.2e5)] == \
        ["50 us", "2 ms", "250 ms", "1.5 s", "2 min"]
    assert [error_label(x) for x in (1e-4, 5e-6, 0.01, 0.5, 2.0)] == ["1e-4", "5e-6", "0.01", "0.5", "2"]


def test_the_error_axis_stops_above_a_zero_or_far_error():
    floor, lo, hi = error_limits(np.array([0.0, 0.02, 0.1]))
    assert floor == pytest.approx(0.02 / 1.5) and hi == pytest.approx(0.15)
    assert lo == pytest.approx(floor / 1.5)  # room for a marker drawn at the floor
    floor, _, _ = error_limits(np.array([1e-9, 0.1]))  # a far outlier does not stretch the axis
    assert floor == pytest.approx(0.1 / 10 ** ERROR_DECADES)
    assert error_limits(np.array([0.0]))[0] == 1e-3


def test_hover_names_method_time_error_settings_and_the_floor():
    pt = {"seconds": 0.0123, "rmse": 0.0, "psnr": float("inf"), "flip": 0.0, "label": "max_depth 12"}
    text = hover_text("raytrace", pt, "rmse", False, 1e-3)
    assert text.splitlines()[:3] == ["raytrace", "run time 12.3 ms", "rmse 0 against the reference"]
    assert "settings: max_depth 12" in text and "below the axis floor (1e-3): drawn at the floor" in text
    assert "floor" not in hover_text("phong", {**pt, "rmse": 0.2}, "rmse", True, 1e-3)
    assert nearest_point(np.array([[10.0, 10.0], [50.0, 40.0]]), (47.0, 44.0)) == 1
    assert nearest_point(np.array([[10.0, 10.0]]), (40.0, 40.0)) is None


@pytest.mark.gl
def test_the_plot_at_1024x600_hover_ticks_and_floor(xvfb, tmp_path):
    out = tmp_path / "ui"
    p = subprocess.run([*ui_command(), "whitted", "--methods", "phong,raytrace", "--size", "64",
                        "--window", "1024x600", "--script", script_of("PlotHover"), "--out", str(out)],
                       cwd=ROOT, env={**os.environ, "DISPLAY": xvfb}, capture_output=True,
                       text=True, timeout=400)
    assert p.returncode == 0, p.stderr[-2000:]
    log = json.loads((out / "summary.json").read_text())["script"]
    axes = log["axes"]
    (rt_seconds, rt_rmse), = log["points"]["raytrace"]
    (_, ph_rmse), = log["points"]["phong"]
    assert rt_rmse == 0.0 and ph_rmse > 0  # the ray tracer is the plot's reference
    # one positive error: the axis is the decade around it (and room for the floor's marker),
    # not down to 1e-6 for the zero
    assert axes["y"]["limits"] == pytest.approx([ph_rmse / math.sqrt(10) / 1.5, ph_rmse * math.sqrt(10)])
    # the tooltip of the ray tracer's point, drawn at the floor, says so
    lines = log["hover"].splitlines()
    assert lines[0] == "raytrace" and lines[1] == f"run time {time_label(rt_seconds * 1e3)}"
    assert "rmse 0 against the reference" in lines and lines[-1].startswith("below the axis floor")
    assert "settings: max_depth 12" in log["hover"]
    # labelled ticks: inside the plot area, none touching its neighbour
    x0, y0, w, h = axes["rect"]
    for axis, lo_px, hi_px in (("x", x0, x0 + w), ("y", y0, y0 + h)):
        ticks = axes[axis]["ticks"]
        assert ticks and all(lo_px - 1 <= t[2] <= hi_px + 1 for t in ticks), axis
        pos = sorted((t[2], t[3]) for t in ticks)
        assert all(b - a >= (sa + sb) / 2 for (a, sa), (b, sb) in zip(pos, pos[1:])), (axis, ticks)
    assert any(t[1].endswith(" ms") or t[1].endswith(" s") for t in axes["x"]["ticks"])
    assert "error plot" not in " ".join(log["cut"])
