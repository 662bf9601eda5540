"""The error plot's axes and hover (issue #29, item 4), as plain functions of numbers: which
ticks a log axis labels so that no two labels touch at the plot's size, how run times and
errors are written, where the error axis stops (its *floor*) and which point the mouse is on.

The error axis spans at most :data:`ERROR_DECADES` decades below the largest error shown:
an error of 0 (a panel that is its own reference, as the path tracer at its finest knob) or
far below the others no longer stretches the axis down to 1e-6 and squeezes every other line
into its top; such a point is drawn at the floor with a marker that says so, and its hover gives
its value.
"""
from __future__ import annotations

import math

import numpy as np

ERROR_DECADES = 4
"""The error axis spans at most this many decades below its largest error."""
MARGIN = 1.5
"""Factor of room beyond the extreme values on each log axis."""
LABEL_GAP = 6.0
"""Pixels at least between two neighbouring tick labels."""
HOVER_PIXELS = 10.0
"""A point is hovered when the mouse is this close to it (pixels)."""


def time_label(ms: float) -> str:
    """A run time in milliseconds as a tick label: ``"50 us"``, ``"2 ms"``, ``"1 s"``, ``"2 min"``."""
    if ms < 1.0:
        return f"{ms * 1e3:.3g} us"
    if ms < 1e3:
        return f"{ms:.3g} ms"
    if ms < 6e4:
        return f"{ms / 1e3:.3g} s"
    return f"{ms / 6e4:.3g} min"


def error_label(v: float) -> str:
    """An error as a tick label: ``"0.01"``, ``"0.5"``, ``"1e-4"``, ``"5e-6"``."""
    e = math.floor(math.log10(v) + 1e-9)
    if -2 <= e <= 2:
        return f"{v:.3g}"
    return f"{v / 10.0 ** e:.3g}e{e}"


def log_ticks(lo: float, hi: float, length: float, size_of, label_of,
              gap: float = LABEL_GAP) -> tuple[list[float], list[str]]:
    """Ticks of a log axis from ``lo`` to ``hi`` (> 0) drawn ``length`` pixels long: the
    densest of 1-2-5 per decade, each decade, every 2nd, 3rd, ... decade whose labels
    (``label_of(value)``, ``size_of(label)`` pixels along the axis) leave ``gap`` pixels between
    neighbours; at least the one tick the axis holds (its geometric middle when it holds no
    decade).  Returns (values, labels)."""
    span = math.log10(hi) - math.log10(lo)

    def px(v: float) -> float:
        return length * (math.log10(v) - math.log10(lo)) / span

    def fits(values) -> bool:
        sizes = [size_of(label_of(v)) for v in values]
        return all(px(b) - px(a) >= (sa + sb) / 2 + gap
                   for a, b, sa, sb in zip(values, values[1:], sizes, sizes[1:]))

    e0, e1 = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
    decades = [10.0 ** e for e in range(e0, e1 + 1)]
    candidates = [[d * m for d in decades for m in (1, 2, 5)]]
    candidates += [[10.0 ** e for e in range(e0, e1 + 1) if e % k == 0] for k in range(1, e1 - e0 + 2)]
    for values in candidates:
        values = [v for v in values if lo <= v <= hi]
        if len(values) >= 2 and fits(values):
            return values, [label_of(v) for v in values]
    middle = [v for v in decades if lo <= v <= hi][:1] or [math.sqrt(lo * hi)]
    return middle, [label_of(v) for v in middle]


def log_limits(values: np.ndarray) -> tuple[float, float]:
    """Axis range of positive ``values`` on a log axis: a factor :data:`MARGIN` beyond them,
    and at least one decade (so that the axis has a labelled tick)."""
    lo, hi = float(values.min()) / MARGIN, float(values.max()) * MARGIN
    if hi < 10.0 * lo:
        mid = np.sqrt(lo * hi)
        lo, hi = mid / np.sqrt(10.0), mid * np.sqrt(10.0)
    return lo, hi


def error_limits(errors: np.ndarray) -> tuple[float, float, float]:
    """(floor, bottom, top) of the error axis for the (n,) ``errors`` (>= 0): the floor is
    the bottom of :func:`log_limits` of the positive ones, raised to :data:`ERROR_DECADES`
    decades below the largest error (errors below it are drawn at it); the axis goes a factor
    :data:`MARGIN` below the floor, so that a marker there is whole; a floor of 1e-3 and a top
    of 1 when no error is positive."""
    positive = errors[np.isfinite(errors) & (errors > 0)]
    if positive.size == 0:
        return 1e-3, 1e-3 / MARGIN, 1.0
    lo, hi = log_limits(positive)
    floor = max(lo, float(positive.max()) / 10.0 ** ERROR_DECADES)
    return floor, floor / MARGIN, hi


def nearest_point(points: np.ndarray, mouse: tuple[float, float],
                  radius: float = HOVER_PIXELS) -> int | None:
    """Index of the (n, 2) pixel ``points`` nearest ``mouse``, if within ``radius`` pixels."""
    if len(points) == 0:
        return None
    d = np.hypot(points[:, 0] - mouse[0], points[:, 1] - mouse[1])
    k = int(np.argmin(d))
    return k if d[k] <= radius else None


def hover_text(method: str, point: dict, metric: str, matched: bool, floor: float) -> str:
    """The tooltip of one plotted point: the method (and whether against its matched
    reference), its run time, its error in the plotted metric and the others, its settings,
    and, for a point below the axis floor, that it is drawn at the floor."""
    against = "its matched reference" if matched else "the reference"
    lines = [f"{method}{' (vs matched)' if matched else ''}",
             f"run time {time_label(point['seconds'] * 1e3)}",
             f"{metric} {point[metric]:.4g} against {against}"]
    others = [f"{k} {point[k]:.4g}" for k in ("rmse", "psnr", "flip") if k != metric and k in point]
    if others:
        lines.append(", ".join(others))
    if point.get("label"):
        lines.append(f"settings: {point['label']}")
    if point[metric] < floor:
        lines.append(f"below the axis floor ({error_label(floor)}): drawn at the floor")
    return "\n".join(lines)
