"""The window loop (hello_imgui through ``immapp.run``), started by ``workbench ui``
(:mod:`workbench.app.cmd_ui`).

With an output folder the loop writes ``ui.png`` (the last frame) and ``summary.json`` (frames,
GL renderer, threads and child processes alive after exit, the script's log) into it.  SIGTERM
and SIGINT close the window as its close button does: background jobs, the error plot's worker
process and the pyrender child end before the process does.
"""
from __future__ import annotations

import json
import multiprocessing
import os
import signal
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

from . import WINDOW_SIZE
from .glfw_title import glfw_library, window_title
from .state import AppState

IDLE_FPS = 2.0
"""Frames per second while nothing changes and no input comes (hello_imgui's idling: it sleeps
between frames; an input event, :func:`hello_imgui.request_refresh` from a background job that
delivers, or :func:`.panel_refresh.in_progress` wakes it at once)."""


def frame_rest(last: float | None, now: float, cap: float, job_running: bool) -> float:
    """Seconds to sleep before a frame that starts at ``now`` when the previous one started at
    ``last``: enough to keep at most ``cap`` frames per second while a background job runs
    (0 without a job, without a cap or on the first frame)."""
    if last is None or cap <= 0.0 or not job_running:
        return 0.0
    return max(0.0, last + 1.0 / cap - now)


def run(state: AppState, frames: int | None = None, script=None,
        window: tuple[int, int] = WINDOW_SIZE, out: Path | None = None) -> int:
    """Open the window (``window`` = (width, height) pixels) and loop until it is closed,
    ``frames`` frames were shown, the script sets ``state.quit`` or SIGTERM/SIGINT comes.
    Background jobs and child processes are ended and joined before returning (after a signal,
    CPU jobs get :data:`SIGNAL_GRACE_SECONDS`: one inside a numba compile cannot stop sooner);
    with ``out``, the last frame and the summary are written there.  Returns 0, or 128 + the
    signal's number when a signal closed the window."""
    t0 = time.perf_counter()
    with quit_on_signals(state) as closing:
        try:
            shown = _loop(state, frames, script, window)
        finally:
            closing.set()
            stop_background(state)
    if out is not None:
        write_outputs(state, script, out, time.perf_counter() - t0, shown)
    return 128 + state.quit_signal if state.quit_signal else 0


SIGNAL_GRACE_SECONDS = 1.0
"""After SIGTERM or SIGINT, how long the CPU jobs' threads, then the error plot's, get to see
their cancel flag."""
SIGNAL_EXIT_SECONDS = 3.0
"""After SIGTERM or SIGINT, how long the window's loop gets to end before the process ends its
child processes and itself."""
SIGNAL_END_SECONDS = 4.0
"""After SIGTERM or SIGINT, how long the whole exit (the loop, the clean-up and the
interpreter's own end, which waits for every job thread: one inside a numba compile cannot
stop) may take before the process ends its child processes and itself."""


@contextmanager
def quit_on_signals(state: AppState):
    """While the window runs, SIGTERM and SIGINT set ``state.quit`` and ``state.quit_signal``
    (the loop ends at its next frame, as by the close button) instead of killing the process
    past its children; a second signal before then ends the process at once (after the
    ``finally`` clean-ups).

    A Python handler runs only when the main thread returns to the interpreter, which a long
    call (a GL draw or a compile under load) can delay: so the signal's number is also written
    to a pipe by the interpreter's C handler (:func:`signal.set_wakeup_fd`), and a watcher
    thread, woken by it, sets the flags itself and, if the loop has not ended (the event this
    yields, which the caller sets when it has) :data:`SIGNAL_EXIT_SECONDS` later, terminates the
    child processes and ends the process (status 128 + the signal's number); it does the same
    if the process has not ended :data:`SIGNAL_END_SECONDS` after the signal (it outlives this
    context once a signal came)."""
    handled = []  # the signals the Python handler saw (the watcher may set the flags first)

    def handler(signum, _frame):
        if handled:
            raise SystemExit(128 + signum)
        handled.append(signum)
        state.quit, state.quit_signal = True, state.quit_signal or signum
    read_end, write_end = os.pipe()
    os.set_blocking(write_end, False)
    closing = threading.Event()

    def end(signum):
        for child in multiprocessing.active_children():
            child.terminate()
        os._exit(128 + signum)

    def watch():
        data = os.read(read_end, 1)
        if not data:  # the context ended without a signal
            return
        t_signal = time.monotonic()
        state.quit_signal = state.quit_signal or data[0]
        state.quit = True
        if not closing.wait(SIGNAL_EXIT_SECONDS):
            end(data[0])
        time.sleep(max(0.0, t_signal + SIGNAL_END_SECONDS - time.monotonic()))
        end(data[0])
    old = {s: signal.signal(s, handler) for s in (signal.SIGTERM, signal.SIGINT)}
    old_fd = signal.set_wakeup_fd(write_end, warn_on_full_buffer=False)
    watcher = threading.Thread(target=watch, name="ui-signal-watch", daemon=True)
    watcher.start()
    try:
        yield closing
    finally:
        closing.set()
        signal.set_wakeup_fd(old_fd)
        for s, h in old.items():
            signal.signal(s, h)
        os.close(write_end)          # wakes the watcher if no signal came
        if not state.quit_signal:
            watcher.join()
            os.close(read_end)


