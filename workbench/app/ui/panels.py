"""GUI functions: each takes the :class:`~.state.AppState` and draws one part of the window."""
from __future__ import annotations

import numpy as np
from imgui_bundle import imgui

from . import camera as cam
from .colours import colour_scale, hot_table
from .display_passes import SCALE_FLOOR
from .drag_resolution import render_camera, set_adaptive
from .export import export
from .gl_sessions import KNOB_VALUES, STANDIN_CHOICES, draws_standins
from .inspect import pixel_under_mouse, probe_tooltip, select_ray_tree
from .panel_gpu import gpu, stale, upload, upload_linear
from .panel_refresh import mismatch
from .panel_show import difference_on_gpu, image_stats, show_difference, show_panel
from .patch_view import select_patch
from .section import section
from .placement import PANEL_GAP, PANEL_LINES, focus, panel_grid
from .state import (DISPLAY_MODES, HARMONIES, MATERIAL_FIELDS, AppState, choosable_methods,
                    set_display, set_material_value, set_option, set_scene, short_name,
                    toggle_method)

ORBIT_SPEED = 0.01
"""Radians of orbit per pixel of mouse drag."""
ZOOM_STEP = 0.9
"""Distance factor per notch of the mouse wheel."""
MATERIAL_RANGES = {"ka": (0.0, 1.0), "kd": (0.0, 1.0), "ks": (0.0, 1.0),
                   "shininess": (1.0, 500.0), "kr": (0.0, 1.0), "kt": (0.0, 1.0),
                   "ior": (1.0, 2.5)}
def right_edge() -> float:
    """The right edge of the current window's content (screen pixels): less its padding and,
    when shown, its vertical scrollbar (which covers what lies under it: at 1024x600 the Scene
    window's "reset zoom" ran under it unnoticed)."""
    from imgui_bundle.imgui import internal
    scrollbar = internal.get_current_window().scrollbar_sizes.x
    return (imgui.get_window_pos().x + imgui.get_window_width()
            - imgui.get_style().window_padding.x - scrollbar)


def check_fits(state: AppState, name: str) -> None:
    """Note in ``state.cut`` whether the last item (its frame and label) ends past the right
    edge of its window's content (:func:`right_edge`): nothing should (scripts and tests read it)."""
    right = right_edge()
    if imgui.get_item_rect_max().x > right + 1.0:
        state.cut.add(name)
    else:
        state.cut.discard(name)


def same_line_if_fits(width: float) -> None:
    """Continue the line if an item ``width`` pixels wide still fits in the window, else
    start a new line (buttons that wrap instead of running past the edge)."""
    spacing = imgui.get_style().item_spacing.x
    if imgui.get_item_rect_max().x + spacing + width <= right_edge():
        imgui.same_line()


def button_width(label: str) -> float:
    return imgui.calc_text_size(label).x + 2 * imgui.get_style().frame_padding.x


def label_room(*labels: str) -> float:
    """Pixels a widget's label beside it needs (the longest of ``labels``)."""
    return max(imgui.calc_text_size(x).x for x in labels) + imgui.get_style().item_inner_spacing.x


def scene_picker(state: AppState) -> None:
    """Combo over the bundled scenes (a scene opened from a file is listed first), the camera
    and zoom resets, the export and the drag's adaptive resolution (:mod:`.drag_resolution`)."""
    from ...scene.library import bundled
    paths = bundled()
    if state.scene_path not in paths:
        paths = [state.scene_path, *paths]
    names = [p.stem if p.parent == paths[-1].parent else p.name for p in paths]
    imgui.set_next_item_width(-label_room("scene"))
    changed, idx = imgui.combo("scene", paths.index(state.scene_path), names)
    check_fits(state, "scene")
    if changed and paths[idx] != state.scene_path:
        set_scene(state, str(paths[idx]))
    if imgui.button("reset camera"):
        state.camera = cam.reset(state.scene, state.camera)
    same_line_if_fits(button_width("reset zoom"))
    if imgui.button("reset zoom"):
        state.view = (1.0, 0.5, 0.5)
    same_line_if_fits(button_width("export"))
    clicked = imgui.button("export")
    check_fits(state, "export")
    changed, on = imgui.checkbox("drag at 30 fps", state.drag.enabled)
    if imgui.is_item_hovered():
        imgui.set_tooltip("While the camera moves, the GL panels render at the largest resolution\n"
                          "that holds 30 frames per second, at full resolution once it rests\n"
                          "(workbench ui --drag-resolution adaptive|full)")
    check_fits(state, "drag at 30 fps")
    if changed:
        set_adaptive(state, on)
    if clicked:
        folder = (state.export_dir / f"{state.scene_path.stem}_{state.frame:06d}").resolve()
        export(state, folder)  # its message (the folder, panels skipped) in status["export"]
    if "export" in state.status:
        imgui.push_text_wrap_pos(0.0)
        imgui.text_disabled(state.status["export"])
        imgui.pop_text_wrap_pos()


