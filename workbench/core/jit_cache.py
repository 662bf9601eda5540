"""Numba's on-disk cache, kept in a folder named by the code it was compiled from.

Numba checks a cached function against its own source file's time stamp only ("Notes on
caching" in the Numba documentation: changes to functions in other files that it calls are
not detected).  The ray tracer's dispatch compiles every kind's kernels into its own cached
functions, so after an edit of, say, ``scene/kinds/lathe_kernels.py`` (a ``git checkout``, a
merge) the unchanged ``renderers/raytrace/kernels.py`` would load its stale machine code and
draw the old shape.  :func:`use_code_keyed_cache` points ``NUMBA_CACHE_DIR`` at
``BASE/<kernel fingerprint>``: a digest of the kernel sources (:func:`kernel_sources`: every
module that imports numba, and every workbench module those import, whose constants the
kernels compile in), so an edit of any of them compiles afresh while an edit elsewhere (the
window, the reports, a renderer's Python side) keeps the warm cache; the few most recently
used older folders are kept, the rest removed.

Several processes share the folder (the test suite's workers, the window's child processes, a
user's two commands), and numba's save of a new cache entry is not safe against another
process saving an entry of the same function at the same moment: each reads the function's
index, picks the first free data-file number, writes the index and then the data, so both may
pick the same number and the index may point one signature at the other's machine code (numba
issues 4807 and 10128).  :func:`lock_cache_saves` serialises those saves with an exclusive
``flock`` on a lock file beside the function's index (loads need no lock: numba writes each
file to a temporary name and renames it, and a missing data file is a cache miss).
"""
from __future__ import annotations

import hashlib
import importlib.abc
import importlib.util
import os
import re
import shutil
import sys
from pathlib import Path

try:
    import fcntl
except ImportError:  # not POSIX: numba's saves stay as they are
    fcntl = None

CODE_PACKAGES = ("core", "scene", "renderers")
"""The layers whose sources numba kernels may read (imports run core -> scene -> renderers)."""
KEEP = 3
"""Cache folders of other code versions kept beside the current one (most recently used)."""
DIGITS = 16
"""Hex digits of the fingerprint in a folder name."""


def code_fingerprint() -> str:
    """SHA-256 (hex) over the workbench's core, scene and renderer sources, sorted by path (what
    a rendered image may depend on: the reference cache's key)."""
    root = Path(__file__).resolve().parents[1]
    modules = _module_names(root)
    layers = tuple(f"{root.name}.{pkg}" for pkg in CODE_PACKAGES)
    return _digest(root, {p: _read(p) for n, p in modules.items() if n.startswith(layers)})


_IMPORT = re.compile(rb"^[ \t]*(?:from[ \t]+(\.*)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)|import[ \t]+([\w., \t]+))",
                     re.M)
"""An import statement: ``from <dots><module> import <names>`` or ``import <modules>``."""
_NUMBA = re.compile(rb"^[ \t]*(?:import|from)[ \t]+numba\b", re.M)


def _module_names(root: Path) -> dict[str, str]:
    """Dotted name -> source file (a path string) of every module of the package
    (``workbench.core.tol``; a package by its ``__init__.py``).  Plain strings and one
    ``os.walk``: every command computes the fingerprint at start-up."""
    out = {}
    top = str(root.parent)
    for folder, dirs, files in os.walk(root):
        package = os.path.relpath(folder, top).replace(os.sep, ".")
        for f in files:
            if f.endswith(".py"):
                out[package if f == "__init__.py" else f"{package}.{f[:-3]}"] = os.path.join(folder, f)
    return out


