"""The project's scripted sessions of the window, for its tests and benchmarks:
``workbench ui SCENE --script tests/app/ui/sessions.py:NAME --out DIR`` (see
:mod:`workbench.app.ui.session_file`).  ``NAME(out)`` makes the session; the window calls it once
per frame after the panels' images are updated; it acts on the state through the same functions
the mouse and sliders call, and records images into ``out``.  The ``Controls`` session is in
``session_controls.py`` beside this file."""
from __future__ import annotations

import ctypes
import time
from pathlib import Path

import numpy as np

from workbench.app.ui import camera as cam
from workbench.app.ui.export import export
from workbench.app.ui.panel_show import shown_texture
from workbench.app.ui.inspect import select_ray_tree, shown_field
from workbench.app.ui.layout import window_report
from workbench.app.ui.panels import status_text
from workbench.app.ui.state import AppState, method_kind, set_display, set_material_value, set_option, shown_image

CPU_WAIT_SECONDS = 240.0
"""How long the check script waits for background jobs before giving up (a scene's first
kernels compile in a job: on a cold cache, with the other test process on the second core and
another program on the machine, the media scenes' took more than 120 s)."""
PLOT_WAIT_SECONDS = 10.0
"""How long the check script then waits for the error plot's points."""


class JobsDone:
    """Whether every panel's job has ended and the window has taken its final image: the
    board was idle at this frame's script call and at the previous frame's.  The script runs
    after the frame's ``update_images``: a job that ends between the two has its last tiles
    taken only at the next frame, so an idle board alone may still show the previous image
    (``test_ui_features``' moved light once recorded the old ray-traced image so)."""

    def __init__(self):
        self.idle_since = None

    def __call__(self, state: AppState) -> bool:
        if state.jobs.busy():
            self.idle_since = None
            return False
        if self.idle_since is None:
            self.idle_since = state.frame
        return state.frame > self.idle_since


def _record(state: AppState, out: Path, phase: str) -> None:
    """Each panel's image as ``{phase}_{file stem}.npy`` (a user's model: ``glsl_<name>``)."""
    from workbench.renderers.base import file_stem
    for m in state.methods:
        np.save(out / f"{phase}_{file_stem(m)}.npy", np.asarray(state.images[m], np.float32))


def _spec_material(state: AppState) -> str:
    """The material of the first sphere (else first object): the one whose ks is changed."""
    from workbench.scene.model import Sphere
    objs = [o for o in state.scene.objects if isinstance(o, Sphere)] or list(state.scene.objects)
    return objs[0].material


class Check:
    """before -> orbit -> flat knob change -> ks change -> wait for CPU jobs -> quit."""

    def __init__(self, out: Path):
        self.out, self.log, self.t_wait, self.t_plot = out, {}, None, None
        self.jobs_done = JobsDone()

    def __call__(self, state: AppState) -> None:
        f, out = state.frame, self.out
        if f == 2:
            _record(state, out, "before")
            state.camera = cam.orbit(state.camera, 0.4, 0.15)
        elif f == 3:
            _record(state, out, "orbit")
            knob = state.options["flat"]["tessellation"]
            set_option(state, "flat", "tessellation", 2 if knob != 2 else 3)
        elif f == 4:
            _record(state, out, "knob")
            mat = _spec_material(state)
            ks = state.scene.materials[mat].ks
            set_material_value(state, mat, "ks", 1.0 if ks < 0.5 else 0.0)
            self.log.update(material=mat, ks_before=ks)
        elif f == 5:
            _record(state, out, "ks")
            self.t_wait = time.perf_counter()
        elif f > 5 and ((self.jobs_done(state) and self._plotted(state))
                        or time.perf_counter() - self.t_wait > CPU_WAIT_SECONDS):
            _record(state, out, "final")
            self.log["cpu_done"] = not state.jobs.busy()
            m0 = state.methods[0]
            set_display(state, m0, "indexed2-mediancut")
            shown = shown_image(state, m0).reshape(-1, 3)
            self.log["display"] = {"method": m0, "colours": int(len(np.unique(shown, axis=0))),
                                   "image_colours": int(len(np.unique(
                                       state.images[m0].reshape(-1, 3), axis=0)))}
            self.log["exported"] = [p.name for p in export(state, out / "export")]
            self.log["windows"] = window_report()
            self.log["status_bar"] = status_text(state)
            if "raytrace" in state.methods:
                i, j = state.camera.height // 2, state.camera.width // 3
                tree = select_ray_tree(state, i, j)["tree"]
                self.log["ray_tree"] = {"pixel": [i, j], "color": tree["color"],
                                        "depth": tree.get("depth"),
                                        "n_children": len(tree.get("children", [])),
                                        "object_shown": shown_field(tree, "object"),
                                        "object_name": state.scene.objects[tree["object"]].name
                                        if tree["object"] is not None else None}
            state.quit = True


    def _plotted(self, state: AppState) -> bool:
        """Every panel has its point in the error plot, or :data:`PLOT_WAIT_SECONDS` passed
        since the jobs ended (the screenshot shows the plot)."""
        if self.t_plot is None:
            self.t_plot = time.perf_counter()
        return (all(m in state.errors.points for m in state.methods)
                or time.perf_counter() - self.t_plot > PLOT_WAIT_SECONDS)


class Features:
    """Scene file browser (a bad file, then a good one, from ``out/scenes``, which the caller
    fills) -> light 0 moved (GL panels the next frame, CPU panels once their restarted jobs
    end) -> error plot: one point per method, then a second flat point after a knob change
    -> quit.  Waits for background jobs between steps."""

    def __init__(self, out: Path):
        self.out, self.log, self.step, self.t_wait = out, {}, 0, time.perf_counter()
        self.jobs_done = JobsDone()

    def _settled(self, state: AppState) -> bool:
        return (self.jobs_done(state)
                or time.perf_counter() - self.t_wait > CPU_WAIT_SECONDS)

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui.file_browser import go_to, listing, open_scene
        from workbench.app.ui.state import light_fields, light_value, set_light_value
        out, step = self.out, self.step
        if step == 0 and state.frame >= 2:
            b = state.browser
            go_to(b, out / "scenes")
            self.log["listing"] = [p.name for group in listing(b.folder) for p in group]
            version = state.scene_version
            self.log["bad"] = {"opened": open_scene(state, b.folder / "bad.toml"),
                               "message": b.message, "failed": b.failed,
                               "version_kept": state.scene_version == version}
            b.selected = b.folder / "good.toml"
        elif step == 1:  # a frame drawn with the error message, then the good file
            self.log["good"] = {"opened": open_scene(state, state.browser.selected),
                                "scene_path": str(state.scene_path)}
        elif step == 2 and self._settled(state):
            _record(state, out, "lit0")
            light = state.scene.lights[0]
            where = light_fields(light)[0]
            p = np.asarray(light_value(light, where), float)
            moved = tuple(p + np.array([1.0, 0.5, 0.0]) * max(1.0, float(np.abs(p).max())) * 0.5)
            set_light_value(state, 0, where, moved)
            self.log["light"] = {"field": where, "before": p.tolist(), "after": list(moved)}
        elif step == 3:
            _record(state, out, "lit1_next_frame")
            self.t_wait = time.perf_counter()
        elif step == 4 and self._settled(state):
            _record(state, out, "lit1")
            self.log["cpu_done"] = not state.jobs.busy()
            self.t_wait = time.perf_counter()
        elif step == 5 and self._plotted(state, {m: 1 for m in state.methods}):
            _record(state, out, "plot")
            plot = state.errors
            np.save(out / "plot_reference.npy", plot.ref_image)
            for m, image in plot.matched.items():
                if image is not False:
                    np.save(out / f"plot_matched_{m}.npy", image)
            self.log["plot"] = {"reference": plot.reference, "ref_options": plot.ref_options,
                                "points": self._points(state)}
            self.flat_tess = state.options["flat"]["tessellation"]
            set_option(state, "flat", "tessellation", 1 if self.flat_tess != 1 else 2)
        elif step == 6 and self._plotted(state, {"flat": 2}):
            self.log["plot_knob"] = self._points(state)["flat"]
            state.quit = True
        else:
            return
        self.step += 1

    def _plotted(self, state: AppState, counts: dict) -> bool:
        """The error plot holds ``counts[m]`` points of each method, each also against the
        method's matched reference where it has one (or the wait timed out)."""
        plot = state.errors
        return (all(len(plot.points.get(m, {})) >= n and
                    (plot.matched.get(m) is False or len(plot.matched_points.get(m, {})) >= n)
                    for m, n in counts.items())
                or time.perf_counter() - self.t_wait > CPU_WAIT_SECONDS)

    @staticmethod
    def _points(state: AppState) -> dict:
        """{method: [point]}: each point's total error, its options and, where evaluated, its
        errors against the matched reference (``rmse_matched``, ``flip_matched``)."""
        plot = state.errors
        out = {}
        for m, pts in plot.points.items():
            out[m] = []
            for o, p in pts.items():
                split = plot.matched_points.get(m, {}).get(o)
                out[m].append({**p, "options": dict(o),
                               **({} if split is None else {"rmse_matched": split["rmse"],
                                                            "flip_matched": split["flip"]})})
        return out