def write_outputs(state: AppState, script, out: Path, seconds: float, shown: list) -> None:
    """``out/ui.png`` (the last frame, when hello_imgui kept one) and ``out/summary.json``;
    ``shown`` lists (panel name, (x0, y0, x1, y1) window pixels) of the images in the last
    frame."""
    from imgui_bundle import hello_imgui
    from PIL import Image
    shot = hello_imgui.final_app_window_screenshot()
    if shot is not None and shot.size:
        Image.fromarray(shot[..., :3]).save(out / "ui.png")
    summary = {"frames": state.frame, "seconds": seconds,
               "gl_renderer": state.gl_renderer, "methods": state.methods,
               "scene": state.scene_path.stem,
               "panel_size": [state.camera.width, state.camera.height],
               "window": list(state.window_size),
               "timings": state.timings, "shown": [[m, list(r)] for m, r in shown],
               "threads": [t.name for t in threading.enumerate()],
               "child_processes": [c.name for c in multiprocessing.active_children()],
               "script": getattr(script, "log", {})}
    (out / "summary.json").write_text(json.dumps(summary, indent=1, default=str))


def _loop(state: AppState, max_frames: int | None, script, window: tuple[int, int]) -> list:
    """hello_imgui's runner with the workbench's callbacks; returns when the window closes,
    with the images' rectangles of the last frame (:attr:`.screen_blits.ScreenBlits.last`)."""
    import moderngl
    from imgui_bundle import hello_imgui, immapp

    from ...renderers import gl
    from . import window_style
    from .panel_gpu import release_gl
    from .panel_refresh import in_progress, update_images
    from .panel_show import draw_shown_images
    from .layout import docking_params, refit
    from .panels import status_bar
    from .plot import track
    clock = {"t": None, "title": window_title(state)}
    shown = []

    def post_init():
        state.ctx = moderngl.create_context()  # the window's current GLFW context
        gl.use_context(state.ctx)
        state.gl_renderer = gl.renderer_name(state.ctx)
        state.jobs.notify = hello_imgui.request_refresh  # a job's new tiles wake the loop

    def show_gui():
        now = time.perf_counter()
        rest = frame_rest(clock["t"], now, state.fps_cap_while_job, state.jobs.busy())
        if rest > 0.0:
            time.sleep(rest)
            now = time.perf_counter()
        if clock["t"] is not None:
            state.frame_seconds = now - clock["t"]
        clock["t"] = now
        state.drag.frame(state.camera, now, state.frame_seconds)  # the GL panels' scale
        refit(state)
        update_images(state)
        track(state)
        if window_title(state) != clock["title"]:  # the scene changed: so does the title
            clock["title"] = window_title(state)
            glfw = glfw_library()
            glfw.glfwSetWindowTitle(glfw.glfwGetCurrentContext(), clock["title"].encode())
        if script is not None:
            script(state)
        if in_progress(state) or getattr(script, "keeps_awake", script is not None):
            hello_imgui.request_refresh()

    def end_frame():  # after every dockable window's gui, before ImGui renders
        state.gui_seconds = time.perf_counter() - clock["t"]
        state.frame += 1
        if state.quit or (max_frames is not None and state.frame >= max_frames):
            hello_imgui.get_runner_params().app_shall_exit = True

    def before_exit():
        from .glfw_title import window_size
        from .window_size import remember
        state.window_size = window_size()
        note = remember(state.window_size)  # the next run opens at this size
        if note:
            print(note, file=sys.stderr)
        if state.gpu is not None:
            shown.extend(state.gpu.blits.last)
        stop_background(state)
        release_gl(state)

    params = hello_imgui.RunnerParams()
    params.app_window_params.window_title = window_title(state)
    params.app_window_params.window_geometry.size = window
    params.fps_idling.enable_idling = True
    params.fps_idling.fps_idle = IDLE_FPS
    # hello_imgui asks for an 8x multisampled window by default: on llvmpipe that makes every
    # frame ~4x dearer (imgui anti-aliases its own shapes and text without it)
    params.renderer_backend_options.open_gl_options.anti_aliasing_samples = 0
    params.imgui_window_params.show_status_bar = True
    # hello_imgui's own FPS and idling toggle sat under the status text in a narrow window
    # (1024 x 600); the status text gives the frame time, and idling is always on
    params.imgui_window_params.show_status_fps = False
    params.imgui_window_params.default_imgui_window_type = \
        hello_imgui.DefaultImGuiWindowType.provide_full_screen_dock_space
    params.docking_params = docking_params(state, window[1])
    params.ini_disable = True  # no settings file written into the working folder
    params.callbacks.post_init = post_init
    theme_style = params.callbacks.setup_imgui_style

    def setup_style():  # window backgrounds: one clear per frame, not one fill per window
        theme_style()
        window_style.clear_to_window_background()
    params.callbacks.setup_imgui_style = setup_style
    params.callbacks.show_gui = show_gui
    params.callbacks.before_imgui_render = lambda: (end_frame(), draw_shown_images(state))
    params.callbacks.show_status = lambda: status_bar(state)
    params.callbacks.before_exit = before_exit
    immapp.run(params, immapp.AddOnsParams(with_implot=True))
    return shown


def stop_background(state: AppState) -> None:
    """End everything that runs beside the window: the CPU jobs, the error plot's reference
    render and worker, the pyrender child process (child processes always joined; threads
    joined, or given :data:`SIGNAL_GRACE_SECONDS` after a signal)."""
    grace = SIGNAL_GRACE_SECONDS if state.quit_signal else None
    state.jobs.join_all(grace)
    state.errors.shutdown(grace)
    if state.pyrender is not None:
        state.pyrender.close()
        state.pyrender = None
