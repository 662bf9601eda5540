"""``workbench ui [SCENE]``: the interactive comparison window (imgui-bundle, GLFW).

The one way to start the window: users, tests and benchmarks all run this command.  ``--script
FILE.py:NAME`` drives the window from a scripted session written in Python
(:mod:`.ui.session_file`; the project's own are in ``tests/app/ui/sessions.py``) and ``--out``
receives its outputs: what the session records, ``summary.json`` and ``ui.png`` (the last frame).
"""
from __future__ import annotations

import os
import sys
import threading
from pathlib import Path

from .args import methods_list, size
from .ui import WINDOW_SIZE

PANEL_SIZE_RANGE = (8, 4096)
"""Allowed ``--size``: pixels along the panels' longer side."""


def add_parser(sub) -> None:
    # (the help names ui.state's FIRST_VIEW, EMITTER_VIEW and MAX_PANELS without importing the
    # window's modules for every command; tests/app/ui/test_ui_command.py checks that they agree)
    p = sub.add_parser("ui", help="interactive side-by-side comparison window",
                       description="Open a window comparing the methods live on one camera: "
                                   "mouse orbit (left drag), pan (right drag), zoom (wheel).")
    p.add_argument("scene", nargs="?", default="whitted", help="bundled scene name or file")
    p.add_argument("--methods", type=methods_list, default=[],
                   help="comma-separated methods, 1 to 6 (default: phong,raytrace, plus "
                        "radiosity,pathtrace on a scene with emitters)")
    p.add_argument("--size", type=int, default=256,
                   help="panel resolution: pixels along the longer side, the other side keeps the "
                        "scene camera's aspect (default %%(default)s; %d to %d)" % PANEL_SIZE_RANGE)
    p.add_argument("--window", type=size, default=None, metavar="WxH",
                   help="window size in pixels, at least 320x240 (default: the size the window "
                        "had when last closed, else %dx%d)" % WINDOW_SIZE)
    p.add_argument("--drag-resolution", choices=("adaptive", "full"), default="adaptive",
                   help="while the camera moves, the GL panels render at the largest resolution "
                        "that holds 30 frames per second and at full resolution once it rests "
                        "(adaptive, the default; the Scene window's 'drag at 30 fps'), or always "
                        "at full resolution (full)")
    p.add_argument("--frames", type=int, default=None, metavar="N",
                   help="close the window after N frames")
    p.add_argument("--script", default=None, metavar="FILE.py:NAME",
                   help="drive the window with a scripted session: NAME(out) in the Python file "
                        "FILE.py makes a callable the window calls once per frame with its state "
                        "(the project's tests and benchmarks keep theirs in tests/app/ui/sessions.py)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="write the last frame (ui.png), summary.json and the script's outputs here")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..core.errors import WorkbenchError
    lo, hi = PANEL_SIZE_RANGE
    if not lo <= args.size <= hi:
        raise WorkbenchError(f"--size must be in [{lo}, {hi}] pixels, got {args.size}")
    if args.frames is not None and args.frames < 1:
        raise WorkbenchError(f"--frames must be at least 1, got {args.frames}")
    from .ui.window_size import MIN_SIZE, remembered
    window = args.window
    if window is not None and not (window[0] >= MIN_SIZE[0] and window[1] >= MIN_SIZE[1]):
        raise WorkbenchError(f"--window must be at least {MIN_SIZE[0]}x{MIN_SIZE[1]} pixels, "
                             f"got {window[0]}x{window[1]}")
    if args.script is not None:
        from .ui.session_file import load_session
        make_session = load_session(args.script)
    out = args.out if args.out is not None or args.script is None else Path("out/ui")
    if out is not None:
        from ..core.output_paths import check_output_dir
        check_output_dir(out, "--out")
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise WorkbenchError("no display (DISPLAY is not set): the UI needs a window; "
                             "under no screen run it inside `xvfb-run -s '-screen 0 1280x800x24'`")
    if out is not None:
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise WorkbenchError(f"--out {out}: cannot create the folder ({e.strerror})") from None
    if window is None:  # the size the window had when last closed (ui.window_size)
        window, note = remembered()
        if note:
            print(note, file=sys.stderr)
    from .ui.heap import map_large_blocks
    from .ui.state import new_state
    from .ui.main import run
    map_large_blocks()  # images in mappings of their own, not in the arenas (issue #29)
    state = new_state(args.scene, args.methods or None, args.size)
    state.drag.enabled = args.drag_resolution == "adaptive"
    script = make_session(out) if args.script is not None else None
    code = run(state, frames=args.frames, script=script, window=window or WINDOW_SIZE, out=out)
    if code and threading.active_count() > 1:
        # a signal closed the window while a CPU job was still inside a numba compile (which
        # cannot be interrupted): its children are gone, so end without waiting for it
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code
