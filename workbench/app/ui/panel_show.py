"""The panels and the difference view shown in the window.

* :func:`show_panel` and :func:`show_difference` stand in for ``imgui.image``: the image is
  drawn into the window by a GPU pass (:class:`.screen_blits.ScreenBlits`) once the gui is
  done (:func:`draw_shown_images`), straight from the linear image while it changes, from an
  RGBA8 display texture (:func:`panel_texture`, :func:`shown_texture`) made once when it
  stays.
* The difference view's ``"abs"`` map is computed on the GPU from the panels' linear copies
  (:func:`difference_on_gpu`), its maximum and sum reduced on the GPU for the colour scale;
  during a drag nothing is read back for it: the maximum and mean printed are read one frame
  later (:func:`image_stats`, :func:`.panel_gpu.take_gpu_stats`).
"""
from __future__ import annotations

import numpy as np

from .display_passes import SCALE_FLOOR
from .panel_gpu import (display_texture, float_texture, gpu, linear_source, read_value, read_values,
                        stale, take_gpu_stats, upload_linear)
from .state import AppState

def panel_texture(state: AppState, method: str):
    """The RGBA8 texture showing ``method``'s panel through its display mode; rebuilt only
    when the image or the mode changed (another mode than direct24:
    :meth:`.display_modes.ModeDisplay.step`, cheap while the image changes)."""
    mode = state.display.get(method, "direct24")
    if mode != "direct24":
        g = gpu(state)
        g.shown.pop(method, None)
        todo = g.modes.step(method, state.images.version(method), mode,
                            lambda: state.images[method], method in state.textures)
        if todo is not None and todo[0] == "pass":
            source, flip = linear_source(state, method)
            g.modes.run(source, flip, display_texture(state, method, source.size), *todo[1:])
        elif todo is not None:
            upload_linear(state, method, todo[1])
        return state.textures[method]
    gpu(state).modes.forget(method)
    key = (state.images.version(method), mode)
    if stale(state, method, key) or method not in state.textures:
        source, flip = linear_source(state, method)
        gpu(state).passes.encode(source, display_texture(state, method, source.size), flip)
    return state.textures[method]


def image_stats(state: AppState, name: str) -> tuple[float, float]:
    """(maximum, mean) of ``state.images[name]``, computed once per change of the image.

    An image whose statistics were reduced on the GPU this frame (the difference view during
    a drag) gives the previous image's until the next frame
    (:func:`.panel_gpu.take_gpu_stats`): reading them now would wait for everything the frame
    has drawn so far."""
    g = gpu(state)
    key = state.images.version(name)
    queued = g.gpu_stats.get(name)
    if queued is not None and queued[0] == key:
        take_gpu_stats(state, name, now=name not in g.stats)
        held = g.stats[name]
        return held[1], held[2]
    held = g.stats.get(name)
    if held is None or held[0] != key:
        image = state.images[name]
        held = g.stats[name] = (key, float(image.max()), float(image.mean()))
    return held[1], held[2]


def difference_on_gpu(state: AppState, a: str, b: str, table: np.ndarray) -> bool:
    """The ``"abs"`` error map of panels ``a`` and ``b`` computed on the GPU from their
    linear copies, to be shown through ``table`` ((n, 3) uint8 colour scale from 0 to the
    map's maximum, uploaded once per window: :func:`show_difference`), with nothing read back:
    the maximum is reduced on the GPU (:meth:`.display_passes.DisplayPasses.statistics`, with
    the sum for the mean: :func:`image_stats`) and the (H, W) float32 map becomes
    ``state.images["difference"]`` as a pending read (the probe reads one pixel of it, the
    export all).  Returns False when the two images differ in size (the caller's CPU path then
    reports it)."""
    g = gpu(state)
    (ta, fa), (tb, fb) = linear_source(state, a), linear_source(state, b)
    if ta.size != tb.size:
        return False
    held = g.uploads.get("difference values")
    if held is not None and held.size != ta.size and "difference" in state.images:
        state.images["difference"]  # a pending map of the old size: read before its texture goes
    values = float_texture(state, "difference values", ta.size, 1)
    g.passes.difference((ta, fa), (tb, fb), values)
    stats = g.passes.statistics(values)
    if "colour table" not in g.uploads:
        g.uploads["colour table"] = state.ctx.texture((len(table), 1), 3,
                                                      np.ascontiguousarray(table, np.uint8).tobytes(),
                                                      alignment=1)
    w, h = ta.size
    state.images.set_pending("difference", lambda: read_values(values),
                             pixel=lambda i, j, shape: read_value(values, i, j, shape),
                             shape=(h, w))
    version = state.images.version("difference")
    g.gpu_stats["difference"] = (version, stats, state.frame, w * h)
    g.difference_inputs = (version, values, g.uploads["colour table"], stats)
    return True