def method_list(state: AppState) -> None:
    """Checkboxes over the methods (1 to 6 selected), in as many columns as their labels
    fit (two at most); a refused change says why."""
    methods = [*choosable_methods(), *state.user_methods]
    style = imgui.get_style()
    column = imgui.get_frame_height() + label_room(*map(short_name, methods)) + style.item_spacing.x
    cols = 2 if 2 * column <= imgui.get_content_region_avail().x else 1
    x0 = imgui.get_cursor_pos_x()
    for k, m in enumerate(methods):
        if k % cols:
            imgui.same_line(x0 + column)
        changed, on = imgui.checkbox(f"{short_name(m)}##{m}", m in state.methods)
        if short_name(m) != m and imgui.is_item_hovered():
            imgui.set_tooltip(m)
        check_fits(state, f"method {m}")
        if changed:
            toggle_method(state, m, on)
    if "methods" in state.status:
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(imgui.ImVec4(1.0, 0.6, 0.3, 1.0), state.status["methods"])
        imgui.pop_text_wrap_pos()


def parameters(state: AppState) -> None:
    """Sliders: the chosen material's coefficients and each selected method's quality knob."""
    from ...renderers.base import get_renderer
    section(state, "material")
    names = list(state.scene.materials)
    imgui.push_item_width(-label_room("material", *MATERIAL_FIELDS))  # labels fit beside
    changed, idx = imgui.combo("material", names.index(state.material), names)
    check_fits(state, "material")
    if changed:
        state.material = names[idx]
    mat = state.scene.materials[state.material]
    for f in MATERIAL_FIELDS:
        lo, hi = MATERIAL_RANGES[f]
        changed, v = imgui.slider_float(f, float(getattr(mat, f)), lo, hi)
        check_fits(state, f)
        if changed:
            set_material_value(state, state.material, f, v)
    imgui.pop_item_width()
    section(state, "quality")
    for m in state.methods:
        knob = get_renderer(m).knob
        values = list(knob.values)
        cur = state.options[m][knob.name]
        idx = values.index(cur) if cur in values else 0
        imgui.push_text_wrap_pos(0.0)  # its own line(s): a label beside the slider was cut
        imgui.text(f"{short_name(m)}: {knob.name}")
        imgui.pop_text_wrap_pos()
        imgui.set_next_item_width(-1)
        changed, idx = imgui.slider_int(f"##knob {m}", idx, 0, len(values) - 1,
                                        format=str(values[idx]))
        check_fits(state, f"knob {m}")
        if changed:
            set_option(state, m, knob.name, values[idx])
        if draws_standins(m):
            standin_controls(state, m)


def standin_controls(state: AppState, method: str) -> None:
    """The stand-ins of a Gouraud or Phong panel (:mod:`.gl_sessions`): the ``standins``
    option (on, off or a subset) on its own line, and its knobs (``envmap_resolution``,
    ``shadow_resolution``, ``shadow_bias``, ``envmap_iterations``) under a closed tree node; the
    CLI's option names and defaults."""
    opts = state.options[method]
    cur = str(opts["standins"])
    choices = list(STANDIN_CHOICES) if cur in STANDIN_CHOICES else [cur, *STANDIN_CHOICES]
    imgui.set_next_item_width(-label_room("standins"))
    changed, k = imgui.combo(f"standins##{method}", choices.index(cur), choices)
    check_fits(state, f"standins {method}")
    if changed:
        set_option(state, method, "standins", choices[k])
    if not imgui.tree_node(f"{method}: stand-in knobs"):
        return
    imgui.push_item_width(-label_room(*KNOB_VALUES))
    for name, values in KNOB_VALUES.items():
        values = list(values) if opts[name] in values else sorted({*values, opts[name]})
        idx = values.index(opts[name])
        changed, idx = imgui.slider_int(f"{name}##{method}", idx, 0, len(values) - 1, format=str(values[idx]))
        check_fits(state, f"{name} {method}")
        if changed:
            set_option(state, method, name, values[idx])
    imgui.pop_item_width()
    imgui.tree_pop()


