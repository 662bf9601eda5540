"""Raster figures of the reports, drawn with Pillow's default font (no font files needed):
the labelled side-by-side grid and error heat maps with a colour-scale legend.

All functions return (H, W, 3) uint8 sRGB arrays; writing them is the caller's job
(:func:`workbench.core.imageio.save_png8`).
"""
from __future__ import annotations

import textwrap

import numpy as np

from ..core.imageio import to_srgb8

PAD = 6
LINE = 14  # heat-map label line height (px)
BG = (255, 255, 255)
FG = (20, 20, 20)
MUTED = (120, 120, 120)


def font(size: int = 11):
    """Pillow's bundled default font (scalable when Pillow has FreeType, bitmap otherwise)."""
    from PIL import ImageFont
    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError):  # older Pillow or no FreeType: fixed bitmap font
        return ImageFont.load_default()


def colormap(values: np.ndarray, vmin: float, vmax: float, name: str = "magma") -> np.ndarray:
    """Map an (H, W) array to (H, W, 3) uint8 through a matplotlib colour map (clipped)."""
    import matplotlib
    span = vmax - vmin if vmax > vmin else 1.0
    x = np.clip((np.asarray(values, dtype=np.float64) - vmin) / span, 0.0, 1.0)
    rgba = matplotlib.colormaps[name](x)
    return (rgba[..., :3] * 255.0 + 0.5).astype(np.uint8)


def _text_width(draw, text: str, f) -> int:
    x0, _, x1, _ = draw.textbbox((0, 0), text, font=f)
    return x1 - x0


def _wrap(draw, text: str, f, width: int) -> list[str]:
    """Greedy wrap to a pixel width (character-based first guess, then shortened)."""
    chars = max(8, int(width / max(1, _text_width(draw, "abcdefghij", f) / 10)))
    lines = []
    for para in text.split("\n"):
        for line in textwrap.wrap(para, chars) or [""]:
            while _text_width(draw, line, f) > width and len(line) > 4:
                line = line[:-2] + "…"
            lines.append(line)
    return lines


def grid(tiles: list[dict], columns: int | None = None, notes: list[str] = ()) -> np.ndarray:
    """Side-by-side grid of labelled images.

    Parameters
    ----------
    tiles : list of ``{"title": str, "lines": [str, ...], "image": (H, W, 3) linear float}``,
        all images of the same size; title and lines are written under the image.
    columns : tiles per row (default: up to 4).
    notes : lines written under the grid (methods that do not apply or failed, with why).

    Returns
    -------
    (H, W, 3) uint8 sRGB.
    """
    from PIL import Image, ImageDraw
    h, w = tiles[0]["image"].shape[:2]
    fs = max(11, round(w / 34))
    line = fs + 4
    f, fb = font(fs), font(fs + 2)
    tw = max(w, 15 * fs)
    ncol = columns or min(4, len(tiles))
    nrow = -(-len(tiles) // ncol)
    nlines = max(len(t["lines"]) for t in tiles) + 1
    cell_h = h + PAD + line * nlines + PAD
    width = ncol * (tw + PAD) + PAD
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    note_lines = [x for n in notes for x in _wrap(probe, n, f, width - 2 * PAD)]
    canvas = Image.new("RGB", (width, nrow * (cell_h + PAD) + PAD + line * len(note_lines)), BG)
    draw = ImageDraw.Draw(canvas)
    for k, t in enumerate(tiles):
        x0 = PAD + (k % ncol) * (tw + PAD)
        y0 = PAD + (k // ncol) * (cell_h + PAD)
        canvas.paste(Image.fromarray(to_srgb8(t["image"])), (x0, y0))
        y = y0 + h + PAD // 2
        draw.text((x0, y), t["title"], fill=FG, font=fb)
        for i, text in enumerate(t["lines"]):
            draw.text((x0, y + line * (i + 1)), _wrap(draw, text, f, tw)[0], fill=FG, font=f)
    y = nrow * (cell_h + PAD)
    for i, text in enumerate(note_lines):
        draw.text((PAD, y + i * line), text, fill=MUTED, font=f)
    return np.asarray(canvas)


def heatmap(values: np.ndarray, vmin: float, vmax: float, label: str, title: str = "",
            cmap: str = "magma") -> np.ndarray:
    """An error map in false colour with a vertical colour-scale legend (5 labelled ticks).

    Parameters
    ----------
    values : (H, W) per-pixel error.
    vmin, vmax : the colour scale (values outside are clipped; shared across methods so that
        heat maps can be compared).
    label : what the scale measures (e.g. "FLIP", "|linear error|").

    Returns
    -------
    (H', W', 3) uint8: title on top, map, legend on the right.
    """
    from PIL import Image, ImageDraw
    h, w = values.shape
    f = font(11)
    bar_w, legend_w = 14, 78
    top = LINE + PAD if title else PAD
    canvas = Image.new("RGB", (w + legend_w + 2 * PAD, h + top + PAD + LINE), BG)
    canvas.paste(Image.fromarray(colormap(values, vmin, vmax, cmap)), (PAD, top))
    ramp = np.linspace(vmax, vmin, h)[:, None] * np.ones((1, bar_w))
    bx = PAD + w + PAD
    canvas.paste(Image.fromarray(colormap(ramp, vmin, vmax, cmap)), (bx, top))
    draw = ImageDraw.Draw(canvas)
    draw.rectangle([bx, top, bx + bar_w - 1, top + h - 1], outline=FG)
    for i in range(5):
        frac = i / 4
        y = top + int(round((1 - frac) * (h - 1)))
        draw.line([bx + bar_w, y, bx + bar_w + 3, y], fill=FG)
        draw.text((bx + bar_w + 5, y - 6), f"{vmin + frac * (vmax - vmin):.3g}", fill=FG, font=f)
    if title:
        draw.text((PAD, 2), title, fill=FG, font=f)
    draw.text((PAD, top + h + 2), label, fill=MUTED, font=f)
    return np.asarray(canvas)
