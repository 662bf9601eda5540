"""Where panels go in their window (:func:`panel_grid`) and bringing a docked window to the
front (:func:`focus`): used by the views, below the docking layout (:mod:`.layout`) that
lists them."""
from __future__ import annotations

from imgui_bundle import hello_imgui

PANEL_GAP = 8
"""Pixels between two image panels (imgui's item spacing and a margin)."""
PANEL_LINES = 3
"""Text lines of each panel besides its image: title, status, display-mode combo."""


def panel_grid(n: int, avail_w: float, avail_h: float, aspect: float,
               chrome_h: float) -> tuple[int, float, float]:
    """Lay out ``n`` panels of aspect ``aspect`` (width / height) in rows that fit a region of
    ``avail_w`` x ``avail_h`` pixels, each panel taking ``chrome_h`` pixels of text besides its
    image: (columns, image width, image height) of the largest images for which the rows fit
    both ways (never below 32 pixels wide: the window then scrolls)."""
    best = (1, 0.0)
    for cols in range(1, max(1, n) + 1):
        rows = -(-n // cols)
        w = min((avail_w - (cols - 1) * PANEL_GAP) / cols,
                ((avail_h - (rows - 1) * PANEL_GAP) / rows - chrome_h) * aspect)
        if w > best[1]:
            best = (cols, w)
    cols, w = best
    w = max(32.0, float(int(w)))
    return cols, w, float(int(w / aspect))


def focus(label: str) -> None:
    """Bring a dockable window's tab to the front (e.g. the ray tree after a Ctrl+click)."""
    hello_imgui.get_runner_params().docking_params.focus_dockable_window(label)
