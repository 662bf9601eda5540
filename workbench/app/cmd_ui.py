"""``workbench ui [SCENE]``: the interactive comparison window (imgui-bundle, GLFW)."""
from __future__ import annotations

from .args import methods_list


def add_parser(sub) -> None:
    p = sub.add_parser("ui", help="interactive side-by-side comparison window",
                       description="Open a window comparing the methods live on one camera: "
                                   "mouse orbit (left drag), pan (right drag), zoom (wheel).")
    p.add_argument("scene", nargs="?", default="whitted", help="bundled scene name or file")
    p.add_argument("--methods", type=methods_list, default=[], help="comma-separated methods, 1 to 6 "
                                                 "(default: flat,gouraud,phong)")
    p.add_argument("--size", type=int, default=256, help="panel width and height in pixels")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..core.errors import WorkbenchError
    if not 16 <= args.size <= 2048:
        raise WorkbenchError(f"--size must be in [16, 2048], got {args.size}")
    import os
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise WorkbenchError("no display (DISPLAY is not set): the UI needs a window; "
                             "under no screen run it inside `xvfb-run -s '-screen 0 1280x800x24'`")
    from .ui.main import run as run_ui
    from .ui.state import new_state
    state = new_state(args.scene, args.methods or None,
                      (args.size, args.size))
    run_ui(state)
    return 0
