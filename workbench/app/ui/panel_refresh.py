"""Each panel's picture redrawn only when what it shows changes (:func:`update_images`, once
per frame before the widgets).

* GL methods (``ui_kind`` ``"gl"``: flat, Gouraud, Phong, a user's shading model) draw through a cached
  :class:`~workbench.renderers.raster.RasterSession` (one per scene, method and options,
  built by :func:`.gl_sessions.build_session`; replaced sessions are released) into the
  session's float framebuffer, in the window's own moderngl context, and only when the
  panel's inputs change: the scene version (materials, lights), the panel's options
  (tessellation, stand-ins) and the shared camera (which carries the panel size).  A frame
  in which nothing changed draws nothing.  A material or light slider keeps
  the session (``RasterSession.update``): the edited values are drawn by live programs that
  read them from uniforms (compiled once, no geometry upload), and once the values have
  rested for :data:`LIVE_REST_SECONDS` they are compiled back in (``settle``: the literal
  programs, the fast static variant), one program per frame.
* During a drag (a panel drawn in consecutive frames) the frame does not wait for the GPU
  after a panel's draw (no ``glFinish``): it is timed once the camera rests, by one more draw
  of the same image (:func:`timed_draw`).  llvmpipe itself still waits where a pass reads a
  panel whose draw is not done.  While the camera moves a panel draws at the resolution
  :mod:`.drag_resolution` chooses for the frame budget (its image is then smaller, shown
  scaled up in the same rectangle), never timed; at full resolution once the camera rests.
* CPU and progressive methods are requested from the :class:`~.jobs.JobBoard`; their image is
  taken when the job reports new tiles (``Job.version``), drawn over the panel's previous
  image until done (:func:`over_stale`).
* :func:`in_progress` tells the loop whether something on screen changes by itself.
"""
from __future__ import annotations

import time

import numpy as np

from .drag_resolution import render_camera
from .panel_gpu import PanelGPU, RasterPanel, gpu, read_pixel, stale, take_gpu_stats
from .state import AppState, method_kind

LIVE_REST_SECONDS = 0.5
"""How long edited material or light values must stay unchanged before a GL panel compiles
them back into its programs (until then it draws them from uniforms)."""


def tiled(method: str) -> bool:
    """The method accepts ``on_tile`` (it reports partial images band by band)."""
    from ...renderers.base import get_renderer
    return "on_tile" in get_renderer(method).options


def refresh_raster(state: AppState, method: str) -> bool:
    """Redraw ``method``'s panel if its inputs changed; returns whether it drew."""
    from ...core.errors import WorkbenchError
    from ...renderers.raster import RasterSession
    from .gl_sessions import build_session, session_status
    g = gpu(state)
    key = (state.scene_version, tuple(sorted(state.options[method].items())))
    panel = g.raster.get(method)
    if (panel is not None and panel.session_key != key and panel.session_key[1] == key[1]
            and panel.session.update(state.scene)):
        # only material or light values changed: same session, live programs
        panel.session_key, panel.drawn, panel.edited = key, None, time.perf_counter()
    elif panel is None or panel.session_key != key:
        if state.panel_errors.get(method, (None,))[0] == key:
            return False  # did not build for these inputs: its message stays shown
        if panel is not None:
            g.compiled += panel.session.programs.compiles
            panel.session.release()
            del g.raster[method]
            g.linear.pop(method, None)
        try:
            session = build_session(state, method)
        except WorkbenchError as e:  # over the memory limit, a model that does not compile: one line
            state.panel_errors[method] = (key, str(e))
            state.status[method] = str(e)
            if method in state.images:  # del, not pop: a pending read of a released session
                del state.images[method]
            state.ctx.screen.use()
            return False
        state.panel_errors.pop(method, None)
        panel = g.raster[method] = RasterPanel(session, key)
        state.status[method] = session_status(panel.session)
    if (panel.session.live and time.perf_counter() - panel.edited > LIVE_REST_SECONDS
            and g.settle_frame != state.frame):
        # the values rested: compiled back in (the static variant), one program per frame
        # over all panels (each costs llvmpipe ~0.1 s, most of it at its first draw)
        g.settle_frame = state.frame
        panel.session.settle(budget=1)
        panel.drawn = None
    cam = render_camera(state.drag, state.camera)  # smaller while the camera moves
    full = cam is state.camera
    if panel.drawn == cam and method in state.images:
        if not panel.timed and full:  # the drag has ended: time a draw of the image shown
            timed_draw(state, panel, method)
            panel.draws += 1
        return False
    fbo = panel.session.framebuffer(cam.width, cam.height)
    if panel.drawn_frame == state.frame - 1 or not (full and panel.timed):
        # drawn last frame too (a drag), at the drag's smaller resolution or back at full
        # resolution after it: no wait for the draw to end, so that llvmpipe's threads
        # rasterise it while this thread goes on with the frame; it is timed once the camera
        # rests at full resolution (the next frame)
        panel.session.draw_to(fbo, cam, *shared_near_far(g, panel.session, cam))
        state.ctx.screen.use()  # back to the window's framebuffer for imgui
        panel.timed = False
    else:
        timed_draw(state, panel, method, fbo)
    state.image_requests[method] = (cam, state.scene)
    state.images.set_pending(method, lambda: RasterSession.read_image(fbo),
                             pixel=lambda i, j, shape: read_pixel(fbo, i, j, shape),
                             shape=(cam.height, cam.width))
    g.linear[method] = (fbo.color_attachments[0], True, state.images.version(method))
    panel.drawn, panel.draws, panel.drawn_frame = cam, panel.draws + 1, state.frame
    return True