def _read(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read()


def _imports(name: str, is_package: bool, text: bytes, modules: dict[str, str]) -> set[str]:
    """The package's modules (dotted names, keys of ``modules``) that module ``name``'s source
    ``text`` imports (absolute and relative imports, at any depth of the file)."""
    here = name.split(".") if is_package else name.split(".")[:-1]   # its package
    found = set()
    for dots, module, names, plain in _IMPORT.findall(text):
        if plain:
            targets = [n.split()[0].decode() for n in plain.split(b",") if n.split()]
        else:
            base = ".".join(here[:len(here) - len(dots) + 1]) if dots else ""
            mod = ".".join(x for x in (base, module.decode()) if x)
            words = names.strip(b"()").split(b",")
            targets = [mod] + [f"{mod}.{w.split()[0].decode()}" for w in words if w.split()]
        found.update(t for t in targets if t in modules)
    return found


def _kernel_texts() -> dict[str, bytes]:
    """Source file -> text of the modules numba kernels are compiled from (see
    :func:`kernel_sources`)."""
    root = Path(__file__).resolve().parents[1]
    modules = _module_names(root)
    layers = tuple(f"{root.name}.{pkg}" for pkg in CODE_PACKAGES)
    text = {n: _read(p) for n, p in modules.items() if n.startswith(layers)}
    todo = [n for n, t in text.items() if b"numba" in t and _NUMBA.search(t)]
    seen: dict[str, bytes] = {}
    while todo:
        n = todo.pop()
        if n not in seen:
            t = seen[n] = text[n] if n in text else _read(modules[n])
            todo.extend(_imports(n, modules[n].endswith("__init__.py"), t, modules) - seen.keys())
    return {modules[n]: t for n, t in seen.items()}


def kernel_sources() -> list[Path]:
    """The modules numba kernels are compiled from: every module of the layers kernels live in
    (:data:`CODE_PACKAGES`) that imports numba, and, transitively, every workbench module
    those import (their constants are compiled in), sorted."""
    return sorted(map(Path, _kernel_texts()))


def kernel_fingerprint() -> str:
    """SHA-256 (hex) over :func:`kernel_sources`: the numba cache folder's key."""
    return _digest(Path(__file__).resolve().parents[1], _kernel_texts())


def _digest(root: Path, texts: dict[str, bytes]) -> str:
    """SHA-256 over each file's path relative to ``root`` and its text, in the order of the
    paths' parts (as ``pathlib`` sorts them)."""
    h = hashlib.sha256()
    top = str(root)
    for p in sorted(texts, key=lambda p: os.path.relpath(p, top).split(os.sep)):
        h.update(os.path.relpath(p, top).encode())
        h.update(texts[p])
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
    used = []
    for p in others:
        try:
            used.append((p.stat().st_mtime, p))
        except OSError:  # removed meanwhile by another process pruning the same folder
            continue
    used.sort(reverse=True)
    for _, p in used[KEEP:]:
        shutil.rmtree(p, ignore_errors=True)


def use_code_keyed_cache() -> Path:
    """Set ``NUMBA_CACHE_DIR`` to ``BASE/<fingerprint>`` (:func:`kernel_fingerprint`; ``BASE``:
    the variable's value, or :func:`default_base`) and return it; a value that already ends in
    this fingerprint (a child process) is kept.  Either way the process's cache saves are locked
    (:func:`lock_cache_saves`).  Numba imported before this call re-reads its configuration."""
    fp = kernel_fingerprint()[:DIGITS]
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given and Path(given).name == fp:  # a child process: the folder is set, its saves not yet locked
        lock_cache_saves()
        return Path(given)
    base = Path(given) if given else default_base()
    current = base / fp
    try:
        current.mkdir(parents=True, exist_ok=True)
        os.utime(current)
    except OSError:
        return current  # numba falls back to its own locations when it cannot write here
    _prune(base, current)
    lock_cache_saves()
    os.environ["NUMBA_CACHE_DIR"] = str(current)
    config = sys.modules.get("numba.core.config")
    if config is not None:
        config.reload_config()
    return current


CACHING = "numba.core.caching"
"""The numba module whose ``IndexDataCacheFile.save`` :func:`lock_cache_saves` wraps."""


def lock_cache_saves() -> None:
    """Wrap numba's cache save in an exclusive ``flock`` on ``<index>.lock`` (see the module's
    docstring): now if numba's caching module is loaded, else as soon as it is (a one-shot
    import finder, so that importing workbench does not import numba)."""
    if fcntl is None:
        return
    when_caching_loads(_wrap_save)


def when_caching_loads(patch) -> None:
    """Call ``patch(module)`` with numba's caching module (:data:`CACHING`) now if it is
    loaded, else as soon as it is (a one-shot import finder, so that importing workbench does
    not import numba).  A patch given twice runs once."""
    module = sys.modules.get(CACHING)
    if module is not None:
        patch(module)
        return
    finder = next((f for f in sys.meta_path if isinstance(f, _AfterCaching)), None)
    if finder is None:
        finder = _AfterCaching()
        sys.meta_path.insert(0, finder)
    if patch not in finder.patches:
        finder.patches.append(patch)


def _wrap_save(caching) -> None:
    cls = caching.IndexDataCacheFile
    plain = cls.save
    if getattr(plain, "locked", False):
        return

    def save(self, key, data):
        with open(self._index_path + ".lock", "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
            plain(self, key, data)

    save.locked = True
    cls.save = save


class _AfterCaching(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds :data:`CACHING` through the other finders, removes itself, runs the module, then
    calls its patches (:func:`when_caching_loads`) with it."""

    def __init__(self):
        self.patches = []

    def find_spec(self, name, path=None, target=None):
        if name != CACHING:
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.loader is not None:
            self.inner = spec.loader
            spec.loader = self
        return spec

    def create_module(self, spec):
        return self.inner.create_module(spec)

    def exec_module(self, module):
        self.inner.exec_module(module)
        for patch in self.patches:
            patch(module)