class Layout:
    """Frames 4 to 8 drawn with every widget in place (the docked windows have their sizes from
    frame 2 on; the script sees the previous frame's widgets): logs
    the widgets that ran past their window's edge (``state.cut``), the section titles wrapped
    (``state.wrapped``, frame 8's), the window report and the
    panels' blit rectangles, then quits."""

    def __init__(self, out: Path):
        self.out, self.log = out, {"cut": []}

    def __call__(self, state: AppState) -> None:
        if 4 <= state.frame <= 8:
            self.log["cut"] = sorted(set(self.log["cut"]) | state.cut)
            self.log["wrapped"] = sorted(state.wrapped)
        if state.frame == 8:
            self.log["windows"] = window_report()
            self.log["blits"] = [[m, list(r)] for m, r in state.gpu.blits.last]
            self.log["camera"] = [state.camera.width, state.camera.height]
            state.quit = True


def _gpu_counts(state: AppState) -> tuple[int, int]:
    """(GL panel draws, pixel read-backs from the GPU) so far."""
    draws = sum(p.draws for p in state.gpu.raster.values()) if state.gpu is not None else 0
    return draws, state.images.reads


class Radiosity:
    """Coarse radiosity panel -> a patch picked at the top middle pixel (the Ctrl+click's
    function) with the patch view brought to the front -> wait for the jobs -> quit."""

    def __init__(self, out: Path):
        self.out, self.log, self.t_wait = out, {}, time.perf_counter()
        self.jobs_done = JobsDone()

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui.placement import focus
        from workbench.app.ui.patch_view import select_patch
        f = state.frame
        if f == 0:  # the patch view in front of the error plot: no reference render
            set_option(state, "radiosity", "patch_size", 0.2)
            focus("Patch view")
        elif f == 2:
            i, j = state.camera.height // 5, state.camera.width // 2
            pick = select_patch(state, i, j)
            self.log["pick"] = {"pixel": [i, j], "patch": pick.patch, "surface": pick.surface,
                                "row_sum": float(pick.row.sum()), "patches": len(pick.patches)}
        elif f >= 5 and (self.jobs_done(state)
                         or time.perf_counter() - self.t_wait > CPU_WAIT_SECONDS):
            self.log["windows"] = window_report()
            self.log["cpu_done"] = not state.jobs.busy()
            _record(state, self.out, "final")
            state.quit = True


class Pyrender:
    """The pyrender panel (child process): first image -> orbit -> the image of the orbited
    camera and its point in the error plot -> quit (the child is stopped with the window)."""

    def __init__(self, out: Path):
        self.out, self.log, self.step, self.t0 = out, {}, 0, time.perf_counter()

    def _ready(self, state: AppState) -> bool:
        proc = state.pyrender
        done = proc is not None and not proc.busy and proc.image is not None
        return done or time.perf_counter() - self.t0 > CPU_WAIT_SECONDS

    def __call__(self, state: AppState) -> None:
        if self.step == 0 and self._ready(state):
            _record(state, self.out, "before")
            self.log["child_pid"] = state.pyrender.process.pid
            self.log["first_image_seconds"] = time.perf_counter() - self.t0
            state.camera = cam.orbit(state.camera, 0.5, 0.1)
            self.t0 = time.perf_counter()
            self.log["status_while_rendering"] = None
        elif self.step == 1:
            self.log["status_while_rendering"] = state.status.get("pyrender")
        elif self.step == 2 and self._ready(state) and ("pyrender" in state.errors.points or
                                                         time.perf_counter() - self.t0 > CPU_WAIT_SECONDS):
            _record(state, self.out, "orbit")
            self.log["error"] = state.pyrender.error
            self.log["plotted"] = sorted(state.errors.points)
            state.quit = True
        else:
            return
        self.step += 1


