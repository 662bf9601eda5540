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

The error split (:mod:`workbench.compare.reference`, README "Ground truth and the error split"):
each method's *matched* reference (the same physics as the method, at its limit:
:func:`~workbench.compare.reference.matched_spec`; a path-traced one at the path tracer's finest
knob here) renders as a job of its own, on a board per (reference method, options), and each
point also gets its error against it (the discretisation error) when it arrives, drawn as a
dashed "vs matched" line beside the method's total error.  The total point never waits for it;
while a matched reference renders, the plot says which and how far it is.
"""
from __future__ import annotations

import multiprocessing as mp
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

import numpy as np

from .jobs import job_key
from .state import AppState, ErrorPlot, choosable_methods, method_kind, short_name

SETTLE_SECONDS = 0.3
"""The camera and scene must stay unchanged this long before the reference render starts."""
METRICS = ("rmse", "flip")
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
    from .panel_refresh import tiled
    from .jobs import JobBoard
    if plot.ref_image is not None:
        return plot.ref_image
    if time.perf_counter() - plot.since < SETTLE_SECONDS:
        return None
    if plot.board is None:
        plot.board = JobBoard(cached=True, share=state.jobs)
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
        plot.message = (f"rendering the reference: {plot.reference} ({options_text(plot.ref_options)})"
                        + (f": {job.meter.text()}" if job.meter is not None and job.meter.first else "..."))
        return None
    plot.ref_image = job.image
    plot.message = (f"reference: {plot.reference} ({options_text(plot.ref_options)}), "
                    + ("from the cache" if job.cached == "hit" else f"{job.seconds:.2f} s"))
    return plot.ref_image


def reference_meter(plot: ErrorPlot):
    """The meter of the reference's job while it renders and reports progress, else None."""
    from .panel_refresh import running_meter
    job = None if plot.board is None or plot.ref_image is not None else plot.board.current.get(plot.reference)
    return None if job is None else running_meter(job)


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


MATCHED_SUFFIX = " vs matched"
"""Label suffix of a method's line of errors against its matched reference."""


def plotted_lines(plot: ErrorPlot, methods, metric: str) -> dict:
    """{label: (run times in ms, errors, the points)} of the methods on screen (a removed
    panel's line leaves the legend), each sorted by run time: the method's total errors under
    its name, its errors against its matched reference (where evaluated) under
    ``name + MATCHED_SUFFIX``, right after it.  Errors as evaluated (0 for the reference
    itself): the axis floor is the view's (:func:`.plot_axes.error_limits`)."""
    lines = {}
    for m in methods:
        for label, points in ((m, plot.points), (m + MATCHED_SUFFIX, plot.matched_points)):
            rows = sorted(points.get(m, {}).values(), key=lambda p: p["seconds"])
            if rows:
                lines[label] = (np.array([p["seconds"] * 1e3 for p in rows]),
                                np.array([p[metric] for p in rows], float), rows)
    return lines


