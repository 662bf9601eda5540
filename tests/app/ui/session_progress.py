"""Scripted sessions of the window's long jobs (issue #29, item 2): each frame records what the
radiosity and path-traced panels show (image, meter, status, whether the progress bar is drawn)
and what the error plot's reference is, until every job has ended.  Run by
``test_ui_progress.py`` as ``workbench ui SCENE --script session_progress.py:NAME --out DIR``."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from workbench.app.ui.panel_refresh import running_meter
from workbench.app.ui.plot import reference_meter
from workbench.app.ui.state import AppState

from sessions import JobsDone

WAIT_SECONDS = 400.0
"""How long a session waits for the jobs and the reference before it gives up (and says so)."""


class Progress:
    """Records, per frame and per CPU panel, the job's meter and the image shown whenever it
    changed (``{method}_{k}.npy``); ends once no job runs and the error plot has its reference
    (or :data:`WAIT_SECONDS` passed)."""

    def __init__(self, out: Path):
        self.out, self.t0 = out, time.perf_counter()
        self.log = {"frames": {}, "images": {}, "finished": False, "reference_bar": []}
        self.seen: dict[str, tuple] = {}
        self.jobs_done = JobsDone()

    def __call__(self, state: AppState) -> None:
        for m in state.methods:
            job = state.jobs.current.get(m)
            if job is None or job.meter is None:
                continue
            meter = job.meter
            self.log["frames"].setdefault(m, []).append({
                "frame": state.frame, "done": meter.done, "target": meter.target,
                "fraction": meter.fraction, "detail": meter.detail, "left": meter.seconds_left(),
                "status": state.status.get(m, ""), "bar": running_meter(job) is not None,
                "job_done": job.done})
            key = (id(job), state.images.version(m))
            if m in state.images and self.seen.get(m) != key:
                self.seen[m] = key
                k = len(self.log["images"].setdefault(m, []))
                np.save(self.out / f"{m}_{k}.npy", np.asarray(state.images[m], np.float32))
                self.log["images"][m].append({"frame": state.frame, "job_done": job.done,
                                              "status": state.status.get(m, "")})
        plot = state.errors
        meter = reference_meter(plot)
        if meter is not None:  # the error plot draws the reference's progress bar
            self.log["reference_bar"].append({"frame": state.frame, "fraction": meter.fraction,
                                              "message": plot.message})
        ready = plot.ref_image is not None
        if ready or time.perf_counter() - self.t0 > WAIT_SECONDS:
            if self.jobs_done(state) or time.perf_counter() - self.t0 > WAIT_SECONDS:
                self.finish(state, ready)

    def finish(self, state: AppState, ready: bool) -> None:
        plot = state.errors
        board = plot.board
        ref_job = None if board is None else board.current.get(plot.reference)
        self.log.update({
            "finished": ready and not state.jobs.busy(), "reference": plot.reference,
            "reference_message": plot.message, "panel_jobs_started": state.jobs.count,
            "reference_jobs_started": None if board is None else board.count,
            "reference_shared": ref_job is not None and ref_job is state.jobs.current.get(plot.reference),
            "reference_cached": None if ref_job is None else ref_job.cached,
            "options": {m: {k: v for k, v in state.options[m].items()} for m in state.methods}})
        if ready:
            np.save(self.out / "reference.npy", np.asarray(plot.ref_image, np.float32))
        state.quit = True


def progress(out: Path) -> Progress:
    return Progress(out)


class Phases:
    """Records, per frame and per panel whose method reports phases (``on_progress``: the
    hybrid method, POV-Ray, Mitsuba), the job's meter (phase, done, target, measured), the
    bar's value the panel draws (:meth:`~workbench.app.ui.meter.Meter.bar`), whether it draws
    one and its status line; ends once no job runs (or :data:`WAIT_SECONDS` passed), with each
    panel's job outcome."""

    def __init__(self, out: Path):
        self.out, self.t0 = out, time.perf_counter()
        self.log = {"frames": {}, "finished": False}
        self.jobs_done = JobsDone()

    def __call__(self, state: AppState) -> None:
        now = time.perf_counter()
        for m in state.methods:
            job = state.jobs.current.get(m)
            if job is None or not job.phased:
                continue
            meter = job.meter
            running = running_meter(job)
            self.log["frames"].setdefault(m, []).append({
                "frame": state.frame, "phase": meter.phase, "done": meter.done,
                "target": meter.target, "unit": meter.unit, "measured": meter.measured,
                "fraction": meter.fraction, "bar": running is not None,
                "bar_value": None if running is None else running.bar(now - self.t0),
                "status": state.status.get(m, ""), "job_done": job.done})
        if state.frame > 2 and (self.jobs_done(state) or now - self.t0 > WAIT_SECONDS):
            self.log["finished"] = not state.jobs.busy()
            self.log["jobs"] = {m: {"error": j.error, "done": j.image is not None,
                                    "status": state.status.get(m, "")}
                                for m, j in state.jobs.current.items()}
            state.quit = True


def phases(out: Path) -> Phases:
    return Phases(out)
