"""Minimal self-contained HTML: images embedded as base64 PNG data, tables, escaped text."""
from __future__ import annotations

import base64
import html
from pathlib import Path

STYLE = """
body { font-family: sans-serif; margin: 1.5em; color: #222; max-width: 1400px; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #eee; }
td.num { text-align: right; font-family: monospace; }
.ok { color: #1a7f1a; } .bad { color: #b00020; } .warn { color: #a66300; } .muted { color: #777; }
figure { display: inline-block; margin: 0.4em; vertical-align: top; }
figcaption { font-size: 0.85em; }
img.pix { image-rendering: pixelated; }
"""


def esc(x) -> str:
    return html.escape(str(x))


def img_tag(path: str | Path, alt: str = "", css: str = "") -> str:
    """An ``<img>`` with the PNG file's bytes embedded (the page needs no other file)."""
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    cls = f' class="{css}"' if css else ""
    return f'<img{cls} alt="{esc(alt)}" src="data:image/png;base64,{data}">'


def fmt(x, digits: int = 4) -> str:
    """A number for a table cell (``inf`` and strings pass through)."""
    if isinstance(x, float):
        return f"{x:.{digits}g}"
    return str(x)


def table(header: list[str], rows: list[list], numeric: set[int] = frozenset(),
          row_class: list[str] | None = None) -> str:
    """An HTML table; cells are escaped unless wrapped as ``("raw", html)``."""
    out = ["<table><tr>" + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>"]
    for i, row in enumerate(rows):
        cls = f' class="{row_class[i]}"' if row_class and row_class[i] else ""
        cells = []
        for j, c in enumerate(row):
            text = c[1] if isinstance(c, tuple) and c[0] == "raw" else esc(fmt(c))
            cells.append(f'<td class="num">{text}</td>' if j in numeric else f"<td>{text}</td>")
        out.append(f"<tr{cls}>" + "".join(cells) + "</tr>")
    return "\n".join(out) + "</table>"


def page(title: str, body: str) -> str:
    return (f"<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>{esc(title)}</title>"
            f"<style>{STYLE}</style></head><body>\n{body}\n</body></html>\n")
