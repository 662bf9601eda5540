"""Numba's on-disk cache, kept in a folder named by the code it was compiled from.

Numba checks a cached function against its own source file's time stamp only ("Notes on
caching" in the Numba documentation: changes to functions in other files that it calls are
not detected).  The ray tracer's dispatch compiles every kind's kernels into its own cached
functions, so after an edit of, say, ``scene/kinds/lathe_kernels.py`` (a ``git checkout``, a
merge) the unchanged ``renderers/raytrace/kernels.py`` would load its stale machine code and
draw the old shape.  :func:`use_code_keyed_cache` points ``NUMBA_CACHE_DIR`` at
``BASE/<code fingerprint>``, so any change to the layers a kernel may import (core, scene,
renderers) compiles afresh; the few most recently used older folders are kept, the rest
removed.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import sys
from pathlib import Path

CODE_PACKAGES = ("core", "scene", "renderers")
"""The layers whose sources numba kernels may read (imports run core -> scene -> renderers)."""
KEEP = 3
"""Cache folders of other code versions kept beside the current one (most recently used)."""
DIGITS = 16
"""Hex digits of the fingerprint in a folder name."""


def code_fingerprint() -> str:
    """SHA-256 (hex) over the workbench's core, scene and renderer sources, sorted by path."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for pkg in CODE_PACKAGES:
        for p in sorted((root / pkg).rglob("*.py")):
            h.update(str(p.relative_to(root)).encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def default_base() -> Path:
    """``$XDG_CACHE_HOME/workbench/numba`` (``~/.cache`` when unset): used when the
    environment names no ``NUMBA_CACHE_DIR``."""
    home = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(home) / "workbench" / "numba"


def _prune(base: Path, current: Path) -> None:
    """Remove fingerprint folders of ``base`` beyond the :data:`KEEP` most recently used."""
    try:
        others = [p for p in base.iterdir() if p.is_dir() and p != current
                  and len(p.name) == DIGITS and all(c in "0123456789abcdef" for c in p.name)]
    except OSError:
        return
    others.sort(key=lambda p: p.stat().st_mtime, reverse=True)
    for p in others[KEEP:]:
        shutil.rmtree(p, ignore_errors=True)


def use_code_keyed_cache() -> Path:
    """Set ``NUMBA_CACHE_DIR`` to ``BASE/<fingerprint>`` (``BASE``: the variable's value, or
    :func:`default_base`) and return it; a value that already ends in this fingerprint (a
    child process) is kept.  Numba imported before this call re-reads its configuration."""
    fp = code_fingerprint()[:DIGITS]
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given and Path(given).name == fp:
        return Path(given)
    base = Path(given) if given else default_base()
    current = base / fp
    try:
        current.mkdir(parents=True, exist_ok=True)
        os.utime(current)
    except OSError:
        return current  # numba falls back to its own locations when it cannot write here
    _prune(base, current)
    os.environ["NUMBA_CACHE_DIR"] = str(current)
    config = sys.modules.get("numba.core.config")
    if config is not None:
        config.reload_config()
    return current