class Fps:
    """Count frames for ``seconds`` after a warm-up while the camera turns by ``step`` radians
    per frame (a steady mouse drag: every panel changes every frame and the CPU jobs restart;
    ``step`` 0 leaves the camera alone).  ``raytrace_spp`` sets the ray tracer's samples per
    pixel (a longer background job).  With ``wait_cpu`` the count also ends when no background
    job runs any more (the rate is the one *while* a job runs), then the session stays open
    until the jobs end and logs the ray trace's run time with the window open.  ``display``
    sets every panel's display mode first (e.g. an indexed CLUT); ``standins`` the ``standins``
    option of every panel that has it (``"off"``: the bare local models).  The GL panels'
    render scale over the count is logged (:meth:`_scales`); after a drag the camera rests
    and the session logs the seconds from its last move to the start of the frame after the
    one whose GL panels drew it at full resolution (``full_resolution_after_s``: on screen)."""

    def __init__(self, out: Path, seconds: float = 10.0, warmup: int = 10, step: float = 0.002,
                 raytrace_spp: int | None = None, wait_cpu: bool = False,
                 display: str | None = None, standins: str | None = None):
        self.out, self.seconds, self.warmup, self.step, self.log = out, seconds, warmup, step, {}
        self.spp, self.wait_cpu, self.t0, self.display = raytrace_spp, wait_cpu, None, display
        self.standins, self.full_frame = standins, None

    def _scales(self, state: AppState) -> dict:
        """The GL panels' render scale over the counted frames (:mod:`~workbench.app.ui.drag_resolution`):
        whether it adapted, its median (the resolution the drag settled at, also in pixels)
        and 10th and 90th percentiles."""
        median = float(np.median(self.scales))
        return {"drag_resolution": "adaptive" if state.drag.enabled else "full",
                "drag_scale_median": median,
                "drag_scale_p10_p90": np.percentile(self.scales, [10, 90]).round(3).tolist(),
                "drag_panel_px_median": [round(state.camera.width * median),
                                         round(state.camera.height * median)]}

    def __call__(self, state: AppState) -> None:
        if state.frame == 0 and self.spp is not None:
            set_option(state, "raytrace", "spp", self.spp)
        if state.frame == 0 and self.display is not None:
            for m in state.methods:
                set_display(state, m, self.display)
            self.log["display"] = self.display
        if state.frame == 0 and self.standins is not None:
            for m in state.methods:
                if "standins" in state.options[m]:
                    set_option(state, m, "standins", self.standins)
            self.log["standins"] = self.standins
        if self.step and "fps" not in self.log:
            state.camera = cam.orbit(state.camera, self.step, 0.0)
            self.t_moved = time.perf_counter()
        if state.frame == self.warmup:
            self.t0, self.busy_frames, self.gui, self.frame_ms = time.perf_counter(), 0, 0.0, []
            self.scales = []
            self.counts, self.starts = _gpu_counts(state), state.jobs.count
            self.cpu0 = process_cpu_seconds()
        elif self.t0 is not None and "fps" not in self.log:
            busy = state.jobs.busy()
            self.busy_frames += busy
            self.gui += state.gui_seconds
            self.frame_ms.append(state.frame_seconds * 1e3)
            self.scales.append(state.drag.scale)
            dt = time.perf_counter() - self.t0
            if dt >= self.seconds or (self.wait_cpu and not busy):
                n = state.frame - self.warmup
                (d0, r0), (d1, r1) = self.counts, _gpu_counts(state)
                q = np.percentile(self.frame_ms, [10, 50, 90, 99]).round(1).tolist()
                self.log.update(frames=n, seconds=dt, fps=n / dt, gui_ms_mean=self.gui / n * 1e3,
                                cpu_ms_per_frame=(process_cpu_seconds() - self.cpu0) / n * 1e3,
                                frame_ms_p10_50_90_99=q,
                                frames_with_cpu_job_running=self.busy_frames,
                                gl_panel_draws=d1 - d0, read_backs=r1 - r0,
                                cpu_jobs_started=state.jobs.count - self.starts,
                                panels_window=window_report()["Panels"].get("size"),
                                raster_ms={m: state.timings.get(m, 0) * 1e3
                                           for m in state.methods if method_kind(state, m) == "gl"},
                                **self._scales(state))
                self.t_wait = time.perf_counter()
                state.quit = not (self.wait_cpu or self.step)
        elif "fps" in self.log and self.step and not self.wait_cpu:
            # the drag has ended: the first frame after the one whose GL panels drew the
            # camera at full resolution shows them (its buffer swapped)
            if self.full_frame is not None and state.frame > self.full_frame:
                self.log["full_resolution_after_s"] = state.drag.now - self.t_moved  # frame start
                state.quit = True
            elif self.full_frame is None and all(p.drawn == state.camera
                                                 for p in state.gpu.raster.values()):
                self.full_frame = state.frame
            elif time.perf_counter() - self.t_moved > CPU_WAIT_SECONDS:
                state.quit = True
        elif "fps" in self.log and (not state.jobs.busy()
                                    or time.perf_counter() - self.t_wait > CPU_WAIT_SECONDS):
            job = state.jobs.current.get("raytrace")
            self.log.update(raytrace_seconds=None if job is None else job.seconds,
                            raytrace_options=state.options["raytrace"])
            state.quit = True