def dashed(xs: np.ndarray, ys: np.ndarray, dashes: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """A dashed polyline through the (n,) points (``xs``, ``ys``) on log-log axes, for
    implot's ``plot_line`` (a NaN breaks its line): each segment cut into ``2 * dashes`` equal
    pieces in log coordinates, every other one left out.  Returns (m,) arrays with NaN
    between the dashes (empty for fewer than two points)."""
    if len(xs) < 2:
        return np.zeros(0), np.zeros(0)
    lx, ly = np.log10(xs), np.log10(ys)
    t = np.arange(2 * dashes + 1) / (2 * dashes)
    starts, ends = t[:-1:2], t[1::2]
    out = []
    for k in range(len(xs) - 1):
        for a, b in zip(starts, ends):
            out += [(lx[k] + a * (lx[k + 1] - lx[k]), ly[k] + a * (ly[k + 1] - ly[k])),
                    (lx[k] + b * (lx[k + 1] - lx[k]), ly[k] + b * (ly[k + 1] - ly[k])),
                    (np.nan, np.nan)]
    pts = np.array(out)
    return 10.0 ** pts[:, 0], 10.0 ** pts[:, 1]


def _evaluate(image: np.ndarray, reference: np.ndarray) -> dict:
    from ...compare.metrics import metrics
    return metrics(image, reference)


def _matched(state: AppState, plot: ErrorPlot, method: str):
    """``method``'s matched reference for the current key and the panel's options (Gouraud's
    and Phong's follows their stand-ins, :func:`~workbench.compare.reference.matched_spec` as
    ``compare`` calls it): ``(image, "")`` once rendered, ``(None, progress)`` while it
    renders, ``(False, "")`` when the method has none (outside renderers, a user's shading
    model) or it does not apply to the scene.  Held in ``plot.matched[method]`` for the options
    ``plot.matched_options[method]`` (other options: looked up again)."""
    options = state.options[method]
    held = tuple(sorted(options.items()))
    if method in plot.matched and plot.matched_options.get(method) == held:
        return plot.matched[method], ""
    plot.matched.pop(method, None)
    plot.matched_options[method] = held
    from ...compare.reference import finest_options, matched_spec
    from .panel_refresh import tiled
    from .jobs import JobBoard
    spec = matched_spec(method, state.scene, options)
    if spec is None:
        plot.matched[method] = False
        return False, ""
    ref_m, opts, _ = spec
    if ref_m == "pathtrace" and "spp" not in opts:  # 'converged': its finest knob here
        opts = {**opts, **finest_options(ref_m)}
    if ref_m == plot.reference and opts == plot.ref_options:  # the full reference itself
        plot.matched[method] = plot.ref_image
        return plot.ref_image, ""
    held = (ref_m, tuple(sorted(opts.items())))
    plot.matched_in_use.add(held)
    board = plot.matched_boards.get(held)
    if board is None:
        board = JobBoard(cached=True, share=state.jobs)
        plot.matched_boards.put(held, board)
    job = board.request(state.scene, state.camera, ref_m, opts, tiled=tiled(ref_m))
    what = f"{ref_m} ({options_text(opts)})"
    if job.cancelled.is_set():  # the previous key's job, still ending
        return None, f"{what} waits for the previous one to end"
    if job.error is not None:
        plot.matched[method] = False
        return False, ""
    if job.image is None:
        done = job.meter.text() if job.meter is not None and job.meter.first else "started"
        return None, f"{what}: {done}"
    plot.matched[method] = job.image
    return job.image, ""


def _collect(plot: ErrorPlot, pending: dict, points: dict, what: str) -> None:
    """Move finished evaluations of ``pending`` into ``points`` (a failed one is kept in
    ``plot.failed``: not submitted again for this key)."""
    for (m, opts), fut in list(pending.items()):
        if fut.done():
            del pending[(m, opts)]
            if fut.exception() is None:
                points.setdefault(m, {})[opts] = fut.result()
            else:
                plot.failed[(m, opts, what)] = f"{m}: {what} evaluation failed ({fut.exception()})"
                plot.message = plot.failed[(m, opts, what)]


def _submit(plot: ErrorPlot, pending: dict, m: str, opts: tuple, what: str, *args) -> None:
    """Queue ``_point(*args)`` for the worker process under ``pending[(m, opts)]``."""
    if plot.pool is None:
        plot.pool = ProcessPoolExecutor(1, mp_context=mp.get_context("spawn"))
    try:
        pending[(m, opts)] = plot.pool.submit(_point, *args)
    except BrokenProcessPool:  # the worker died (e.g. out of memory): a new one next time
        plot.pool.shutdown(wait=False, cancel_futures=True)
        plot.pool = None
        plot.failed[(m, opts, what)] = plot.message = f"{m}: the error-evaluation process died"


def track(state: AppState) -> None:
    """Per frame: follow scene and camera, request the reference and the matched references,
    queue the new final images for evaluation against each and collect finished evaluations.
    Never waits: a total point is queued as soon as the full reference is there, its error
    against the matched reference when that one is."""
    plot = state.errors
    key = (state.scene_version, state.camera)
    if key != plot.key:
        for board in plot.boards():
            for job in board.current.values():
                job.cancelled.set()
        plot.key, plot.since, plot.ref_image, plot.candidates = key, time.perf_counter(), None, []
        plot.gave_up = False
        plot.points, plot.pending, plot.failed = {}, {}, {}
        plot.matched, plot.matched_points, plot.matched_pending = {}, {}, {}
        plot.matched_options = {}
        plot.matched_in_use.clear()  # the same set object: the boards' cache reads it
        plot.matched_message = ""
    plot.matched_boards.trim()  # a board's images came since it was put
    _collect(plot, plot.pending, plot.points, "error")
    _collect(plot, plot.matched_pending, plot.matched_points, "matched error")
    if plot.shown < state.frame - 1:  # the plot's window is hidden: no reference render
        return
    ref = _reference(state, plot)
    if ref is None:
        return
    rendering = []
    for m in state.methods:
        opts = tuple(sorted(state.options[m].items()))
        total = not (opts in plot.points.get(m, {}) or (m, opts) in plot.pending
                     or (m, opts, "error") in plot.failed)
        split = not (opts in plot.matched_points.get(m, {}) or (m, opts) in plot.matched_pending
                     or (m, opts, "matched error") in plot.failed)
        if not (total or split):
            continue
        final = _final_image(state, m)
        if final is None or final[0].shape != ref.shape:
            continue
        image, seconds = final
        label = ", ".join(f"{k} {v}" for k, v in opts)
        if total:
            _submit(plot, plot.pending, m, opts, "error", image, ref, seconds, label)
        if split:
            matched, progress = _matched(state, plot, m)
            if matched is None:
                rendering.append(f"{m}'s {progress}")
            elif matched is not False and matched.shape == ref.shape:
                _submit(plot, plot.matched_pending, m, opts, "matched error", image, matched, seconds, label)
    plot.matched_message = ("rendering the matched reference of " + "; ".join(rendering) + "..."
                            if rendering else "")


def _point(image: np.ndarray, reference: np.ndarray, seconds: float, label: str) -> dict:
    return {**_evaluate(image, reference), "seconds": float(seconds), "label": label}


def error_plot(state: AppState) -> None:
    """Log-log plot: one line per method through its knob settings, run time on x (a dashed
    one of the same colour: its error against its matched reference)."""
    from imgui_bundle import imgui
    plot = state.errors
    plot.shown = state.frame
    imgui.set_next_item_width(100)
    changed, k = imgui.combo("error", METRICS.index(plot.metric), list(METRICS))
    if changed:
        plot.metric = METRICS[k]
    imgui.same_line()
    imgui.push_text_wrap_pos(0.0)
    meter = reference_meter(plot)
    if meter is not None:  # the reference's done/target and time left, as the panels' bars
        from .panels import progress_line
        progress_line(meter, plot.message, imgui.get_content_region_avail().x)
    else:
        imgui.text_disabled(plot.message)
    if plot.matched_message:
        imgui.text_disabled(plot.matched_message)
    elif plot.matched_pending:
        imgui.text_disabled(f"evaluating {len(plot.matched_pending)} error(s) against matched references...")
    none = [m for m in state.methods if plot.matched.get(m) is False]
    if none:
        imgui.text_disabled(f"no matched reference: {', '.join(map(short_name, none))} (total error only)")
    imgui.pop_text_wrap_pos()
    lines = plotted_lines(plot, state.methods, plot.metric)
    draw_plot(plot, lines)


def draw_plot(plot: ErrorPlot, lines: dict) -> None:
    """The implot plot of ``lines`` (:func:`plotted_lines`): log-log, the ticks labelled as
    densely as their labels leave room for at the plot's size (:func:`.plot_axes.log_ticks`:
    run times as ``ms`` / ``s``), the error axis at most :data:`~.plot_axes.ERROR_DECADES`
    decades deep with points below its floor drawn at the floor as grey down-triangles (legend:
    "below the axis floor"), and the point under the mouse described in a tooltip
    (:func:`.plot_axes.hover_text`: method, run time, errors, settings), also kept in
    ``plot.hover`` with the axes in ``plot.axes`` (scripts read them)."""
    from imgui_bundle import imgui, implot
    from .plot_axes import (error_label, error_limits, hover_text, log_limits, log_ticks,
                            nearest_point, time_label)
    for name in CLEAR_FILLS:
        implot.push_style_color(getattr(implot.Col_, name), imgui.ImVec4(0.0, 0.0, 0.0, 0.0))
    avail = imgui.get_content_region_avail()
    if lines:
        xs, ys = (np.concatenate([v[k] for v in lines.values()]) for k in (0, 1))
        xlim, (floor, *ylim) = log_limits(xs), error_limits(ys)
    else:  # 1 ms to 1 s
        xlim, (floor, *ylim) = (1.0, 1e3), error_limits(np.zeros(0))
    # the legend: outside on the right where the plot keeps most of the width, else under the
    # plot (in a row if its entries fit, else a column): at 1024x600 the plot's tab is ~250 px
    # wide and a legend beside it left the plot 14 px
    entries = [short_name(k.removesuffix(MATCHED_SUFFIX)) + k[len(k.removesuffix(MATCHED_SUFFIX)):]
               for k in lines] + ["below the axis floor"]
    widths = [imgui.calc_text_size(e).x + 30.0 for e in entries]
    text_h = imgui.get_text_line_height()
    row_h = imgui.get_text_line_height_with_spacing()
    if avail.x - max(widths) >= 2 * max(widths, default=0.0) + 150.0:
        where, flags, room_x, room_y = implot.Location_.east, implot.LegendFlags_.outside, max(widths), 0.0
    elif sum(widths) <= avail.x - 20.0:
        where, flags = implot.Location_.south, implot.LegendFlags_.outside | implot.LegendFlags_.horizontal
        room_x, room_y = 0.0, row_h + 10.0
    else:
        where, flags, room_x, room_y = implot.Location_.south, implot.LegendFlags_.outside, 0.0, len(entries) * row_h + 10.0
    # the plot area's length along each axis, estimated before the plot exists (its ticks
    # are set up first), conservatively: the legend's room and the axes' labels taken off
    x_ticks = log_ticks(*xlim, max(40.0, avail.x - room_x - 5 * text_h),
                        lambda t: imgui.calc_text_size(t).x, time_label)
    y_ticks = log_ticks(*ylim, max(20.0, avail.y - room_y - 3 * text_h), lambda t: text_h, error_label)
    plot.hover = ""
    if implot.begin_plot("##error against run time", imgui.ImVec2(-1, -1)):
        implot.setup_axes("run time", plot.metric)
        implot.setup_legend(where, flags)
        implot.setup_axis_scale(implot.ImAxis_.x1, implot.Scale_.log10)
        implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
        implot.setup_axes_limits(*xlim, *ylim, implot.Cond_.always)
        implot.setup_axis_ticks(implot.ImAxis_.x1, *x_ticks, False)
        implot.setup_axis_ticks(implot.ImAxis_.y1, *y_ticks, False)
        colours, shown_points = {}, []
        for label, (xs, ys, rows) in lines.items():
            m = label.removesuffix(MATCHED_SUFFIX)
            colour = colours.setdefault(m, implot.get_colormap_color(len(colours)))
            marker = getattr(implot.Marker_, marker_of(m))
            shown = short_name(m) + label[len(m):]  # a user's model by its file's name
            drawn = np.maximum(ys, floor)
            if label == m:
                implot.plot_line(shown, xs, drawn, implot.Spec(line_color=colour, marker=marker, marker_size=5))
            else:  # dashes of the same colour, smaller markers (one legend entry: same label)
                implot.plot_line(shown, *dashed(xs, drawn), implot.Spec(line_color=colour))
                implot.plot_scatter(shown, xs, drawn, implot.Spec(line_color=colour, marker=marker,
                                                                  marker_size=3))
            shown_points += [(shown, label != m, x, y, row) for x, y, row in zip(xs, drawn, rows)]
        below = [(x, y) for _, _, x, y, row in shown_points if row[plot.metric] < floor]
        if below:
            bx, by = (np.array(v, float) for v in zip(*below))
            grey = imgui.ImVec4(0.7, 0.7, 0.7, 1.0)
            implot.plot_scatter("below the axis floor", bx, by, implot.Spec(
                line_color=grey, marker_line_color=grey, marker_fill_color=grey,
                marker=implot.Marker_.down, marker_size=8))
        pos, size = implot.get_plot_pos(), implot.get_plot_size()
        plot.axes = {"rect": [pos.x, pos.y, size.x, size.y],
                     "x": {"limits": list(xlim), "ticks": [
                         [v, t, implot.plot_to_pixels(v, ylim[0]).x, imgui.calc_text_size(t).x]
                         for v, t in zip(*x_ticks)]},
                     "y": {"limits": list(ylim), "ticks": [
                         [v, t, implot.plot_to_pixels(xlim[0], v).y, text_h] for v, t in zip(*y_ticks)]}}
        if implot.is_plot_hovered() and shown_points:
            mouse = imgui.get_mouse_pos()
            pixels = np.array([[p.x, p.y] for p in (implot.plot_to_pixels(x, y)
                                                      for _, _, x, y, _ in shown_points)])
            k = nearest_point(pixels, (mouse.x, mouse.y))
            if k is not None:
                name, matched, _, _, row = shown_points[k]
                plot.hover = hover_text(name, row, plot.metric, matched, floor)
                imgui.set_tooltip(plot.hover)
        implot.end_plot()
    implot.pop_style_color(len(CLEAR_FILLS))