def timed_draw(state: AppState, panel: RasterPanel, method: str, fbo=None) -> None:
    """Draw ``panel`` at ``state.camera`` into ``fbo`` (by default its framebuffer of the
    camera's size, redrawing the image it holds: the same image) and wait for the draw to end:
    ``state.timings[method]`` is the draw's time, not just its submission."""
    cam = state.camera
    if fbo is None:
        fbo = panel.session.framebuffer(cam.width, cam.height)
    t0 = time.perf_counter()
    panel.session.draw_to(fbo, cam, *shared_near_far(gpu(state), panel.session, cam))
    state.ctx.finish()
    state.ctx.screen.use()  # back to the window's framebuffer for imgui
    state.timings[method] = time.perf_counter() - t0
    panel.timed = True


def shared_near_far(g: PanelGPU, session, cam) -> tuple[float, float]:
    """The automatic clip planes of ``session`` for ``cam``, computed once per camera for
    sessions with the same parts' boxes (the GL panels of one scene and tessellation share
    them: 3-10 ms of Python each on a loaded machine, every frame of a drag)."""
    key = session.part_boxes.tobytes()
    if g.near_far.get("camera") != cam:
        g.near_far = {"camera": cam}
    if key not in g.near_far:
        g.near_far[key] = session.near_far(cam)
    return g.near_far[key]


def refresh_cpu(state: AppState, method: str) -> None:
    """Ask for ``method``'s background job; take its image when it has new tiles."""
    job = state.jobs.request(state.scene, state.camera, method, state.options[method],
                             tiled=tiled(method))
    if job.cancelled.is_set():
        state.status[method] = "restarting (stale image)"
    elif job.error:
        state.status[method] = job.error
    elif job.done:
        state.timings[method] = job.seconds
        state.status[method] = (f"done: {job.spp} spp, noise {job.noise:.3g}"
                                if job.progressive and job.noise is not None
                                else f"done: {job.meter.text()}" if job.shoots and job.meter.first
                                else "done")
    elif job.meter is not None and job.meter.first is not None:
        # samples per pixel, rows or shooting rounds done, and the time left (a phased job:
        # its phase, and the time elapsed where the phase reports no amount done)
        state.status[method] = ("" if job.phased else "refining: " if job.progressive or job.shoots
                                else "rendering: ") + job.meter.text()
    else:
        state.status[method] = waiting_text(method, job)
    shape = (state.camera.height, state.camera.width, 3)
    key = (id(job), job.version, shape, job.cancelled.is_set())
    if stale(state, f"{method} job", key) or method not in state.images:
        image, held = job.snapshot()
        # the previous job's image is kept while its successor waits, unless it has another
        # size (a scene switch changed the panels' aspect): then black until the new one comes
        if image.shape == shape:
            state.images[method] = over_stale(state, method, job, image)
            state.progress[method] = shown_progress(state, method, job, held)
            if state.progress[method]["state"] in ("done", "refining", "shooting") or method not in state.image_requests:
                state.image_requests[method] = (job.camera, job.scene)
            # else: the previous image (or its rows not yet rendered again) still shows
        else:
            state.images[method] = np.zeros(shape, np.float32)
            state.progress[method] = {"state": "waiting"}
            state.image_requests.pop(method, None)


def mismatch(state: AppState, a: str, b: str) -> str:
    """Why panels ``a`` and ``b`` do not show the same camera and scene (empty when they do):
    during a drag a GL panel follows the camera while a ray-traced one keeps its previous image
    until its new render is done (issue #29, item 7: the difference view compared them
    unflagged)."""
    ra, rb = state.image_requests.get(a), state.image_requests.get(b)
    if ra is None or rb is None:
        return f"waiting for {a if ra is None else b}"
    def same(r, q) -> bool:  # scenes by identity: every edit makes a new one
        return r[0] == q[0] and r[1] is q[1]

    if same(ra, rb):
        return ""
    what = "camera" if ra[0] != rb[0] else "scene edit"
    behind = [m for m in (a, b) if state.progress.get(m, {}).get("state") in ("stale", "rendering")]
    return f"{a} and {b} show different {what}s" + (f" ({behind[0]} re-renders)" if len(behind) == 1 else "")


