"""The live plot of error against run time for the methods on screen (implot).

The reference is the compare module's (:func:`workbench.compare.reference.candidates`, first
that renders, at its finest knob value, :func:`~workbench.compare.reference.finest_options`),
rendered for the current scene and camera in a background job of its own
(:class:`~.jobs.JobBoard`) once the camera has been still for :data:`SETTLE_SECONDS`, and
only while the plot's window is shown (a reference can take long: radiosity or hybrid at the
finest patches, which cannot be cancelled midway, so closing the window waits for it).  Each
panel whose image is final (a raster draw, a finished CPU job) gives one point per knob
setting: its run time and :func:`workbench.compare.metrics.metrics` against the reference
(RMSE, PSNR, FLIP), computed in a worker process: ``flip_evaluator`` holds the GIL (a 256 x 256
evaluation, ~0.2 s, stalled the UI thread for as long when it ran in a thread).  The UI thread
only copies images and reads finished results; a change of scene or camera starts a new set of
points.
"""
from __future__ import annotations

import multiprocessing as mp
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

import numpy as np

from .jobs import job_key
from .state import AppState, ErrorPlot, choosable_methods, method_kind

SETTLE_SECONDS = 0.3
"""The camera and scene must stay unchanged this long before the reference render starts."""
METRICS = ("rmse", "flip")
FLOOR = 1e-6
"""Errors are drawn at least this large on the log axis (the reference itself has error 0)."""
MARGIN = 1.5
CLEAR_FILLS = ("frame_bg", "plot_bg", "legend_bg")
"""implot colours drawn fully transparent (imgui skips such fills): the plot shows the window
background instead of painting its frame, plot area and legend, which on llvmpipe cost
~2.4 ms of CPU per frame (9.0-9.4 against 11.5-11.8 ms for a whole 1600 x 860 frame)."""


def _final_image(state: AppState, method: str) -> tuple[np.ndarray, float] | None:
    """(image, run time) of a panel whose image is final for the current request, else None."""
    kind = method_kind(state, method)
    if kind == "gl":
        if method not in state.images or method not in state.timings:
            return None
        return np.array(state.images[method], np.float32), state.timings[method]
    if kind == "child":
        proc = state.pyrender
        current = (state.scene_version, state.camera, tuple(sorted(state.options[method].items())))
        if proc is None or proc.image_key != current:
            return None
        return np.asarray(proc.image, np.float32), proc.seconds
    job = state.jobs.current.get(method)
    key = job_key(state.scene, state.camera, method, state.options[method])
    if job is None or job.key != key or job.image is None or job.seconds is None:
        return None
    return job.image, job.seconds


def _reference(state: AppState, plot: ErrorPlot) -> np.ndarray | None:
    """The reference image of the current key once rendered (requests it meanwhile)."""
    from ...compare.reference import candidates, finest_options
    from .frames import tiled
    from .jobs import JobBoard
    if plot.ref_image is not None:
        return plot.ref_image
    if time.perf_counter() - plot.since < SETTLE_SECONDS:
        return None
    if plot.board is None:
        plot.board = JobBoard()
    if not plot.candidates:
        plot.candidates = [m for m, _ in candidates(state.scene)]
    while plot.candidates:
        m = plot.candidates[0]
        plot.reference, plot.ref_options = m, finest_options(m)
        job = plot.board.request(state.scene, state.camera, m, plot.ref_options, tiled=tiled(m))
        if job.cancelled.is_set():  # the previous key's job, still ending: wait for it
            plot.message = "rendering the reference..."
            return None
        if job.error is None:
            break
        plot.candidates.pop(0)  # does not apply to this scene: the next in the rule's order
    else:
        plot.message, plot.gave_up = "no reference: no method renders this scene", True
        return None
    if job.image is None:
        plot.message = f"rendering the reference: {plot.reference} ({options_text(plot.ref_options)})..."
        return None
    plot.ref_image = job.image
    plot.message = (f"reference: {plot.reference} ({options_text(plot.ref_options)}), "
                    f"{job.seconds:.2f} s")
    return plot.ref_image


def options_text(options: dict) -> str:
    """``{"max_depth": 12}`` -> ``"max_depth=12"`` (the plot's header and labels)."""
    return ", ".join(f"{k}={v}" for k, v in options.items())


MARKERS = ("circle", "square", "diamond", "up", "down", "left", "right", "cross", "plus",
           "asterisk")
"""implot marker of each method, by its place in the registry (the same shape every frame)."""


def marker_of(method: str) -> str:
    """The name of ``method``'s marker in :data:`MARKERS` (stable: by registry order)."""
    allowed = choosable_methods()
    k = allowed.index(method) if method in allowed else len(allowed)
    return MARKERS[k % len(MARKERS)]