class DragCheck:
    """A camera drag with display modes and a ray-traced panel: once the ray trace is done,
    ``mode`` is set on every GL panel and the script waits for their exact images; then
    ``frames`` frames each orbit the camera, logging per frame what each GL panel shows
    (``display_modes`` kind: "fast" or "exact"), its distinct colours, the exact computations
    started, whether the ray-traced panel still holds its image and what the probe reads at
    three pixels (one-pixel reads); then the camera rests until the GL panels are exact again
    and the ray trace has restarted and ended, logging rows of the ray-traced panel that went
    black meanwhile, and each GL panel's display texture against the CLI's mode
    (``shown_M.npy``, ``cli_M.npy``)."""

    def __init__(self, out: Path, mode: str = "indexed16-mediancut", frames: int = 8):
        self.out, self.mode, self.frames, self.log = out, mode, frames, {"drag": []}
        self.step, self.k, self.t0 = 0, 0, time.perf_counter()

    def _gl(self, state: AppState) -> list[str]:
        return [m for m in state.methods if method_kind(state, m) == "gl"]

    def _exact(self, state: AppState) -> bool:
        md = state.gpu.modes
        return all(md.shown.get(m, (None, None, ""))[:3] == (state.images.version(m), self.mode,
                                                              "exact") for m in self._gl(state))

    def _texture(self, state: AppState, m: str) -> np.ndarray:
        h, w = state.camera.height, state.camera.width
        return np.frombuffer(shown_texture(state, m).read(), np.uint8).reshape(h, w, -1)[..., :3]

    def __call__(self, state: AppState) -> None:
        from workbench.core.display import apply_display_mode
        from workbench.core.imageio import to_srgb8
        now, md = time.perf_counter(), state.gpu.modes if state.gpu is not None else None
        timeout = now - self.t0 > CPU_WAIT_SECONDS
        h, w = state.camera.height, state.camera.width
        if self.step == 0 and state.frame >= 2 and (not state.jobs.busy() or timeout):
            for m in self._gl(state):
                set_display(state, m, self.mode)
            self.step, self.t0 = 1, now
        elif self.step == 1 and (self._exact(state) or timeout):
            self.log["exact_before_drag"] = self._exact(state)
            self.before = state.images["raytrace"].copy()
            self.started0 = md.started
            self.step = 2
        elif self.step == 2:
            if self.k:  # what the previous frame's orbit shows now
                pixels = [(h // 2, w // 2), (h // 3, w // 4), (h - 1, w - 1)]
                probe = {m: [state.images.pixel(m, i, j, (h, w)).tolist() for i, j in pixels]
                         for m in state.methods}
                shown = state.images["raytrace"]
                # the display textures first (during a drag the window draws the panels
                # without them; made here through the same mode pass), then what they hold
                colours = {m: int(len(np.unique(self._texture(state, m).reshape(-1, 3), axis=0)))
                           for m in self._gl(state)}
                self.log["drag"].append({
                    "kinds": {m: md.shown[m][2] for m in self._gl(state)},
                    "colours": colours,
                    "exact_started": md.started - self.started0,
                    "raytrace_kept": bool(np.array_equal(shown, self.before)),
                    "probe": probe,
                    "probe_full": {m: [state.images[m][i, j].tolist() for i, j in pixels]
                                   for m in state.methods}})
            if self.k < self.frames:
                state.camera = cam.orbit(state.camera, 0.05, 0.0)
                self.k += 1
            else:
                self.step, self.t0, self.black_rows = 3, now, 0
        elif self.step == 3:
            image = state.images["raytrace"]
            black = (np.abs(image).max(-1).max(-1) == 0) & (np.abs(self.before).max(-1).max(-1) > 0)
            self.black_rows = max(self.black_rows, int(black.sum()))
            job = state.jobs.current.get("raytrace")
            if (self._exact(state) and job is not None and job.image is not None
                    and job.key[1] == state.camera) or timeout:
                self.log.update(exact_after_rest=self._exact(state), raytrace_black_rows=self.black_rows,
                                rest_seconds=now - self.t0, exact_started=md.started - self.started0)
                for m in self._gl(state):
                    np.save(self.out / f"shown_{m}.npy", self._texture(state, m))
                    np.save(self.out / f"cli_{m}.npy",
                            to_srgb8(apply_display_mode(state.images[m], self.mode)))
                state.quit = True


class ExportCheck:
    """Frame 2: orbit the camera, override a material (the first sphere's ``ks``) and light
    0 (intensity, and where it is), set the first panel's display mode to ``mode`` and the
    knobs; then wait for the background jobs and export into ``out/export`` (logging the
    status line), and quit."""

    def __init__(self, out: Path, mode: str = "indexed16-mediancut"):
        self.out, self.mode, self.log, self.t0 = out, mode, {}, time.perf_counter()
        self.jobs_done = JobsDone()

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui.state import light_fields, light_value, set_light_value
        if state.frame == 2:
            state.camera = cam.orbit(state.camera, 0.3, 0.1)
            mat = _spec_material(state)
            set_material_value(state, mat, "ks", 0.9)
            light = state.base_scene.lights[0]
            where = light_fields(light)[0]
            p = np.asarray(light_value(light, where), float)
            set_light_value(state, 0, where, tuple(p + np.array([0.5, 0.3, -0.2])))
            set_light_value(state, 0, "intensity", float(light.intensity) * 0.7)
            set_display(state, state.methods[0], self.mode)
            if "phong" in state.methods:
                set_option(state, "phong", "tessellation", 2)
            if "raytrace" in state.methods:
                set_option(state, "raytrace", "max_depth", 3)
            self.t0 = time.perf_counter()
        elif state.frame > 4 and (self.jobs_done(state)
                                  or time.perf_counter() - self.t0 > CPU_WAIT_SECONDS):
            self.log["exported"] = [p.name for p in export(state, self.out / "export")]
            self.log["status"] = state.status["export"]
            state.quit = True


class ExportRefining:
    """Export (into ``out/export``) in the first frame whose path-traced panel shows a running
    image of at least two passes, short of its target; log the panel's progress as taken
    (``state.progress``) and the status line, and quit (at most :data:`CPU_WAIT_SECONDS`)."""

    def __init__(self, out: Path):
        self.out, self.log, self.t0 = out, {}, time.perf_counter()

    def __call__(self, state: AppState) -> None:
        held = state.progress.get("pathtrace", {})
        if held.get("state") == "refining" and held["passes"] >= 2:
            self.log["exported"] = [p.name for p in export(state, self.out / "export")]
            self.log["progress"] = dict(held)
            self.log["status"] = state.status["export"]
            state.quit = True
        elif time.perf_counter() - self.t0 > CPU_WAIT_SECONDS:
            self.log["progress"] = dict(held)
            state.quit = True


class DiffPause:
    """The difference view during a drag (``phong`` against ``raytrace``): once the ray trace
    is done, save the map (``before_difference.npy``) and the status; orbit the camera for
    ``frames`` frames, logging from the second (the status is the previous frame's gui's) the
    difference's status line and whether its map is still the one before; then rest until the ray trace at the final camera is done and the
    view is live again, saving both panels and the map (``after_*.npy``)."""

    def __init__(self, out: Path, frames: int = 4):
        self.out, self.frames, self.log = out, frames, {"drag": []}
        self.step, self.k, self.t0, self.done_frames = 0, 0, time.perf_counter(), 0

    def _save(self, state: AppState, phase: str) -> None:
        for m in ("phong", "raytrace", "difference"):
            np.save(self.out / f"{phase}_{m}.npy", np.asarray(state.images[m], np.float32))

    def __call__(self, state: AppState) -> None:
        timeout = time.perf_counter() - self.t0 > CPU_WAIT_SECONDS
        job = state.jobs.current.get("raytrace")
        done = job is not None and job.image is not None and job.key[1] == state.camera
        self.done_frames = self.done_frames + 1 if done else 0
        # the map of the finished ray trace: drawn in a frame after the one it came in
        if self.step == 0 and state.frame >= 3 and (self.done_frames >= 3 or timeout):
            self.log["before_status"] = state.status.get("difference")
            self._save(state, "before")
            self.before = np.array(state.images["difference"])
            self.step = 1
        elif self.step == 1:
            if self.k >= 2:  # the status of the gui of the frame before (drawn after the script)
                self.log["drag"].append({"status": state.status.get("difference"),
                                         "kept": bool(np.array_equal(state.images["difference"],
                                                                     self.before))})
            if self.k < self.frames:
                state.camera = cam.orbit(state.camera, 0.08, 0.0)
                self.k += 1
            else:
                self.step, self.t0 = 2, time.perf_counter()
        elif self.step == 2 and ((done and "difference" not in state.status) or timeout):
            self.step = 3  # one more frame: the map of this frame's images
        elif self.step == 3:
            self.log["after_status"] = state.status.get("difference")
            self._save(state, "after")
            state.quit = True


def move_pointer(x: float, y: float) -> None:
    """Move the X pointer to (``x``, ``y``) pixels of the window, as a mouse does: through its
    own X connection (a warp by GLFW's ``glfwSetCursorPos`` is not reported to the window)."""
    from workbench.app.ui.glfw_title import glfw_library
    glfw = glfw_library()
    glfw.glfwGetWindowPos.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int)]
    wx, wy = ctypes.c_int(), ctypes.c_int()
    glfw.glfwGetWindowPos(glfw.glfwGetCurrentContext(), ctypes.byref(wx), ctypes.byref(wy))
    x11 = ctypes.CDLL("libX11.so.6")
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XDefaultRootWindow.restype = ctypes.c_ulong
    x11.XDefaultRootWindow.argtypes = [ctypes.c_void_p]
    x11.XWarpPointer.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_int,
                                 ctypes.c_int, ctypes.c_uint, ctypes.c_uint, ctypes.c_int, ctypes.c_int]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    dpy = x11.XOpenDisplay(None)
    x11.XWarpPointer(dpy, 0, x11.XDefaultRootWindow(dpy), 0, 0, 0, 0,
                     int(round(wx.value + x)), int(round(wy.value + y)))
    x11.XCloseDisplay(dpy)  # flushes the request


