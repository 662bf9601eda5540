"""Window backgrounds painted once per frame instead of once per window (software GL).

With hello_imgui's full-window dock space every docked window paints its background
(``ImGuiCol_WindowBg``) over the dock space's own: about three full-window layers of fill per
frame (2.9 Mpx for a 1280 x 760 window, summed from imgui's draw data), and on llvmpipe a UI
frame costs in proportion to the pixels filled (~3x the CPU time of one layer, measured with
bench/ui_fps.py's window).  Instead the window background colour is made fully transparent
(imgui skips such fills) and the framebuffer is cleared to that colour, which gives the same
picture for one clear.  A window dragged out of the dock gets an opaque background back from
:func:`opaque_if_floating`, called at the start of each dockable window's gui.
"""
from __future__ import annotations

from imgui_bundle import hello_imgui, imgui


def clear_to_window_background() -> None:
    """Move the theme's window background colour to the frame's clear colour (call once the
    theme is applied, e.g. in ``post_init``)."""
    style = imgui.get_style()
    bg = style.color_(imgui.Col_.window_bg)
    hello_imgui.get_runner_params().imgui_window_params.background_color = imgui.ImVec4(bg.x, bg.y, bg.z, 1.0)
    style.set_color_(imgui.Col_.window_bg, imgui.ImVec4(bg.x, bg.y, bg.z, 0.0))


def opaque_if_floating() -> None:
    """Paint the current window's background if it is not docked (a floating window would
    otherwise show what is behind it)."""
    if imgui.is_window_docked():
        return
    bg = hello_imgui.get_runner_params().imgui_window_params.background_color
    pos, size = imgui.get_window_pos(), imgui.get_window_size()
    top = pos.y + imgui.get_frame_height()  # below the title bar
    imgui.get_window_draw_list().add_rect_filled(
        imgui.ImVec2(pos.x, top), imgui.ImVec2(pos.x + size.x, pos.y + size.y),
        imgui.color_convert_float4_to_u32(bg))


def with_background(gui):
    """``gui`` preceded by :func:`opaque_if_floating` (a dockable window's gui function)."""
    def wrapped():
        opaque_if_floating()
        gui()
    return wrapped
