"""The error plot's error split (issue #13 item 5, in the window): beside each method's total
error (against the full reference) its error against its matched reference, as a dashed
"vs matched" line; the matched reference renders on its own board and a total point never
waits for it (a first attempt queued the total point only with its matched error, and the
pyrender panel's point then waited for a reference it never gets)."""
from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from workbench.app.ui.plot import MATCHED_SUFFIX, ErrorPlot, dashed, plotted_lines, track
from workbench.app.ui.state import new_state
from workbench.compare import reference
from workbench.compare.metrics import metrics
from workbench.renderers import base, registry


def test_matched_points_add_a_line_after_the_methods_own():
    plot = ErrorPlot()
    pt = {"seconds": 0.5, "rmse": 0.1, "flip": 0.2}
    opts = (("tessellation", 6),)
    plot.points = {"phong": {opts: pt}, "flat": {opts: pt}}
    plot.matched_points = {"phong": {opts: {**pt, "rmse": 0.01}}}
    lines = plotted_lines(plot, ["phong", "flat"], "rmse")
    assert list(lines) == ["phong", "phong" + MATCHED_SUFFIX, "flat"]
    assert lines["phong" + MATCHED_SUFFIX][1].tolist() == [0.01] and lines["phong"][1].tolist() == [0.1]


def test_dashes_lie_on_the_log_log_line_and_cover_half_of_it():
    xs, ys = np.array([1.0, 100.0, 1000.0]), np.array([0.1, 0.001, 0.01])
    dx, dy = dashed(xs, ys, dashes=5)
    gaps = np.isnan(dx)
    assert np.array_equal(gaps, np.isnan(dy)) and gaps.sum() == 2 * 5  # a break after each dash
    pieces = np.split(np.c_[np.log10(dx), np.log10(dy)], np.flatnonzero(gaps))
    pieces = [p[~np.isnan(p[:, 0])] for p in pieces if (~np.isnan(p[:, 0])).sum()]
    assert len(pieces) == 10 and all(len(p) == 2 for p in pieces)
    lx, ly = np.log10(xs), np.log10(ys)
    total = 0.0
    for k, p in enumerate(pieces):
        seg = k // 5  # each dash lies on its segment of the polyline (log coordinates)
        d = np.array([lx[seg + 1] - lx[seg], ly[seg + 1] - ly[seg]])
        rel = p - [lx[seg], ly[seg]]
        assert np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]).max() < 1e-9
        total += np.linalg.norm(p[1] - p[0]) / np.linalg.norm(d)
    assert abs(total - 1.0) < 1e-9  # half of each of the two segments
    assert dashed(xs[:1], ys[:1])[0].size == 0


class SlowReference:
    """A matched reference registered by the test: one grey image, rendered only once the
    test lets it (``release``)."""

    name = "slow_ref"
    ui_kind = "cpu"
    knob = base.Knob("level", (1,), 1)
    options = {"level": base.Option(int, 1)}
    memory_options = ()
    release = threading.Event()

    def estimate_bytes(self, scene, width, height, **options):
        return 64 * width * height + 1

    def render(self, scene, width, height, level=1):
        assert self.release.wait(60)
        return base.RenderResult(self.name, np.full((height, width, 3), 0.5, np.float32))


@pytest.fixture
def slow_matched(monkeypatch):
    """Phong's matched reference is :class:`SlowReference`."""
    monkeypatch.setitem(registry.BUILTIN, "slow_ref", f"{__name__}:SlowReference")
    monkeypatch.setitem(reference.MATCHED, "phong", ("slow_ref", {}, "a slow test reference"))
    monkeypatch.setattr(SlowReference, "release", threading.Event())
    yield SlowReference
    SlowReference.release.set()
    base._instances.pop("slow_ref", None)


def _frames_until(state, done, seconds=90.0) -> bool:
    deadline = time.monotonic() + seconds
    while not done() and time.monotonic() < deadline:
        state.frame += 1
        state.errors.shown = state.frame
        track(state)
        time.sleep(0.02)
    return done()


def test_a_total_point_does_not_wait_for_the_matched_reference(slow_matched):
    state = new_state("whitted", ["phong"], panel_size=16)
    state.options["phong"]["standins"] = "off"  # matched: the table's entry (MATCHED)
    shape = (state.camera.height, state.camera.width, 3)
    image = np.linspace(0.0, 1.0, int(np.prod(shape)), dtype=np.float32).reshape(shape)
    state.images["phong"], state.timings["phong"] = image, 0.01
    plot = state.errors
    try:
        assert _frames_until(state, lambda: "phong" in plot.points)
        assert plot.reference == "raytrace" and "phong" not in plot.matched_points
        # the plot says what it waits for, and the window keeps waking for it
        assert "phong's slow_ref" in plot.matched_message and plot.busy(state.frame)
        slow_matched.release.set()
        assert _frames_until(state, lambda: "phong" in plot.matched_points)
        (total,), (split,) = plot.points["phong"].values(), plot.matched_points["phong"].values()
        grey = np.full(shape, 0.5, np.float32)
        assert np.isclose(split["rmse"], metrics(image, grey)["rmse"], rtol=1e-6)
        assert np.isclose(total["rmse"], metrics(image, plot.ref_image)["rmse"], rtol=1e-6)
        assert plot.matched_message == "" and not plot.busy(state.frame + 5)
        assert list(plotted_lines(plot, ["phong"], "rmse")) == ["phong", "phong" + MATCHED_SUFFIX]
    finally:
        plot.shutdown()