class PlotHover:
    """The error plot with ``raytrace`` at its finest knob (the reference's own setting: error
    0, below any log axis): once the plot has every panel's point and every matched one (at
    most :data:`CPU_WAIT_SECONDS`), the pointer is moved (through X, as a mouse would) onto the
    ray tracer's point, drawn at the axis floor (again whenever the plot's layout moves it), and
    the plot's tooltip, axes and points are logged; quits once the tooltip came (or 40 frames
    later)."""

    def __init__(self, out: Path):
        self.out, self.log, self.t0, self.moved, self.target = out, {}, time.perf_counter(), None, None

    def _point_pixel(self, plot) -> tuple[float, float]:
        (pt,) = plot.points["raytrace"].values()
        x0, y0, w, h = plot.axes["rect"]
        (xl, xh), (yl, yh) = plot.axes["x"]["limits"], plot.axes["y"]["limits"]
        fx = np.log(pt["seconds"] * 1e3 / xl) / np.log(xh / xl)
        fy = np.log(max(pt[plot.metric], yl * 1.5) / yl) / np.log(yh / yl)  # the floor: 1.5 up
        return x0 + fx * w, y0 + (1 - fy) * h

    def __call__(self, state: AppState) -> None:
        from workbench.renderers.base import get_renderer
        plot = state.errors
        if state.frame == 2:
            set_option(state, "raytrace", "max_depth", get_renderer("raytrace").knob.values[-1])
            return
        have = (all(plot.points.get(m) for m in state.methods) and plot.axes
                and not (plot.pending or plot.matched_pending or plot.matched_message))
        if self.moved is None and not (have or time.perf_counter() - self.t0 > CPU_WAIT_SECONDS):
            return
        if plot.hover or (self.moved is not None and state.frame > self.moved + 40):
            self.log.update(hover=plot.hover, axes=plot.axes, cut=sorted(state.cut),
                            points={m: [[p["seconds"], p["rmse"]] for p in plot.points[m].values()]
                                    for m in state.methods})
            state.quit = True
            return
        target = self._point_pixel(plot)
        if self.target is None or np.hypot(*np.subtract(target, self.target)) > 1.0:
            move_pointer(*target)
            self.target = target
        if self.moved is None:
            self.moved = state.frame


RESIZE_WAIT_SECONDS = 20.0
"""How long :class:`Resize` waits for the X server to apply the new size."""


class Resize:
    """Log the window's size at frame 1, resize it at frame 2 to ``size`` (GLFW, as a user's
    drag of its corner), log it again once the X server has applied it (at most
    :data:`RESIZE_WAIT_SECONDS` later: a loaded machine applies it frames later) and quit."""

    def __init__(self, out: Path, size: tuple[int, int] = (900, 560)):
        self.out, self.size, self.log, self.asked = out, size, {}, None

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui.glfw_title import glfw_library, window_size
        if state.frame == 1:
            self.log["opened"] = list(window_size())
        elif state.frame == 2:
            glfw = glfw_library()
            glfw.glfwSetWindowSize.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
            glfw.glfwSetWindowSize(glfw.glfwGetCurrentContext(), *self.size)
            self.asked = time.perf_counter()
        elif state.frame >= 6 and (tuple(window_size()) == tuple(self.size)
                                   or time.perf_counter() - self.asked > RESIZE_WAIT_SECONDS):
            self.log["resized"] = list(window_size())
            state.quit = True


class Screens:
    """What a user sees of the default view: once nothing is in progress (the jobs, the error
    plot's reference and points; at most :data:`CPU_WAIT_SECONDS`) and a few frames later,
    the window as the X server shows it (``xwd``, :mod:`.screenshot`) is saved as
    ``screen.png`` with, logged, the widgets cut at a window's right edge over those frames,
    the window report, the blit rectangles, the panels' size, the plot's points, and each
    panel's display texture (``shown_M.npy``) to find it on screen."""

    def __init__(self, out: Path, frames: int = 4):
        self.out, self.frames, self.log = out, frames, {"cut": []}
        self.t0, self.rested = time.perf_counter(), None

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui import screenshot
        from workbench.app.ui.panel_refresh import in_progress
        from workbench.app.ui.glfw_title import window_title
        busy = in_progress(state) and time.perf_counter() - self.t0 < CPU_WAIT_SECONDS
        if state.frame < 2 or busy:
            self.rested = None
            return
        if self.rested is None:
            self.rested = state.frame
        if state.frame > self.rested:  # widgets drawn in a rested frame
            self.log["cut"] = sorted(set(self.log["cut"]) | state.cut)
        if state.frame < self.rested + self.frames:
            return
        h, w = state.camera.height, state.camera.width
        for m in [*state.methods, "difference"]:
            if m in state.images:
                tex = shown_texture(state, m)
                tw, th = tex.size
                np.save(self.out / f"shown_{m}.npy", np.frombuffer(
                    tex.read(), np.uint8).reshape(th, tw, -1)[..., :3])
        shot = screenshot.save(window_title(state), self.out / "screen.png")
        self.log.update(screen=list(shot.shape), windows=window_report(),
                        blits=[[m, list(r)] for m, r in state.gpu.blits.last],
                        camera=[w, h], methods=list(state.methods), timed_out=not
                        (time.perf_counter() - self.t0 < CPU_WAIT_SECONDS),
                        plot_points={m: len(p) for m, p in state.errors.points.items()})
        state.quit = True


class SceneScreens:
    """Every bundled scene in turn (issue #29's acceptance test, ``test_ui_screens.py``): each
    scene is switched to as the Scene window's combo does (the first is the one the window
    opened with); once the panels are done (their jobs, the GL panels' programs; at most
    :data:`CPU_WAIT_SECONDS`) and ``frames`` frames later, the window as the X server shows it
    is saved as ``screen_{scene}.png`` (the error plot as a user finds it then: its points, or
    the reference still rendering with its message and meter; waiting for the references
    too took most of the session, rock's path-traced one alone 23-110 s at 64 px)
    (``xwd``, :mod:`.screenshot`), each panel's display texture as ``shown_{scene}_{m}.npy``,
    and logged under ``scenes``: the widgets cut at a window's right edge over those frames,
    the section titles wrapped, the window report, the blit rectangles, the panels' and the
    scene camera's sizes, each panel's status and its linear image's range.  Then, with
    ``resize``, the window is resized (as a user's drag of its corner) and, once the X server
    has applied it and ``frames`` frames later, ``resized`` logs the window report and the
    blit rectangles again."""

    def __init__(self, out: Path, frames: int = 3, resize: tuple[int, int] | None = None):
        from workbench.scene.library import bundled
        self.out, self.frames, self.resize = out, frames, resize
        self.scenes = [p.stem for p in bundled()]
        self.log = {"scenes": {}, "order": self.scenes}
        self.k, self.t0, self.rested, self.cut = 0, time.perf_counter(), None, set()
        self.asked = None

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui.panel_refresh import in_progress
        from workbench.app.ui.state import set_scene
        if self.asked is not None:
            return self._after_resize(state)
        busy = in_progress(state, plot=False) and time.perf_counter() - self.t0 < CPU_WAIT_SECONDS
        if state.frame < 2 or busy:
            self.rested, self.cut = None, set()
            return
        if self.rested is None:
            self.rested = state.frame
        if state.frame > self.rested:  # widgets drawn in a rested frame
            self.cut |= state.cut
        if state.frame < self.rested + self.frames:
            return
        self._dump(state, self.scenes[self.k])
        self.k += 1
        if self.k < len(self.scenes):
            set_scene(state, self.scenes[self.k])
            self.t0, self.rested = time.perf_counter(), None
        elif self.resize is not None:
            from workbench.app.ui.glfw_title import glfw_library
            glfw = glfw_library()
            glfw.glfwSetWindowSize.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
            glfw.glfwSetWindowSize(glfw.glfwGetCurrentContext(), *self.resize)
            self.asked, self.rested = time.perf_counter(), None
        else:
            state.quit = True

    def _dump(self, state: AppState, scene: str) -> None:
        from workbench.app.ui import screenshot
        from workbench.app.ui.glfw_title import window_title
        assert state.scene_path.stem == scene, (state.scene_path, scene)
        for m in [*state.methods, "difference"]:
            if m in state.images:
                tex = shown_texture(state, m)
                tw, th = tex.size
                np.save(self.out / f"shown_{scene}_{m}.npy", np.frombuffer(
                    tex.read(), np.uint8).reshape(th, tw, -1)[..., :3])
        shot = screenshot.save(window_title(state), self.out / f"screen_{scene}.png")
        images = {}
        for m in state.methods:
            if m in state.images:
                a = np.asarray(state.images[m], np.float64)
                images[m] = {"min": float(a.min()), "max": float(a.max()), "std": float(a.std())}
        cam0 = state.scene.camera
        self.log["scenes"][scene] = {
            "screen": list(shot.shape), "cut": sorted(self.cut), "wrapped": sorted(state.wrapped),
            "windows": window_report(), "blits": [[m, list(r)] for m, r in state.gpu.blits.last],
            "camera": [state.camera.width, state.camera.height],
            "scene_camera": [cam0.width, cam0.height], "methods": list(state.methods),
            "status": {m: state.status.get(m, "") for m in state.methods}, "images": images,
            "timed_out": not time.perf_counter() - self.t0 < CPU_WAIT_SECONDS,
            "seconds": time.perf_counter() - self.t0, "frame": state.frame}

    def _after_resize(self, state: AppState) -> None:
        from workbench.app.ui.glfw_title import window_size
        applied = tuple(window_size()) == tuple(self.resize)
        if not applied and time.perf_counter() - self.asked < RESIZE_WAIT_SECONDS:
            return
        if self.rested is None:
            self.rested = state.frame
        if state.frame < self.rested + 3 * self.frames:  # the dock space, its refit, the windows
            return
        self.log["resized"] = {"window": list(window_size()), "windows": window_report(),
                               "blits": [[m, list(r)] for m, r in state.gpu.blits.last],
                               "camera": [state.camera.width, state.camera.height]}
        state.quit = True