def plotted_lines(plot: ErrorPlot, methods, metric: str) -> dict:
    """{method: (run times in ms, errors)} of the methods on screen (a removed panel's line
    leaves the legend), each sorted by run time, errors at least :data:`FLOOR`."""
    lines = {}
    for m in methods:
        rows = sorted(plot.points.get(m, {}).values(), key=lambda p: p["seconds"])
        if rows:
            lines[m] = (np.array([p["seconds"] * 1e3 for p in rows]),
                        np.maximum(np.array([p[metric] for p in rows]), FLOOR))
    return lines


def _evaluate(image: np.ndarray, reference: np.ndarray) -> dict:
    from ...compare.metrics import metrics
    return metrics(image, reference)


def track(state: AppState) -> None:
    """Per frame: follow scene and camera, request the reference, queue the new final images
    for evaluation and collect finished evaluations.  Never waits."""
    plot = state.errors
    key = (state.scene_version, state.camera)
    if key != plot.key:
        if plot.board is not None:
            for job in plot.board.current.values():
                job.cancelled.set()
        plot.key, plot.since, plot.ref_image, plot.candidates = key, time.perf_counter(), None, []
        plot.gave_up = False
        plot.points, plot.pending, plot.failed = {}, {}, {}
    for (m, opts), fut in list(plot.pending.items()):
        if fut.done():
            del plot.pending[(m, opts)]
            if fut.exception() is None:
                plot.points.setdefault(m, {})[opts] = fut.result()
            else:  # kept as failed: not submitted again for this key
                plot.failed[(m, opts)] = f"{m}: error evaluation failed ({fut.exception()})"
                plot.message = plot.failed[(m, opts)]
    if plot.shown < state.frame - 1:  # the plot's window is hidden: no reference render
        return
    ref = _reference(state, plot)
    if ref is None:
        return
    for m in state.methods:
        opts = tuple(sorted(state.options[m].items()))
        if opts in plot.points.get(m, {}) or (m, opts) in plot.pending or (m, opts) in plot.failed:
            continue
        final = _final_image(state, m)
        if final is None or final[0].shape != ref.shape:
            continue
        image, seconds = final
        if plot.pool is None:
            plot.pool = ProcessPoolExecutor(1, mp_context=mp.get_context("spawn"))
        label = ", ".join(f"{k} {v}" for k, v in opts)
        try:
            plot.pending[(m, opts)] = plot.pool.submit(_point, image, ref, seconds, label)
        except BrokenProcessPool:  # the worker died (e.g. out of memory): a new one next time
            plot.pool.shutdown(wait=False, cancel_futures=True)
            plot.pool = None
            plot.failed[(m, opts)] = plot.message = f"{m}: the error-evaluation process died"


def _point(image: np.ndarray, reference: np.ndarray, seconds: float, label: str) -> dict:
    return {**_evaluate(image, reference), "seconds": float(seconds), "label": label}


def log_limits(values: np.ndarray) -> tuple[float, float]:
    """Axis range of positive ``values`` on a log axis: a factor :data:`MARGIN` beyond them,
    and at least one decade (so that the axis has a labelled tick)."""
    lo, hi = float(values.min()) / MARGIN, float(values.max()) * MARGIN
    if hi < 10.0 * lo:
        mid = np.sqrt(lo * hi)
        lo, hi = mid / np.sqrt(10.0), mid * np.sqrt(10.0)
    return lo, hi


def error_plot(state: AppState) -> None:
    """Log-log plot: one line per method through its knob settings, run time on x."""
    from imgui_bundle import imgui, implot
    plot = state.errors
    plot.shown = state.frame
    imgui.set_next_item_width(100)
    changed, k = imgui.combo("error", METRICS.index(plot.metric), list(METRICS))
    if changed:
        plot.metric = METRICS[k]
    imgui.same_line()
    imgui.push_text_wrap_pos(0.0)
    imgui.text_disabled(plot.message)
    imgui.pop_text_wrap_pos()
    lines = plotted_lines(plot, state.methods, plot.metric)
    for name in CLEAR_FILLS:
        implot.push_style_color(getattr(implot.Col_, name), imgui.ImVec4(0.0, 0.0, 0.0, 0.0))
    if implot.begin_plot("##error against run time", imgui.ImVec2(-1, -1)):
        implot.setup_axes("run time (ms)", plot.metric)
        implot.setup_legend(implot.Location_.north_east, implot.LegendFlags_.outside)
        implot.setup_axis_scale(implot.ImAxis_.x1, implot.Scale_.log10)
        implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
        if lines:
            xs, ys = (np.concatenate([v[k] for v in lines.values()]) for k in (0, 1))
            implot.setup_axes_limits(*log_limits(xs), *log_limits(ys), implot.Cond_.always)
        else:  # 1 ms to 1 s, errors 1e-3 to 1
            implot.setup_axes_limits(1.0, 1e3, 1e-3, 1.0, implot.Cond_.always)
        for m, (xs, ys) in lines.items():
            spec = implot.Spec(marker=getattr(implot.Marker_, marker_of(m)), marker_size=5)
            implot.plot_line(m, xs, ys, spec)
        implot.end_plot()
    implot.pop_style_color(len(CLEAR_FILLS))