def changing(state: AppState, name: str) -> bool:
    """``state.images[name]`` is not the image shown last frame (a drag redraws it every
    frame); records the version shown."""
    g = gpu(state)
    version = state.images.version(name)
    changed = g.shown_versions.get(name) != version
    g.shown_versions[name] = version
    return changed


def show_panel(state: AppState, method: str, size, uv0=(0.0, 0.0), uv1=(1.0, 1.0)) -> None:
    """``imgui.image`` of ``method``'s panel, drawn into the window by a GPU pass instead
    (:class:`.screen_blits.ScreenBlits`; :func:`draw_shown_images` draws once the gui is
    done).  A direct24 panel whose image changed since last frame is sRGB-encoded straight into the window from
    its linear image (no display texture made: one pass where encoding into the texture and
    copying it were two); an image that stays is encoded once into its display texture
    (:func:`panel_texture`), which is then copied (cheaper than encoding every frame), as is
    the display texture of any other mode."""
    g = gpu(state)
    mode = state.display.get(method, "direct24")
    image = None
    if changing(state, method):
        source, flip = linear_source(state, method)
        if mode == "direct24":
            g.modes.forget(method)
            image = g.blits.linear(source, flip)
        else:
            todo = g.modes.step(method, state.images.version(method), mode,
                                lambda: state.images[method], method in state.textures)
            if todo is not None and todo[0] == "pass":
                # the mode's GPU view drawn into the window; its display texture is made once
                # the image stays (the next frame that shows the same image)
                g.modes.shown.pop(method, None)
                image = g.blits.drawn(lambda src, dst: g.modes.to_window(source, flip, *todo[1:], src, dst),
                                      source.size)
            elif todo is not None:
                upload_linear(state, method, todo[1])
    if image is None:
        image = g.blits.copied(panel_texture(state, method))
    g.blits.show(method, image, size, uv0, uv1)


def show_difference(state: AppState, size, uv0=(0.0, 0.0), uv1=(1.0, 1.0)) -> None:
    """``imgui.image`` of the difference view, drawn as :func:`show_panel` draws panels: the
    ``"abs"`` map computed on the GPU colour-mapped straight into the window while it changes
    every frame, else (and for a map computed on the CPU: FLIP) its display texture copied."""
    g = gpu(state)
    held = g.difference_inputs
    if (changing(state, "difference") and held is not None
            and held[0] == state.images.version("difference")):
        values, table, stats = held[1:]
        inputs = {"u_value": values, "u_table": table, "u_stats": stats}
        image = g.blits.drawn(lambda src, dst: g.passes.to_window(
            "colour_map", inputs, src, dst, u_floor=SCALE_FLOOR), values.size)
    else:
        image = g.blits.copied(shown_texture(state, "difference"))
    g.blits.show("difference", image, size, uv0, uv1)


def shown_texture(state: AppState, name: str):
    """The display texture (RGBA8 or RGB8, row 0 on top) of what panel or view ``name``
    (``"difference"``) shows, made if the window draws it without one (scripts and tests
    read it; the window itself does not need it)."""
    g = gpu(state)
    held = g.difference_inputs
    if name != "difference":
        return panel_texture(state, name)
    if held is not None and held[0] == state.images.version("difference"):
        values, table, stats = held[1:]
        if stale(state, "difference texture", held[0]) or "difference" not in state.textures:
            g.passes.colour_map(values, table, stats,
                                display_texture(state, "difference", values.size))
    return state.textures["difference"]


def draw_shown_images(state: AppState) -> None:
    """Draw this frame's panel images into the window (call before imgui renders)."""
    if state.gpu is not None:
        state.gpu.blits.flush()