def scene_screens_shrunk(out: Path) -> SceneScreens:
    """:class:`SceneScreens`, then the window shrunk to 1024 x 600 at run time."""
    return SceneScreens(out, resize=(1024, 600))


def _compiles(state: AppState) -> int:
    """GL programs compiled so far by the GL panels' sessions, released ones included."""
    if state.gpu is None:
        return 0
    return getattr(state.gpu, "compiled", 0) + sum(getattr(p.session.programs, "compiles", 0)
                                                   for p in state.gpu.raster.values())


def slider_step(state: AppState, k: int, edit: str) -> None:
    """One frame of a slider drag (what ``panels.parameters`` and ``lights.light_controls``
    call while a slider moves): ``edit`` "material" sets the chosen material's ``kd``, and
    "material+light" also moves light 0 (its position, direction or centre), to values that
    change with the frame number ``k``."""
    from workbench.app.ui.state import light_fields, light_value, set_light_value
    phase = (k % 40) / 40.0
    tri = 2.0 * min(phase, 1.0 - phase)  # 0 -> 1 -> 0 every 40 frames
    set_material_value(state, state.material, "kd", 0.2 + 0.7 * tri)
    if edit == "material+light" and state.base_scene.lights:
        light = state.base_scene.lights[0]
        where = light_fields(light)[0]
        p = np.asarray(light_value(light, where), float)
        offset = np.array([1.0, 0.5, 0.0]) * (tri - 0.5) * (0.2 if where == "direction" else 2.0)
        set_light_value(state, 0, where, tuple(p + offset))


class SliderFps(Fps):
    """:class:`Fps` without camera motion while a material slider (``edit`` "material") or a
    material and a light slider (``edit`` "material+light") move every frame
    (:func:`slider_step`); also logs the GL programs compiled during the count."""

    def __init__(self, out: Path, edit: str = "material+light", seconds: float = 10.0):
        super().__init__(out, seconds=seconds, step=0.0)
        self.edit = edit

    def __call__(self, state: AppState) -> None:
        if "fps" not in self.log:
            slider_step(state, state.frame, self.edit)
        if state.frame == self.warmup:
            self.compiles0 = _compiles(state)
        super().__call__(state)
        if "fps" in self.log and "programs_compiled" not in self.log:
            self.log.update(edit=self.edit, programs_compiled=_compiles(state) - self.compiles0)


class SliderFrames:
    """GL panels during a slider drag: frame 2 records each panel's image, frames 3 to 8 each
    change the chosen material's ``kd`` and light 0's position (:func:`slider_step`, edit k =
    the frame number) and the next frame records the images drawn with them (``edit{k}_M.npy``)
    with the programs compiled and the draws so far; then the values rest until the panels
    have compiled them back in (``panel_refresh.LIVE_REST_SECONDS``), the images are recorded again
    (``settled_M.npy``) and the script quits."""

    def __init__(self, out: Path):
        self.out, self.log, self.t_rest = out, {"frames": []}, None

    def _note(self, state: AppState, name: str) -> None:
        _record(state, self.out, name)
        self.log["frames"].append({"name": name, "frame": state.frame, "compiles": _compiles(state),
                                   "draws": {m: p.draws for m, p in state.gpu.raster.items()},
                                   "live": {m: p.session.live for m, p in state.gpu.raster.items()}})

    def __call__(self, state: AppState) -> None:
        f = state.frame
        if f == 2:
            self._note(state, "start")
        if 4 <= f <= 9:
            self._note(state, f"edit{f - 1}")
        if 3 <= f <= 8:
            slider_step(state, f, "material+light")
        elif f == 9:
            self.t_rest = time.perf_counter()
        elif f > 9:
            self.log.setdefault("rest_frame_ms", []).append(round(state.frame_seconds * 1e3, 1))
            if (not any(p.session.live for p in state.gpu.raster.values())
                    or time.perf_counter() - self.t_rest > 30.0):
                self._note(state, "settled")  # drawn in this frame's update
                self.log["rest_seconds"] = time.perf_counter() - self.t_rest
                state.quit = True


