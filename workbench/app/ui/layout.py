"""The docking layout (hello_imgui ``DockingParams``): where each window of the UI starts.

::

    +---------------------------------------------------------------------+
    |  Panels (MainDockSpace): the image panels in one row, full width     |
    |                                                                     |
    +----------+---------+------------+--------------+--------------------+
    | Scene    | Methods | Parameters | Difference   | Error plot         |
    |          |         | Lights     |              | Ray tree           |
    |          |         | Colour     |              | Patch view         |
    +----------+---------+------------+--------------+--------------------+
    | status bar: GL_RENDERER | frame time | per-method timings            |

The controls sit in a row under the panels rather than in a column beside them, so the panels
get the window's full width: three 512 px panels side by side fit a 1600 px wide window (a
column beside them needed 2200 px, wider than a 1920 px screen, and every window pixel costs
frame time on a software GL).  The row's height is set at start from the window and panel
heights (:func:`splits`) so that one row of panels fits above it, and set again whenever
either changes (:func:`refit`: the window resized at run time, a scene of another aspect).
Windows in one dock space
are tabs; every window can be dragged elsewhere, split or floated.  Each window's content is a
gui function taking the :class:`~.state.AppState`.
"""
from __future__ import annotations

from imgui_bundle import hello_imgui, imgui

from .state import AppState
from .window_style import with_background

PANEL_CHROME = 110
"""Pixels of the panels window's height besides one row of images: its tab bar, each panel's
title line, status line and display-mode combo, and padding."""
STATUS_BAR = 30
"""Pixels of the window's height taken by the status bar."""


CONTROL_ROW = (0.2, 0.65)
"""The least and largest share of the dock space's height the control row takes."""


def control_row(dock_height: float, panel_height: int) -> float:
    """The control row's share of a dock space ``dock_height`` pixels high: what one row of
    panels ``panel_height`` pixels high (and their :data:`PANEL_CHROME`) leaves, within
    :data:`CONTROL_ROW`."""
    lo, hi = CONTROL_ROW
    return min(hi, max(lo, 1.0 - (panel_height + PANEL_CHROME) / max(1.0, dock_height)))


def splits(window_height: int, panel_height: int) -> list[tuple[str, str, object, float]]:
    """(dock space split, new dock space, side, fraction of the split one) in order: the
    control row takes what one row of panels leaves of the window's height
    (:func:`control_row`), then is split into five columns."""
    row = control_row(window_height - STATUS_BAR, panel_height)
    return [("MainDockSpace", "ControlSpace", imgui.Dir.down, row),
            ("ControlSpace", "ToolSpace", imgui.Dir.right, 0.45),
            ("ToolSpace", "DiffSpace", imgui.Dir.left, 0.45),
            ("ControlSpace", "ParamSpace", imgui.Dir.right, 0.4),
            ("ControlSpace", "MethodSpace", imgui.Dir.right, 0.45)]


def windows(state: AppState) -> list[tuple[str, str, object]]:
    """(label, dock space, gui function of no argument) of every dockable window."""
    from .file_browser import file_browser, shading_picker
    from .inspect import ray_tree_view
    from .lights import light_controls
    from .panels import (colour_wheel, difference_panel, image_panels, method_list, parameters,
                         scene_picker)
    from .patch_view import patch_view
    from .plot import error_plot
    return [("Scene", "ControlSpace", lambda: (scene_picker(state), file_browser(state))),
            ("Methods", "MethodSpace", lambda: (method_list(state), shading_picker(state))),
            ("Parameters", "ParamSpace", lambda: parameters(state)),
            ("Lights", "ParamSpace", lambda: light_controls(state)),
            ("Colour wheel", "ParamSpace", lambda: colour_wheel(state)),
            ("Panels", "MainDockSpace", lambda: image_panels(state)),
            ("Difference", "DiffSpace", lambda: difference_panel(state)),
            ("Error plot", "ToolSpace", lambda: error_plot(state)),
            ("Ray tree", "ToolSpace", lambda: ray_tree_view(state)),
            ("Patch view", "ToolSpace", lambda: patch_view(state))]


def docking_params(state: AppState, window_height: int) -> hello_imgui.DockingParams:
    """The splits (:func:`splits` for a window of ``window_height`` pixels) and dockable
    windows, applied at every start (no settings file is kept)."""
    params = hello_imgui.DockingParams()
    params.docking_splits = [hello_imgui.DockingSplit(a, b, d, r)
                             for a, b, d, r in splits(window_height, state.camera.height)]
    params.dockable_windows = [hello_imgui.DockableWindow(label, space, with_background(fn),
                                                          can_be_closed_=False)
                               for label, space, fn in windows(state)]
    params.layout_condition = hello_imgui.DockingLayoutCondition.application_start
    for w in params.dockable_windows:  # the first tab of each space is the one shown
        w.remember_is_visible = False
    return params


def refit(state: AppState) -> None:
    """Size the control row again (:func:`control_row`) when the main dock space's height or
    the panels' height changed since the last fit (``state.layout_fit``): a window resized at
    run time, a scene whose camera has another aspect (issue #29, item 6).  ImGui's docking
    keeps the row's height in pixels through a resize (1024x600 after 1280x720 left the panels
    32 px high) and the split was only made at start (a square scene after a 4:3 one was shown
    shrunk).  A splitter the user dragged stays until the next change; a layout rearranged so
    that the panels no longer sit above the control row is left alone.  Called once per frame;
    the new height shows from the next frame."""
    from imgui_bundle.imgui import internal
    docking = hello_imgui.get_runner_params().docking_params
    root_id = docking.dock_space_id_from_name("MainDockSpace")  # the whole dock space
    root = None if root_id is None else internal.dock_builder_get_node(root_id)
    if root is None or root.size.y <= 0:
        return
    key = (root.size.y, state.camera.height)
    if key == state.layout_fit:
        return
    row_id = docking.dock_space_id_from_name("ControlSpace")
    row = None if row_id is None else internal.dock_builder_get_node(row_id)
    while row is not None and row.parent_node is not None and row.parent_node.id_ != root_id:
        row = row.parent_node  # up to the control row, a child of the dock space
    if row is None or row.parent_node is None or row.is_central_node() or root.split_axis != internal.Axis.y:
        return
    height = round(control_row(root.size.y, state.camera.height) * root.size.y)
    internal.dock_builder_set_node_size(row.id_, imgui.ImVec2(root.size.x, height))
    state.layout_fit = key


def window_report() -> dict[str, dict]:
    """Each dockable window's state in the last frame: docked, drawn (shown, i.e. its tab in
    front), size and position (window pixels), and the width of its content against the room
    for it (``content_width``, ``room_width``: a window has no horizontal scrollbar, so content
    wider than its room is cut at the right edge)."""
    from imgui_bundle.imgui import internal
    out = {}
    for w in hello_imgui.get_runner_params().docking_params.dockable_windows:
        win = internal.find_window_by_name(w.label)
        if win is None:
            out[w.label] = {"exists": False}
            continue
        out[w.label] = {"exists": True, "docked": bool(win.dock_id), "drawn": bool(win.was_active and not win.hidden),
                        "size": [float(win.size.x), float(win.size.y)],
                        "pos": [float(win.pos.x), float(win.pos.y)],
                        "content_width": float(win.content_size.x),
                        "room_width": float(win.content_region_rect.get_width())}
    return out
