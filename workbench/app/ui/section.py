"""A section title that is never cut (issue #29, item 6: no cut-off text at 1024x600)."""
from __future__ import annotations

from .state import AppState


def section(state: AppState, title: str) -> None:
    """``imgui.separator_text(title)`` where the title fits the window's width; else the title
    wrapped on its own lines over a plain separator (imgui's separator text ends a title too
    long with "..."), noted in ``state.wrapped`` (scripts and tests read it)."""
    from imgui_bundle import imgui
    style = imgui.get_style()
    need = (imgui.calc_text_size(title).x + 2 * style.separator_text_padding.x
            + 2 * style.separator_text_border_size)
    if need <= imgui.get_content_region_avail().x:
        imgui.separator_text(title)
        state.wrapped.discard(title)
        return
    imgui.push_text_wrap_pos(0.0)
    imgui.text(title)
    imgui.pop_text_wrap_pos()
    imgui.separator()
    state.wrapped.add(title)