class GpuPanels:
    """GL panels on the GPU: frames 2 to 5 change nothing, frame 5 orbits the camera and sets
    the difference view to flat - phong ("abs"), frame 7 saves each GL panel's display texture
    (the RGBA8 pixels imgui shows, ``shown_M.npy``), logs three pixels of each GL panel read
    as the probe reads them (one pixel from the GPU), saves the difference map with its
    texture and both images, and quits.  Logs each GL panel's draw count and the read-backs at frames 2, 5
    and 7."""

    def __init__(self, out: Path):
        self.out, self.log = out, {}

    def __call__(self, state: AppState) -> None:
        f = state.frame
        if f in (2, 5, 7):
            plot = state.errors
            self.log[f"frame{f}"] = {"draws": {m: p.draws for m, p in state.gpu.raster.items()},
                                     "reads": state.images.reads,
                                     # images the error plot took for evaluation (read-backs)
                                     "plot_taken": sorted({m for m, _ in [*plot.pending, *plot.matched_pending]}
                                                          | set(plot.points) | set(plot.matched_points))}
        if f == 5:
            state.camera = cam.orbit(state.camera, 0.3, 0.1)
            state.diff_pair, state.diff_kind = ("flat", "phong"), "abs"
        elif f == 7:
            w, h = state.camera.width, state.camera.height
            for m in [*state.gpu.raster, "difference"]:
                shown = np.frombuffer(shown_texture(state, m).read(), np.uint8).reshape(h, w, -1)
                np.save(self.out / f"shown_{m}.npy", shown)
            reads, probe = state.images.reads, {}
            for m in state.gpu.raster:  # the probe's one-pixel reads, before any full read
                probe[m] = [[i, j, state.images.pixel(m, i, j, (h, w)).tolist()]
                            for i, j in ((0, 0), (h // 2, w // 3), (h - 1, w - 1))]
            self.log["probe"] = {"pixels": probe, "full_reads": state.images.reads - reads,
                                 "pixel_reads": state.images.pixel_reads}
            for m in ("flat", "phong", "difference"):
                np.save(self.out / f"image_{m}.npy", state.images[m])
            self.log["blits"] = [[m, list(rect)] for m, rect in state.gpu.blits.last]
            self.log["position"] = list(state.camera.position)
            state.quit = True


class DragRest:
    """A camera drag of ``frames`` frames (the camera orbits every frame, so the GL panels
    draw every frame without waiting for their draws and are drawn into the window straight
    from their linear images, through the display mode ``display`` sets for some), then rest.  In the first frame at rest (the window then shows
    the drag's last frame) it saves the X server's picture of the window (``drag_screen.png``),
    the panel and difference rectangles of the last drag frame, each GL panel's linear image
    (``image_M.npy``) and the camera; in the second it logs each GL panel's draws (the drag's,
    and one timed draw at rest) and times, and quits (``ui.png``: the
    rested window, the panels copied from their display textures)."""

    def __init__(self, out: Path, frames: int = 6, step: float = 0.05,
                 display: dict[str, str] | None = None):
        self.out, self.frames, self.step, self.log = out, frames, step, {}
        self.display = display or {}

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui import screenshot
        from workbench.app.ui.glfw_title import window_title
        f, last = state.frame, 2 + self.frames
        gl = [m for m in state.methods if method_kind(state, m) == "gl"]
        if f == 0:
            for m, mode in self.display.items():
                set_display(state, m, mode)
        if f == 2:
            self.draws0 = {m: state.gpu.raster[m].draws for m in gl}
        if 2 <= f < last:
            state.camera = cam.orbit(state.camera, self.step, 0.02)
        elif f == last:
            self.log["drag_rects"] = [[m, list(r)] for m, r in state.gpu.blits.last]
            self.log["window_srgb"] = state.gpu.blits.srgb
        elif f == last + 1:
            screenshot.save(window_title(state), self.out / "drag_screen.png")
            for m in gl:
                np.save(self.out / f"image_{m}.npy", np.asarray(state.images[m], np.float32))
            self.log.update(position=list(state.camera.position))
        elif f == last + 2:
            self.log.update(draws={m: state.gpu.raster[m].draws - self.draws0[m] for m in gl},
                            timed={m: state.gpu.raster[m].timed for m in gl},
                            timings={m: state.timings.get(m) for m in gl},
                            rest_rects=[[m, list(r)] for m, r in state.gpu.blits.last])
            state.quit = True


def process_cpu_seconds() -> float:
    """CPU seconds used so far by this process, every thread included (user + system)."""
    import os
    t = os.times()
    return t.user + t.system


def rss_bytes() -> int:
    """Resident set size of this process (``VmRSS`` of /proc/self/status), bytes."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    return 0


class Idle:
    """Nothing touched: once nothing is in progress (:func:`workbench.app.ui.panel_refresh.in_progress`: jobs, the
    error plot's reference and evaluations) and ``settle`` seconds have passed (longer than
    hello_imgui's time active after the last event), count the frames drawn and the
    process CPU time over ``seconds``; then change the ray tracer's knob from the script (no
    input event) and wait for the restarted job's image, which must reach its panel although
    the window was idling; then switch to csg and read the window's title.  Scripts keep the loop awake unless, like this one, they say not."""

    keeps_awake = False

    def __init__(self, out: Path, seconds: float = 10.0, settle: float = 4.0):
        self.out, self.seconds, self.settle, self.log = out, seconds, settle, {}
        self.t_begin = self.t_start = time.perf_counter()
        self.t0, self.step = None, 0

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui.panel_refresh import in_progress
        now = time.perf_counter()
        if self.step == 0 and in_progress(state) and now - self.t_begin < CPU_WAIT_SECONDS:
            self.t_start = now
        if self.step == 0 and now - self.t_start > self.settle:
            self.t0, self.cpu0, self.frame0, self.rss0 = now, process_cpu_seconds(), state.frame, rss_bytes()
            self.step = 1
        elif self.step == 1 and now - self.t0 >= self.seconds:
            dt = now - self.t0
            cpu = process_cpu_seconds() - self.cpu0
            self.log["idle"] = {"seconds": dt, "frames": state.frame - self.frame0,
                                "fps": (state.frame - self.frame0) / dt, "cpu_seconds": cpu,
                                "cpu_percent_of_a_core": 100.0 * cpu / dt,
                                "rss_mb_before_after": [self.rss0 / 2**20, rss_bytes() / 2**20]}
            if "raytrace" in state.methods:
                knob = state.options["raytrace"]["max_depth"]
                set_option(state, "raytrace", "max_depth", 2 if knob != 2 else 3)
                self.t0, self.frame0, self.step = now, state.frame, 2
            else:
                state.quit = True
        elif self.step == 2:
            job = state.jobs.current.get("raytrace")
            if (job is not None and job.image is not None and job.key[3] == (("max_depth",
                state.options["raytrace"]["max_depth"]),)) or now - self.t0 > CPU_WAIT_SECONDS:
                shown = state.images["raytrace"]
                self.log["job_after_idle"] = {
                    "done": job is not None and job.image is not None,
                    "shown_is_job_image": bool(job is not None and job.image is not None
                                               and np.array_equal(shown, job.image)),
                    "frames": state.frame - self.frame0, "seconds": now - self.t0}
                from workbench.app.ui.glfw_title import shown_title
                from workbench.app.ui.state import set_scene
                self.log["title_before"] = shown_title()
                set_scene(state, "csg")
                self.step = 3
        elif self.step == 3:
            from workbench.app.ui.glfw_title import shown_title
            self.log["title_after"] = shown_title()
            state.quit = True


class Soak:
    """A long session in a loop (issue #29, item 3: scene switches, drags, method changes and
    exports): each round switches the scene (through ``scenes``) and shows its first view of
    methods (``state.first_view``: whitted's Phong and ray tracer; cornell's also radiosity and
    the path tracer) plus, in turn every ``len(scenes)`` rounds, Gouraud or the ray caster;
    changes knobs (Phong's tessellation, the ray tracer's depth, the path tracer's samples per
    pixel, radiosity's patch size); shows the difference between the first and last panels;
    drags the camera for a few frames and puts it back (the error plot's references of a
    scene seen before then come from the reference cache); waits until the background jobs,
    the error plot's reference and its points are done (at most :data:`CPU_WAIT_SECONDS`);
    exports the comparison into ``out/export``; and logs a round.  The error plot and the
    difference view are the windows shown in front at start (``layout.windows``).

    The session ends after ``rounds`` rounds, or once ``seconds`` have passed and at least
    ``min_rounds`` rounds were done.  Each round's log: its time since the start, the process
    RSS, the C heap (:func:`heap_info`), the jobs the board keeps, the bytes the window holds
    by kind (:func:`workbench.app.ui.panel_memory.window_bytes`), the hidden panels kept, the
    error plot's points, the files exported and the GL objects alive in the window's context
    (:func:`gl_object_counts`).  ``warmup_rounds`` (``2 * len(scenes)``: every scene seen with
    each added method) is logged: the rounds after it are the session's steady state."""

    def __init__(self, out: Path, rounds: int | None = 24,
                 scenes=("whitted", "csg", "cornell", "quadrics"), seconds: float | None = None,
                 min_rounds: int = 0):
        self.out, self.rounds, self.scenes = out, rounds, scenes
        self.seconds, self.min_rounds, self.t_start = seconds, min_rounds, time.perf_counter()
        self.log = {"rounds": [], "warmup_rounds": 2 * len(scenes)}
        self.round, self.t_wait, self.phase = 0, time.perf_counter(), 0

    def _busy(self, state: AppState) -> bool:
        return state.jobs.busy() or state.errors.busy(state.frame)

    def __call__(self, state: AppState) -> None:
        from workbench.app.ui.drag_resolution import set_adaptive
        from workbench.app.ui.panel_memory import window_bytes
        from workbench.app.ui.state import first_view, choosable_methods, panel_camera, set_scene
        if state.frame == 0:  # drags at full resolution: the framebuffers a drag at adapted
            set_adaptive(state, False)  # scales leaves (one per scale) depend on the machine's speed
        if state.frame < 2:
            return
        if self.phase < 6:  # a few frames of orbiting (every panel redraws, jobs restart)
            state.camera = cam.orbit(state.camera, 0.05, 0.01)
            self.phase += 1
            return
        if self.phase == 6:  # the camera put back (as the scene's camera)
            state.camera = panel_camera(state.scene.camera, state.panel_size)
            self.phase += 1
            return
        if self._busy(state) and time.perf_counter() - self.t_wait < CPU_WAIT_SECONDS:
            return
        exported = export(state, self.out / "export")
        hidden = state.hidden_panels
        self.log["rounds"].append({
            "round": self.round, "seconds": time.perf_counter() - self.t_start,
            "rss_mb": rss_bytes() / 2**20, **heap_info(), "jobs_kept": len(state.jobs.started),
            "scene": state.scene_path.stem, "methods": list(state.methods),
            "window_bytes": window_bytes(state),
            "hidden_panels": [] if hidden is None else hidden.keys(),
            "hidden_budget": None if hidden is None else hidden.max_bytes,
            "plot_points": sum(map(len, state.errors.points.values())),
            "reference": state.errors.ref_image is not None, "exported": len(exported),
            "timed_out": self._busy(state), **gl_object_counts(state)})
        elapsed = time.perf_counter() - self.t_start
        if ((self.rounds is not None and self.round >= self.rounds) or (
                self.seconds is not None and elapsed >= self.seconds and self.round >= self.min_rounds)):
            state.quit = True
            return
        k = self.round + 1
        set_scene(state, self.scenes[k % len(self.scenes)])
        extra = ("gouraud", "raycast")[(k // len(self.scenes)) % 2]
        state.methods[:] = [m for m in (*first_view(state.scene, choosable_methods()), extra)
                            if m in choosable_methods()]
        set_option(state, "phong", "tessellation", (2, 3, 4)[k % 3])
        set_option(state, "raytrace", "max_depth", (2, 3)[k % 2])
        set_option(state, "pathtrace", "spp", (4, 16)[k % 2])
        set_option(state, "radiosity", "patch_size", (0.2, 0.1)[k % 2])
        state.diff_pair = (state.methods[0], state.methods[-1])
        self.round, self.phase, self.t_wait = k, 0, time.perf_counter()


class MallInfo(ctypes.Structure):
    """glibc's ``struct mallinfo2`` (malloc.h)."""

    _fields_ = [(n, ctypes.c_size_t) for n in ("arena", "ordblks", "smblks", "hblks", "hblkhd",
                                               "usmblks", "fsmblks", "uordblks", "fordblks",
                                               "keepcost")]


def heap_info() -> dict:
    """The C heap of this process in MB (glibc's ``mallinfo2``; empty elsewhere):
    ``heap_arenas_mb`` (bytes the arenas took from the system), ``heap_mapped_mb`` (blocks
    mapped of their own), ``heap_used_mb`` (allocated in the arenas), ``heap_free_mb`` (free in
    the arenas, kept: what fragmentation costs)."""
    try:
        info = ctypes.CDLL("libc.so.6").mallinfo2
    except (OSError, AttributeError):
        return {}
    info.restype = MallInfo
    m = info()
    return {f"heap_{name}_mb": getattr(m, field) / 2**20 for name, field in
            (("arenas", "arena"), ("mapped", "hblkhd"), ("used", "uordblks"), ("free", "fordblks"))}


def gl_object_counts(state: AppState, names: int = 4096) -> dict:
    """GL objects alive in the window's context: how many of the names 1..``names`` are
    textures, framebuffers, buffers and programs (``glIsTexture`` and friends, through the
    window's GLFW); empty without GLFW."""
    import ctypes

    import imgui_bundle
    try:
        glfw = ctypes.CDLL(str(Path(imgui_bundle.__file__).parent / "libglfw.so.3"))
    except OSError:
        return {}
    glfw.glfwGetProcAddress.restype = ctypes.c_void_p
    glfw.glfwGetProcAddress.argtypes = [ctypes.c_char_p]
    out = {}
    for kind in ("Texture", "Framebuffer", "Buffer", "Program"):
        addr = glfw.glfwGetProcAddress(f"glIs{kind}".encode())
        if not addr:
            continue
        is_ = ctypes.CFUNCTYPE(ctypes.c_ubyte, ctypes.c_uint)(addr)
        out[f"gl_{kind.lower()}s"] = sum(1 for n in range(1, names + 1) if is_(n))
    return out


def fps_indexed(out: Path) -> Fps:
    """:class:`Fps` with the panels shown through an indexed 16-colour display mode."""
    return Fps(out, display="indexed16-kmeans-fs")


def fps_bare(out: Path) -> Fps:
    """:class:`Fps` without the raster stand-ins (the bare local model)."""
    return Fps(out, standins="off")


def fps_static(out: Path) -> Fps:
    """:class:`Fps` with the camera still and the ray tracer's background job (16 spp) awaited."""
    return Fps(out, step=0.0, raytrace_spp=16, wait_cpu=True)


def drag_rest(out: Path) -> DragRest:
    """:class:`DragRest` with Gouraud shown through a direct 16-bit dithered display mode."""
    return DragRest(out, display={"gouraud": "direct16-565-bayer"})


def fps_material_drag(out: Path) -> SliderFps:
    """:class:`SliderFps` dragging a material slider."""
    return SliderFps(out, "material")


def fps_slider_drag(out: Path) -> SliderFps:
    """:class:`SliderFps` dragging a material slider and light 0's intensity."""
    return SliderFps(out, "material+light")


def idle_quick(out: Path) -> Idle:
    """:class:`Idle` over 3 s."""
    return Idle(out, seconds=3.0)


def soak_memory(out: Path) -> Soak:
    """:class:`Soak` for 150 s and at least three times its warm-up rounds (the test of the
    window's memory over a session)."""
    return Soak(out, rounds=None, seconds=150.0, min_rounds=24)


def soak_10min(out: Path) -> Soak:
    """:class:`Soak` for 600 s."""
    return Soak(out, rounds=None, seconds=600.0)


def soak_30min(out: Path) -> Soak:
    """:class:`Soak` for 1800 s (issue #29, item 3's session)."""
    return Soak(out, rounds=None, seconds=1800.0)