def shown_progress(state: AppState, method: str, job, held: dict) -> dict:
    """What ``method``'s panel shows of ``job`` (``held``: :meth:`.jobs.Job.snapshot`'s
    account of the image taken), as the export records it (issue #29, item 5: an export
    recorded the target spp of a panel still refining).

    ``state``: ``"done"`` (the finished render of the current request), ``"refining"`` (a
    progressive job's running image), ``"shooting"`` (radiosity's progressive refinement after
    ``shots`` rounds, ``unshot`` the share of the emitted power still unshot), ``"rendering"``
    (``rows_done`` of ``rows`` rendered, over
    the previous image), ``"stale"`` (the previous request's image: a restart is pending, or
    nothing of the new render has come yet).  A progressive job's also ``spp`` (samples per
    pixel in the image), ``target_spp`` (its knob), ``passes``, ``noise`` (RMS standard error of
    the pixel means, None before two samples) and ``converged`` (it reached its target)."""
    from ...renderers.base import get_renderer
    rows = state.camera.height
    if job.cancelled.is_set():
        out = {"state": "stale"}
    elif held["done"]:
        out = {"state": "done"}
    elif job.progressive:
        out = {"state": "refining" if held["spp"] > 0 else "stale"}
    elif job.shoots:
        out = ({"state": "shooting", "shots": held["shots"], "unshot": held["unshot"]}
               if held["shots"] > 0 else {"state": "stale"})
    elif held["rows_done"] > 0:
        out = {"state": "rendering", "rows_done": held["rows_done"], "rows": rows}
    else:
        out = {"state": "stale"}
    if job.progressive and out["state"] != "stale":
        target = int(state.options[method][get_renderer(method).knob.name])
        out.update(spp=held["spp"], target_spp=target, passes=held["passes"],
                   noise=held["noise"], converged=held["done"] and held["spp"] >= target)
    return out


def waiting_text(method: str, job) -> str:
    """The status of a job that has reported no progress yet: its elapsed time, and, for a
    method with no way to report any (no rows, passes, rounds or phases), that it will not."""
    from .meter import clock_text
    elapsed = clock_text(time.perf_counter() - job.begun)
    if job.meter is None:
        return f"rendering, {elapsed} elapsed ({method} reports no progress)"
    return f"rendering, {elapsed} elapsed"


def running_meter(job):
    """``job``'s :class:`.meter.Meter` while it runs and has reported progress (its panel shows
    a progress bar), else None (done, failed, cancelled, or no report yet)."""
    if job.done or job.cancelled.is_set() or job.meter is None or job.meter.first is None:
        return None
    return job.meter


def over_stale(state: AppState, method: str, job, image: np.ndarray) -> np.ndarray:
    """What a CPU panel shows of ``job``'s ``image`` (H, W, 3): the image once done; before,
    its rendered bands (rows ``0 .. job.rows_done``; a progressive job's image once it has a
    sample) over the panel's previous image (its *backdrop*, taken when the job first shows),
    so a restarted render never blanks the panel (it used to show black until its bands came)."""
    g = gpu(state)
    held = g.backdrops.get(method)
    if held is None or held[0] != id(job):
        prev = state.images[method] if method in state.images else None
        held = g.backdrops[method] = (id(job), prev)
    back = held[1]
    if job.done or back is None or back.shape != image.shape:
        return image
    if job.progressive or job.shoots:  # a whole image once the first pass has landed
        return image if job.meter.first is not None else back
    out = back.copy()
    out[:job.rows_done] = image[:job.rows_done]
    return out


def update_images(state: AppState) -> None:
    """Bring every selected panel up to date (called once per frame, before the widgets)."""
    from .panel_memory import keep_hidden
    from .pyrender_proc import refresh_pyrender
    if state.gpu is not None:
        take_gpu_stats(state, "difference")
    state.jobs.keep_only(state.methods)
    keep_hidden(state)  # the resources of panels hidden long ago are freed
    if state.gpu is not None:  # a removed panel's approximation keeps nothing awake
        state.gpu.modes.approximate &= set(state.methods)
    for m in state.methods:
        kind = method_kind(state, m)
        if kind == "gl":
            refresh_raster(state, m)
        elif kind == "child":
            refresh_pyrender(state)
        else:
            refresh_cpu(state, m)


def in_progress(state: AppState, plot: bool = True) -> bool:
    """Something on screen changes by itself this frame: a background job or the pyrender child
    is working, the error plot waits for its reference or evaluations (unless ``plot`` is
    False: the panels alone), or a GL panel has edited values still to compile back in.  The
    loop then runs at full rate (capped while a job runs, :func:`.main.frame_rest`); otherwise
    it idles."""
    proc = state.pyrender
    g = state.gpu
    return (state.jobs.busy() or (proc is not None and proc.busy) or (plot and state.errors.busy(state.frame))
            or (g is not None and (any(p.session.live or not p.timed for p in g.raster.values())
                                   or g.modes.busy()
                                   or any(g.stats.get(k, (None,))[0] != v[0]
                                          for k, v in g.gpu_stats.items()))))
