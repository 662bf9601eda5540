"""The window loop (hello_imgui through ``immapp.run``).

``python -m workbench.app.ui.main [SCENE] --test-script check --out DIR`` runs a scripted
session (see :mod:`.scripts`) and writes the panel images, ``summary.json`` (frames, GL
renderer, threads alive after exit) and ``ui.png`` (the last frame) into DIR.
"""
from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import threading
import time
from pathlib import Path

from ...core.errors import WorkbenchError
from ..args import size
from .glfw_title import glfw_library, window_title
from .state import AppState, new_state

WINDOW_SIZE = (1280, 760)
IDLE_FPS = 2.0
"""Frames per second while nothing changes and no input comes (hello_imgui's idling: it sleeps
between frames; an input event, :func:`hello_imgui.request_refresh` from a background job that
delivers, or :func:`.frames.in_progress` wakes it at once)."""


def frame_rest(last: float | None, now: float, cap: float, job_running: bool) -> float:
    """Seconds to sleep before a frame that starts at ``now`` when the previous one started at
    ``last``: enough to keep at most ``cap`` frames per second while a background job runs
    (0 without a job, without a cap or on the first frame)."""
    if last is None or cap <= 0.0 or not job_running:
        return 0.0
    return max(0.0, last + 1.0 / cap - now)


def run(state: AppState, max_frames: int | None = None, script=None,
        window: tuple[int, int] = WINDOW_SIZE) -> None:
    """Open the window (``window`` = (width, height) pixels) and loop until it is closed,
    ``max_frames`` frames were shown or the script sets ``state.quit``.  Background jobs are
    joined before returning."""
    import moderngl
    from imgui_bundle import hello_imgui, immapp

    from ...renderers import gl
    from . import window_style
    from .frames import draw_shown_images, in_progress, release_gl, update_images
    from .layout import docking_params
    from .panels import status_bar
    from .plot import track
    clock = {"t": None, "title": window_title(state)}

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
    stop_background(state)


def stop_background(state: AppState) -> None:
    """End everything that runs beside the window (joined): the CPU jobs, the error plot's
    reference render and worker, the pyrender child process."""
    state.jobs.join_all()
    state.errors.shutdown()
    if state.pyrender is not None:
        state.pyrender.close()
        state.pyrender = None


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m workbench.app.ui.main")
    p.add_argument("scene", nargs="?", default="whitted")
    p.add_argument("--methods", default="", help="comma-separated, 1 to 6")
    p.add_argument("--size", type=int, default=256,
                   help="panel resolution: pixels along the longer side (the other side keeps "
                        "the scene camera's aspect)")
    p.add_argument("--frames", type=int, default=None, help="stop after this many frames")
    p.add_argument("--window", type=size, default=WINDOW_SIZE, metavar="WxH",
                   help="window size in pixels (default %(default)s)")
    p.add_argument("--test-script", default=None, help="check or fps (see scripts.py)")
    p.add_argument("--out", type=Path, default=None, help="folder for the script's outputs")
    args = p.parse_args(argv)
    if not 8 <= args.size <= 4096:
        p.error(f"--size {args.size}: the panels' resolution must be 8 to 4096 pixels")
    from .scripts import SCRIPTS
    try:
        state = new_state(args.scene, [m for m in args.methods.split(",") if m] or None,
                          args.size)
    except WorkbenchError as e:  # a bad scene or method list: one line, as `workbench ui` says it
        print(f"workbench: error: {e}", file=sys.stderr)
        return 2
    script = None
    if args.test_script:
        args.out = args.out or Path("out/ui")
    if args.out is not None:  # also without a script: the last frame and the summary
        args.out.mkdir(parents=True, exist_ok=True)
    if args.test_script:
        script = SCRIPTS[args.test_script](args.out)
    t0 = time.perf_counter()
    run(state, args.frames, script, args.window)
    if args.out is not None:
        from imgui_bundle import hello_imgui
        from PIL import Image
        shot = hello_imgui.final_app_window_screenshot()
        if shot is not None and shot.size:
            Image.fromarray(shot[..., :3]).save(args.out / "ui.png")
        summary = {"frames": state.frame, "seconds": time.perf_counter() - t0,
                   "gl_renderer": state.gl_renderer, "methods": state.methods,
                   "scene": state.scene_path.stem, "panel_size": [state.camera.width, state.camera.height],
                   "timings": state.timings,
                   "threads": [t.name for t in threading.enumerate()],
                   "child_processes": [c.name for c in multiprocessing.active_children()],
                   "script": getattr(script, "log", {})}
        (args.out / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