def handle_mouse(state: AppState) -> None:
    """Mouse over the last drawn image panel: left drag orbits, right drag pans, wheel zooms
    (every panel shares ``state.camera``); with Shift, the wheel and left drag zoom and pan the
    linked 2D view of all panels instead."""
    if not imgui.is_item_hovered():
        return
    io = imgui.get_io()
    dx, dy = io.mouse_delta.x, io.mouse_delta.y
    size = imgui.get_item_rect_size()  # the image as shown (scaled from the camera's pixels)
    if io.key_ctrl:  # Ctrl+click selects a pixel, no camera move
        return
    if io.key_shift:  # Shift: linked 2D zoom (wheel) and pan (left drag) of all panels
        lo, mouse = imgui.get_item_rect_min(), imgui.get_mouse_pos()
        (u0, v0), (u1, v1) = cam.view_window(state.view)
        fx, fy = (mouse.x - lo.x) / size.x, (mouse.y - lo.y) / size.y
        if io.mouse_wheel:
            at = (u0 + fx * (u1 - u0), v0 + fy * (v1 - v0))
            state.view = cam.zoom_view(state.view, 1.25 ** io.mouse_wheel, at)
        if imgui.is_mouse_dragging(imgui.MouseButton_.left) and (dx or dy):
            state.view = cam.pan_view(state.view, dx / size.x, dy / size.y)
        return
    if imgui.is_mouse_dragging(imgui.MouseButton_.left) and (dx or dy):
        state.camera = cam.orbit(state.camera, -dx * ORBIT_SPEED, dy * ORBIT_SPEED)
    elif imgui.is_mouse_dragging(imgui.MouseButton_.right) and (dx or dy):
        state.camera = cam.pan(state.camera, -dx / size.y, dy / size.y)
    if io.mouse_wheel:
        state.camera = cam.zoom(state.camera, ZOOM_STEP ** io.mouse_wheel)


def fit_text(text: str, width: float) -> str:
    """``text`` cut to ``width`` pixels of the current font (an ellipsis marks the cut)."""
    if imgui.calc_text_size(text).x <= width:
        return text
    lo, hi = 0, len(text)
    while lo < hi:  # the longest prefix that fits with its ellipsis
        mid = (lo + hi + 1) // 2
        if imgui.calc_text_size(text[:mid] + "...").x <= width:
            lo = mid
        else:
            hi = mid - 1
    return text[:lo] + "..."


def text_in_width(text: str, width: float, disabled: bool = False) -> None:
    """One line of ``text`` cut to ``width`` pixels; the whole text as a tooltip when cut."""
    shown = fit_text(text, width)
    (imgui.text_disabled if disabled else imgui.text)(shown)
    if shown != text and imgui.is_item_hovered():
        imgui.set_tooltip(text)


def progress_line(meter, text: str, width: float) -> None:
    """A job's progress bar ``width`` pixels wide (indeterminate while its phase is not
    measured, :meth:`.meter.Meter.bar`) with ``text`` over it, cut to the bar (the whole text
    as a tooltip when cut)."""
    pad = 2 * imgui.get_style().frame_padding.x
    shown = fit_text(text, max(1.0, width - pad))
    imgui.progress_bar(meter.bar(imgui.get_time()), imgui.ImVec2(width, 0), shown)
    if shown != text and imgui.is_item_hovered():
        imgui.set_tooltip(text)


