"""The ``Controls`` scripted session (``workbench ui SCENE --script tests/app/ui/sessions.py:Controls``): every editable
control of the scene set to its minimum, its maximum and a middle value, one control value per
step, through the functions the window's widgets call.

The controls: each material coefficient (the Parameters sliders' ranges, every material of the
scene at once), each light field (intensity over the drag's range, colour from black to a
bright HDR value, a position, direction or area-light centre at the target, far away and at the
camera), the camera (orbit to both poles, zoom in and out by the wheel's extremes) and every
shown method's quality knob and stand-in knobs (first, last and middle of their value lists).
Each step lasts until the GL panels have redrawn; every panel image present in any frame is
checked for NaN and Inf, and the process's resident size is sampled.  At the end the CPU jobs
get :data:`FINAL_WAIT_SECONDS` to deliver, their images are checked too, and the session quits.
The log (``summary.json``'s ``script``) lists the steps (with the seconds since the first),
any non-finite image and the peak resident size.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from workbench.app.ui import camera as cam
from workbench.app.ui.gl_sessions import KNOB_VALUES
from workbench.app.ui.panels import MATERIAL_RANGES
from workbench.app.ui.state import (AppState, MATERIAL_FIELDS, light_fields, method_kind,
                    set_light_value, set_material_value, set_option)

FINAL_WAIT_SECONDS = 120.0
"""How long the CPU jobs get to deliver after the last step."""
STEP_FRAMES = 2
"""Frames per step: the change lands in the first, the GL panels have redrawn by the second."""
INTENSITY_RANGE = (0.0, 1e6)
"""The light intensity drag's range (:mod:`.lights`)."""
COLOURS = ((0.0, 0.0, 0.0), (0.5, 0.5, 0.5), (50.0, 50.0, 50.0))
"""Light colours tried: black, a middle grey, a bright HDR value (the colour edit has no top)."""
ZOOMS = (1e-3, 1e3)
"""Camera distance factors tried (very near the target, very far)."""
POLE = 0.5 * np.pi - 1e-3
"""Orbit pitch tried at both poles (just short of straight up or down)."""


def _ends(values) -> list:
    """First, last and middle of a list of values."""
    values = list(values)
    return [values[0], values[-1], values[len(values) // 2]]


def _rss_bytes() -> int:
    """The process's resident size now (Linux ``/proc/self/statm``)."""
    import os
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE")


def control_steps(state: AppState) -> list[tuple[str, object]]:
    """(label, action) per control value; ``action(state)`` applies it."""
    from workbench.renderers.base import get_renderer
    from workbench.app.ui.gl_sessions import draws_standins
    steps: list[tuple[str, object]] = []
    for f in MATERIAL_FIELDS:
        lo, hi = MATERIAL_RANGES[f]
        for v in (lo, hi, 0.5 * (lo + hi)):
            steps.append((f"materials {f}={v:g}", lambda s, f=f, v=v: [
                set_material_value(s, name, f, v) for name in s.scene.materials]))
    target, _, _, dist = cam.orbit_parameters(state.camera)
    eye = tuple(float(x) for x in state.camera.position)
    far = tuple(float(x) for x in np.asarray(target) + np.array([0.0, 1.0, 0.0]) * dist * 1e3)
    for k, light in enumerate(state.base_scene.lights):
        for name in light_fields(light):
            if name == "intensity":
                values = [*INTENSITY_RANGE, 0.5 * sum(INTENSITY_RANGE)]
            elif name == "color":
                values = list(COLOURS)
            elif name == "direction":
                values = [(0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.3, -0.2, -1.0)]
            else:  # a position or an area light's centre
                values = [tuple(float(x) for x in target), far, eye]
            for v in values:
                steps.append((f"light {k} {name}={v}",
                              lambda s, k=k, name=name, v=v: set_light_value(s, k, name, v)))
    base = state.camera
    for label, move in (("camera north pole", lambda c: cam.orbit(c, 0.0, POLE)),
                        ("camera south pole", lambda c: cam.orbit(c, 0.0, -POLE)),
                        *((f"camera zoom x{z:g}", lambda c, z=z: cam.zoom(c, z)) for z in ZOOMS),
                        ("camera back", lambda c: c)):
        steps.append((label, lambda s, move=move: setattr(s, "camera", move(base))))
    for m in state.methods:
        knob = get_renderer(m).knob
        for v in _ends(knob.values):
            steps.append((f"{m} {knob.name}={v}", lambda s, m=m, n=knob.name, v=v: set_option(s, m, n, v)))
        if draws_standins(m):
            for name, values in KNOB_VALUES.items():
                for v in _ends(values):
                    steps.append((f"{m} {name}={v}", lambda s, m=m, n=name, v=v: set_option(s, m, n, v)))
    return steps


class Controls:
    """Every control at its minimum, maximum and middle (see the module's docstring)."""

    def __init__(self, out: Path):
        self.out, self.log = out, {"steps": [], "not_finite": [], "errors": []}
        self.steps: list | None = None
        self.peak = 0
        self.t_end: float | None = None

    def _check(self, state: AppState, label: str) -> None:
        """Every panel image present now is finite; the resident size is sampled."""
        for m in state.methods:
            if m in state.images:
                image = np.asarray(state.images[m])
                if not np.isfinite(image).all():
                    self.log["not_finite"].append([label, m])
        self.peak = max(self.peak, _rss_bytes())

    def __call__(self, state: AppState) -> None:
        if self.steps is None:
            self.steps, self.t0 = control_steps(state), time.perf_counter()
            self.log["methods"] = list(state.methods)
            self.log["gl_methods"] = [m for m in state.methods if method_kind(state, m) == "gl"]
        k, phase = divmod(state.frame, STEP_FRAMES)
        if k < len(self.steps):
            label, action = self.steps[k]
            if phase == 0:
                try:
                    action(state)
                except Exception as e:  # a control that raises is a defect: logged, test fails
                    self.log["errors"].append([label, f"{type(e).__name__}: {e}"])
                self.log["steps"].append([label, round(time.perf_counter() - self.t0, 3)])
            else:
                self._check(state, label)
            return
        if self.t_end is None:
            self.t_end = time.perf_counter() + FINAL_WAIT_SECONDS
        self._check(state, "final")
        if not state.jobs.busy() or time.perf_counter() > self.t_end:
            self.log.update(jobs_done=not state.jobs.busy(), peak_rss=self.peak,
                            delivered=[m for m in state.methods if m in state.images])
            state.quit = True
