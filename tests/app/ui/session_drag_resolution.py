"""The scripted session of the GL panels' resolution during a camera drag (issue #29, item 1:
``workbench.app.ui.drag_resolution``), run by ``tests/app/ui/test_ui_drag_resolution.py``:
``workbench ui whitted --methods flat,phong --script session_drag_resolution.py:AdaptiveDrag``.

The frame budget is set by the session, so that what the scale does does not depend on the
machine's speed or load: a budget no frame holds while the scale must go down, one every
frame holds while it must go up."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from workbench.app.ui import camera as cam
from workbench.app.ui import screenshot
from workbench.app.ui.drag_resolution import set_adaptive
from workbench.app.ui.glfw_title import window_title
from workbench.app.ui.panels import status_text
from workbench.app.ui.state import AppState

from sessions import gl_object_counts

DOWN_FRAMES = 6
"""Frames of the drag over the budget."""
UP_FRAMES_MAX = 90
"""At most this many frames of the drag under the budget (the scale climbs back to full)."""
OFF_FRAMES = 5
"""Frames of the drag with the adaptation off (over the budget)."""
STEP = 0.03
"""Radians of orbit per frame of every drag."""
TINY_BUDGET, HUGE_BUDGET = 1e-4, 100.0
"""Frame budgets (seconds) that no frame holds and that every frame holds."""
WAIT_SECONDS = 60.0
"""How long a phase may wait for what it waits for before the session gives up."""


class AdaptiveDrag:
    """Frames 0-2 at rest; then phases, each frame logged (:meth:`_frame`: the scale, the size
    each GL panel drew at, whether the frame saw the camera moved, the seconds it has rested):

    * ``down``: the budget set below any frame's time, the camera orbits
      :data:`DOWN_FRAMES` frames; the frame that draws the last move saves each panel's image
      (``image_M.npy``) and the status bar's text, the next one the X server's picture of
      the window (``drag_screen.png``, that frame on screen) with the panels' rectangles and
      whether the difference view's map is at the panels' drag size;
    * ``rest``: the camera rests until the panels have drawn at full resolution for two frames;
    * ``off``: the adaptation turned off (the checkbox's function), the budget still below
      any frame's time and the drag's scale at its lowest: :data:`OFF_FRAMES` frames of orbit;
    * ``up``: the adaptation on again, the budget above any frame's time: the camera orbits
      until the scale is back at 1 for three frames (at most :data:`UP_FRAMES_MAX`); quit.

    The GL objects alive are logged at the start and at the end (``gl_start``, ``gl_end``)."""

    def __init__(self, out: Path):
        self.out = out
        self.log = {"down": [], "rest": [], "up": [], "off": []}
        self.phase, self.k, self.t0, self.full_frames = "start", 0, time.perf_counter(), 0

    @staticmethod
    def _frame(state: AppState) -> dict:
        d = state.drag
        return {"frame": state.frame, "scale": d.scale, "level": d.level, "moved": d.moved,
                "still_s": d.now - d.last_motion,
                "sizes": {m: list(state.gpu.linear[m][0].size) for m in state.gpu.raster}}

    def _orbit(self, state: AppState) -> None:
        state.camera = cam.orbit(state.camera, STEP, 0.0)
        self.k += 1

    def __call__(self, state: AppState) -> None:
        d, timeout = state.drag, time.perf_counter() - self.t0 > WAIT_SECONDS
        if self.phase == "start" and state.frame >= 2:
            self.log.update(full=[state.camera.width, state.camera.height],
                            enabled_at_start=d.enabled, gl_start=gl_object_counts(state))
            d.budget, self.phase = TINY_BUDGET, "down"
        if self.phase == "down":
            if self.k:  # the frame that drew the previous move
                self.log["down"].append(self._frame(state))
            if self.k < DOWN_FRAMES:
                self._orbit(state)
            else:
                for m in state.gpu.raster:
                    np.save(self.out / f"image_{m}.npy", np.asarray(state.images[m], np.float32))
                self.log["camera"] = {"position": list(state.camera.position),
                                      "look_at": list(state.camera.look_at)}
                self.log["drag_status"] = status_text(state)
                self.phase, self.t0 = "shot", time.perf_counter()
        elif self.phase == "shot":  # the window now shows the drag's last frame
            shape = tuple(reversed(self.log["down"][-1]["sizes"]["flat"]))
            self.log["rest"].append(self._frame(state))
            screenshot.save(window_title(state), self.out / "drag_screen.png")
            self.log.update(drag_rects=[[m, list(r)] for m, r in state.gpu.blits.last],
                            difference_at_drag_size=state.images.has_shape("difference", shape))
            self.phase = "rest"
        elif self.phase == "rest":
            frame = self._frame(state)
            self.log["rest"].append(frame)
            full = all(s == self.log["full"] for s in frame["sizes"].values())
            self.full_frames = self.full_frames + 1 if full else 0
            if self.full_frames >= 2 or timeout:
                self.log["rest_rects"] = [[m, list(r)] for m, r in state.gpu.blits.last]
                set_adaptive(state, False)
                self.log["level_off"] = d.level
                self.phase, self.k = "off", 0
                self._orbit(state)
        elif self.phase == "off":
            self.log["off"].append(self._frame(state))
            if self.k < OFF_FRAMES:
                self._orbit(state)
            else:
                self.log["enabled_off"] = d.enabled
                set_adaptive(state, True)
                d.budget, self.phase, self.k, self.t0 = HUGE_BUDGET, "up", 0, time.perf_counter()
                self.full_frames = 0
                self._orbit(state)
        elif self.phase == "up":
            frame = self._frame(state)
            self.log["up"].append(frame)
            self.full_frames = self.full_frames + 1 if frame["scale"] == 1.0 else 0
            if self.full_frames >= 3 or self.k >= UP_FRAMES_MAX:
                self.log["gl_end"] = gl_object_counts(state)
                state.quit = True
            else:
                self._orbit(state)
