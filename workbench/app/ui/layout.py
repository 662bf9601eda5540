"""The docking layout (hello_imgui ``DockingParams``): where each window of the UI starts.

::

    +-----------+---------------------------------------+
    | Scene     |                                       |
    +-----------+  Panels (MainDockSpace)               |
    | Methods   |                                       |
    +-----------+-------------------+-------------------+
    | Parameters| Difference        | Error plot        |
    | Lights    |                   | Ray tree          |
    | Colour    |                   | Patch view        |
    +-----------+-------------------+-------------------+
    | status bar: GL_RENDERER | frame time | per-method timings |

Windows in one dock space are tabs; every window can be dragged elsewhere, split or floated.
Each window's content is a gui function taking the :class:`~.state.AppState`.
"""
from __future__ import annotations

from imgui_bundle import hello_imgui, imgui

from .state import AppState
from .window_style import with_background

SPLITS = (("MainDockSpace", "ControlSpace", imgui.Dir.left, 0.27),
          ("ControlSpace", "ParamSpace", imgui.Dir.down, 0.5),
          ("ControlSpace", "MethodSpace", imgui.Dir.down, 0.3),
          ("MainDockSpace", "ToolSpace", imgui.Dir.down, 0.45),
          ("ToolSpace", "DiffSpace", imgui.Dir.left, 0.45))
"""(dock space split, new dock space, side, fraction of the split one) in order."""


def windows(state: AppState) -> list[tuple[str, str, object]]:
    """(label, dock space, gui function of no argument) of every dockable window."""
    from .file_browser import file_browser
    from .inspect import ray_tree_view
    from .lights import light_controls
    from .panels import (colour_wheel, difference_panel, image_panels, method_list, parameters,
                         scene_picker)
    from .patch_view import patch_view
    from .plot import error_plot
    return [("Scene", "ControlSpace", lambda: (scene_picker(state), file_browser(state))),
            ("Methods", "MethodSpace", lambda: method_list(state)),
            ("Parameters", "ParamSpace", lambda: parameters(state)),
            ("Lights", "ParamSpace", lambda: light_controls(state)),
            ("Colour wheel", "ParamSpace", lambda: colour_wheel(state)),
            ("Panels", "MainDockSpace", lambda: image_panels(state)),
            ("Difference", "DiffSpace", lambda: difference_panel(state)),
            ("Error plot", "ToolSpace", lambda: error_plot(state)),
            ("Ray tree", "ToolSpace", lambda: ray_tree_view(state)),
            ("Patch view", "ToolSpace", lambda: patch_view(state))]


def docking_params(state: AppState) -> hello_imgui.DockingParams:
    """The splits and dockable windows, applied at every start (no settings file is kept)."""
    params = hello_imgui.DockingParams()
    params.docking_splits = [hello_imgui.DockingSplit(a, b, d, r) for a, b, d, r in SPLITS]
    params.dockable_windows = [hello_imgui.DockableWindow(label, space, with_background(fn),
                                                          can_be_closed_=False)
                               for label, space, fn in windows(state)]
    params.layout_condition = hello_imgui.DockingLayoutCondition.application_start
    for w in params.dockable_windows:  # the first tab of each space is the one shown
        w.remember_is_visible = False
    return params


def focus(label: str) -> None:
    """Bring a dockable window's tab to the front (e.g. the ray tree after a Ctrl+click)."""
    hello_imgui.get_runner_params().docking_params.focus_dockable_window(label)


def window_report() -> dict[str, dict]:
    """Each dockable window's state in the last frame: docked, drawn (shown, i.e. its tab in
    front) and size."""
    from imgui_bundle.imgui import internal
    out = {}
    for w in hello_imgui.get_runner_params().docking_params.dockable_windows:
        win = internal.find_window_by_name(w.label)
        if win is None:
            out[w.label] = {"exists": False}
            continue
        out[w.label] = {"exists": True, "docked": bool(win.dock_id), "drawn": bool(win.was_active and not win.hidden),
                        "size": [float(win.size.x), float(win.size.y)]}
    return out
