"""The window's size remembered between runs (issue #29, item 6): ``workbench ui`` without
``--window`` opens at the size the window had when it was last closed, kept in
``window.json`` under ``$WORKBENCH_CONFIG_DIR``, else ``$XDG_CONFIG_HOME/workbench``, else
``~/.config/workbench``.  A file that cannot be read or written costs one line on stderr and
the default size, never the window."""
from __future__ import annotations

import json
import os
from pathlib import Path

MIN_SIZE = (320, 240)
"""The smallest window ``--window`` accepts and a remembered size may have (pixels)."""


def settings_path() -> Path:
    """Where the last size is kept."""
    base = os.environ.get("WORKBENCH_CONFIG_DIR")
    if not base:
        base = Path(os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config") / "workbench"
    return Path(base) / "window.json"


def valid(size) -> bool:
    """``size`` is (width, height) integers from :data:`MIN_SIZE` to 16384."""
    return (isinstance(size, (list, tuple)) and len(size) == 2
            and all(isinstance(v, int) and lo <= v <= 16384 for v, lo in zip(size, MIN_SIZE)))


def remembered() -> tuple[tuple[int, int] | None, str]:
    """(the last size, or None when none is kept; a one-line note when the file is there but
    unusable, else "")."""
    path = settings_path()
    if not path.is_file():
        return None, ""
    try:
        size = json.loads(path.read_text(encoding="utf-8")).get("size")
    except (OSError, ValueError, AttributeError) as e:
        return None, f"workbench ui: {path}: not read ({type(e).__name__}); the default size is used"
    if not valid(size):
        return None, f"workbench ui: {path}: 'size' is not [width, height] pixels; the default size is used"
    return (size[0], size[1]), ""


def remember(size: tuple[int, int]) -> str:
    """Keep ``size`` for the next run; returns "" or a one-line note of why it was not kept."""
    if not valid(list(size)):
        return ""  # a minimised window (0 x 0) is not a size to come back to
    path = settings_path()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"size": list(size)}) + "\n", encoding="utf-8")
    except OSError as e:
        return f"workbench ui: the window's size was not kept in {path} ({e.strerror})"
    return ""
