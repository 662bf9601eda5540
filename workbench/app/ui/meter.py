"""How far a long background job is and how long it has left (:class:`Meter`), shown as a
progress bar under its panel and in the error plot's reference line.

A job reports what it has done (samples per pixel of a target, rows of an image, or, for
progressive refinement, whose shot count has no target, the way done to its stopping rule)
and the meter turns it into a fraction, a line of text and a time left.  A job of several
steps (the hybrid method's radiosity and ray-trace passes, an outside program's start-up and
render) reports each step as a *phase* with a meter of its own; a step that reports no
amount done (a direct solve, a program that says nothing) is *not measured*: its bar is
indeterminate and its text gives the time elapsed.  The time left
extrapolates the rate since the job's *first* report: the set-up before it (scene
flattening, a cold numba compile) would otherwise make the early estimates far too long.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field


def clock_text(seconds: float) -> str:
    """``75.0`` -> ``"1:15"``; ``3725`` -> ``"1:02:05"`` (to the nearest second)."""
    s = int(round(seconds))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


@dataclass
class Meter:
    """Progress of one job.

    ``unit``: what ``done`` counts (``"spp"``, ``"rows"``, ``"shots"``); ``target``: the
    count at which the job ends, or None when unknown (shots: the stopping rule decides), then
    ``fraction`` comes from the job itself; ``detail``: a short note (noise, unshot energy).
    ``first``: (time, fraction) of the first report, the origin of the rate.  ``phase``:
    the step of the job this meter counts (empty for a job of one step); ``measured``: the
    last report said how far the step is (a target, or a fraction from the job); ``started``:
    when the step began."""

    unit: str
    target: int | None = None
    done: int = 0
    fraction: float = 0.0
    detail: str = ""
    first: tuple[float, float] | None = None
    now: float = field(default_factory=time.perf_counter)
    phase: str = ""
    measured: bool = True
    started: float = field(default_factory=time.perf_counter)

    def update(self, done: int, fraction: float | None = None, detail: str = "",
               now: float | None = None) -> None:
        """Record that ``done`` units are done (``fraction`` of the job, by default
        ``done / target``), at time ``now`` (default: the clock)."""
        self.now = time.perf_counter() if now is None else now
        self.done = int(done)
        self.measured = fraction is not None or bool(self.target)
        if fraction is None:
            fraction = done / self.target if self.target else 0.0
        self.fraction = min(1.0, max(0.0, float(fraction)))
        self.detail = detail
        if self.first is None:
            self.first = (self.now, self.fraction)

    def seconds_left(self) -> float | None:
        """Time left at the rate since the first report: (t - t0) (1 - f) / (f - f0); None
        before a second report with more done."""
        if self.first is None or self.fraction <= self.first[1]:
            return None
        t0, f0 = self.first
        return (self.now - t0) * (1.0 - self.fraction) / (self.fraction - f0)

    def bar(self, clock: float) -> float:
        """The progress bar's value: the fraction done, or, for a step not measured, imgui's
        indeterminate bar (a negative value that moves with ``clock``, seconds)."""
        return self.fraction if self.measured else -clock

    def text(self, now: float | None = None) -> str:
        """``"37/256 spp, noise 0.012, 0:42 left"``, ``"480 shots, unshot 3.1 %, 0:20 left"``,
        with a phase ``"ray trace: 96/192 rows, 0:03 left"``; the time elapsed (at ``now``,
        default the clock) where a phase has no time left yet or is not measured:
        ``"POV-Ray parsing: 0:02 elapsed"``."""
        parts = []
        if self.target:
            parts.append(f"{self.done}/{self.target} {self.unit}")
        elif self.unit:
            parts.append(f"{self.done} {self.unit}")
        if self.detail:
            parts.append(self.detail)
        left = self.seconds_left() if self.measured else None
        if left is not None and self.fraction < 1.0:
            parts.append(f"{clock_text(left)} left")
        elif self.phase and (not self.measured or self.fraction < 1.0):
            now = time.perf_counter() if now is None else now
            parts.append(f"{clock_text(now - self.started)} elapsed")
        text = ", ".join(parts)
        return f"{self.phase}: {text}" if self.phase else text