def image_panels(state: AppState) -> None:
    """One image per selected method at the scene camera's aspect, as large as the window
    allows, in as many rows as fit best (:func:`~.placement.panel_grid`); each image is shown
    scaled from the panels' render resolution."""
    avail = imgui.get_content_region_avail()
    chrome = PANEL_LINES * imgui.get_frame_height_with_spacing()
    cols, w, h = panel_grid(len(state.methods), avail.x, avail.y,
                            state.camera.width / state.camera.height, chrome)
    for k, m in enumerate(state.methods):
        if k % cols:
            imgui.same_line(0, PANEL_GAP)
        imgui.begin_group()
        t = state.timings.get(m)
        imgui.align_text_to_frame_padding()  # every panel's title on the same baseline
        text_in_width(f"{short_name(m)}  {'' if t is None else f'{t * 1e3:.1f} ms'}", w)
        if m in state.images:
            show_panel(state, m, imgui.ImVec2(w, h), *cam.view_window(state.view))
            handle_mouse(state)
            ij = pixel_under_mouse(state)
            if ij is not None:
                probe_tooltip(state, ij)
                if (m == "raytrace" and imgui.get_io().key_ctrl
                        and imgui.is_mouse_clicked(imgui.MouseButton_.left)):
                    select_ray_tree(state, *ij)
                    focus("Ray tree")
                if (m == "radiosity" and imgui.get_io().key_ctrl
                        and imgui.is_mouse_clicked(imgui.MouseButton_.left)):
                    select_patch(state, *ij)
                    focus("Patch view")
        else:
            imgui.dummy(imgui.ImVec2(w, h))
        from .panel_refresh import running_meter
        job = state.jobs.current.get(m)
        meter = None if job is None else running_meter(job)
        if meter is not None:  # done/target and time left, or a phase's time elapsed
            progress_line(meter, state.status.get(m, ""), w)
        else:
            text_in_width(state.status.get(m, ""), w, disabled=True)
        mode = state.display.get(m, "direct24")
        modes = list(DISPLAY_MODES) if mode in DISPLAY_MODES else [mode, *DISPLAY_MODES]
        imgui.set_next_item_width(w)
        changed, k_mode = imgui.combo(f"##display {m}", modes.index(mode), modes)
        check_fits(state, f"display {m}")
        if changed:
            set_display(state, m, modes[k_mode])
        imgui.end_group()


def difference_panel(state: AppState) -> None:
    """Error map between two chosen methods with its colour scale.  While the two images are
    not of the same camera and scene (:func:`.panel_refresh.mismatch`: a drag moves a GL panel
    while a ray-traced one re-renders) the view pauses on the last map of two matching images
    and says so (``state.status["difference"]``; issue #29, item 7)."""
    from ...compare.metrics import error_map
    section(state, "difference")
    ms = state.methods
    a, b = (x if x in ms else ms[0] for x in state.diff_pair)
    kinds = ["abs", "flip"]
    # the two selectors share the window's width, the kind on its own line: nothing is cut
    # off in a narrow window (at 1280 wide, B and the kind were past the right edge)
    style = imgui.get_style()
    label = imgui.calc_text_size("A").x + style.item_inner_spacing.x
    half = max(40.0, (imgui.get_content_region_avail().x - style.item_spacing.x) / 2 - label)
    imgui.set_next_item_width(half)
    _, ia = imgui.combo("A", ms.index(a), ms)
    check_fits(state, "difference A")
    imgui.same_line()
    imgui.set_next_item_width(half)
    _, ib = imgui.combo("B", ms.index(b), ms)
    check_fits(state, "difference B")
    imgui.set_next_item_width(max(40.0, min(120.0, half)))
    _, ik = imgui.combo("kind", kinds.index(state.diff_kind), kinds)
    check_fits(state, "difference kind")
    state.diff_pair, state.diff_kind = (ms[ia], ms[ib]), kinds[ik]
    a, b = state.diff_pair
    if a not in state.images or b not in state.images:
        return
    # the panels' size, or the GL panels' smaller one during a drag (:mod:`.drag_resolution`)
    shapes = {(c.height, c.width) for c in (state.camera, render_camera(state.drag, state.camera))}
    if not all(any(state.images.has_shape(m, s) for s in shapes) for m in (a, b)):
        imgui.text_disabled("waiting for both images at the panels' size")
        return  # one is still the previous scene's (another size): nothing to compare yet
    why = mismatch(state, a, b)
    if why:  # a drag: the map of two images from one camera (the last) stays, flagged
        state.status["difference"] = (f"paused: {why}; the map shown is the last one of two "
                                      "images of the same camera and scene")
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(imgui.ImVec4(1.0, 0.6, 0.3, 1.0), state.status["difference"])
        imgui.pop_text_wrap_pos()
        last = gpu(state).shown.get("difference")
        if last is None or last[:3] != (a, b, state.diff_kind) or "difference" not in state.images:
            return
    else:
        state.status.pop("difference", None)
    # recomputed only when either image or the kind changed (a static frame reads no pixels)
    key = (a, b, state.diff_kind, state.images.version(a), state.images.version(b))
    if not why and (stale(state, "difference", key) or "difference" not in state.images):
        if not (state.diff_kind == "abs" and difference_on_gpu(state, a, b, hot_table())):
            # FLIP (or images of different sizes: error_map says so)
            err = error_map(state.images[a], state.images[b], state.diff_kind)
            upload(state, "difference", colour_scale(err, max(float(err.max()), SCALE_FLOOR)))
            state.images["difference"] = err
    vmax, mean = image_stats(state, "difference")
    vmax = max(vmax, SCALE_FLOOR)
    # the window's width at the camera's aspect, leaving room for the scale's two lines
    avail = imgui.get_content_region_avail()
    room_h = avail.y - 2 * imgui.get_frame_height_with_spacing()
    aspect = state.camera.width / state.camera.height
    w = max(32.0, min(avail.x, room_h * aspect))
    size = imgui.ImVec2(w, w / aspect)
    show_difference(state, size, *cam.view_window(state.view))
    if "colour_scale" not in state.textures:
        upload(state, "colour_scale",
               colour_scale(np.tile(np.linspace(0, 1, 128, dtype=np.float32), (8, 1)), 1.0))
    tb = state.textures["colour_scale"]
    imgui.text("0")
    imgui.same_line()
    imgui.image(imgui.ImTextureRef(tb.glo), imgui.ImVec2(max(10.0, size.x - 60), 10))
    imgui.same_line()
    imgui.text(f"{vmax:.3g}")
    imgui.text(f"mean {mean:.4f}")


def colour_wheel(state: AppState) -> None:
    """The chromatic circle with the course's harmonies for a chosen base hue (HSV)."""
    from ...core.harmony import wheel_image
    section(state, "colour wheel")
    hue, kind = state.wheel
    _, hue = imgui.slider_float("base hue", hue, 0.0, 360.0)
    _, k = imgui.combo("harmony", HARMONIES.index(kind), list(HARMONIES))
    key = f"wheel {hue:.1f} {HARMONIES[k]}"
    if state.wheel != (hue, HARMONIES[k]) or key not in state.textures:
        for old in [t for t in state.textures if t.startswith("wheel ")]:
            state.textures.pop(old).release()
        state.wheel = (hue, HARMONIES[k])
        upload_linear(state, key, wheel_image(hue, HARMONIES[k], size=200))
    imgui.image(imgui.ImTextureRef(state.textures[key].glo), imgui.ImVec2(200, 200))


def status_text(state: AppState) -> str:
    """GL_RENDERER, frame time (and rate), the GL panels' scale while a drag lowers it
    (:mod:`.drag_resolution`) and each shown method's last run time."""
    parts = [f"{m} {state.timings[m] * 1e3:.0f} ms" for m in state.methods if m in state.timings]
    fps = 1.0 / state.frame_seconds if state.frame_seconds > 0 else 0.0
    scale = [f"GL panels at {state.drag.scale * 100:.0f} %"] if state.drag.scale < 1.0 else []
    return " | ".join([state.gl_renderer, f"frame {state.frame_seconds * 1e3:.1f} ms "
                       f"({fps:.0f} fps)", *scale, *parts])


def status_bar(state: AppState) -> None:
    """The status bar line (:func:`status_text`), cut to the window's width (whole in a
    tooltip)."""
    text_in_width(status_text(state), imgui.get_content_region_avail().x)
