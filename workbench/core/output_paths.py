"""Checks of output paths, made by every command before any work starts (a render that would
be lost on a bad path is never started), and the all-or-nothing publication of several files.

A path is writable when it is not an existing folder (files) or is one (folders), and its
nearest existing ancestor is a folder in which a file can be created (tried, not guessed): the
missing folders in between are created when writing.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Callable

from .errors import WorkbenchError


def _writable_parent(path: Path, option: str) -> None:
    """The nearest existing ancestor of ``path`` is a folder this process can write into."""
    ancestor = path.parent
    while not ancestor.exists():
        if ancestor.is_symlink():
            raise WorkbenchError(f"{option}: {ancestor} is a broken link")
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise WorkbenchError(f"{option}: cannot write {path}: {ancestor} is a file, not a folder")
    _probe(ancestor, f"{option}: cannot write {path}")


def _probe(folder: Path, what: str) -> None:
    """Create and drop a file in ``folder``: permissions, read-only file systems and special
    folders such as /proc all answer this one the way the real write will (``os.access``
    answers yes to root everywhere)."""
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".probe-"):
            pass
    except OSError as e:
        raise WorkbenchError(f"{what}: {folder}: {e.strerror or e}") from None


def check_output_file(path: str | os.PathLike, option: str, suffix: str | None = None) -> Path:
    """Refuse a file output that cannot be written, with one line naming ``option``.

    Parameters
    ----------
    path : the file to be written (replaced if it exists).
    option : how the user gave it (``-o``, ``--npy``), for the message.
    suffix : required extension (``".png"``), case-insensitive, if any.
    """
    p = Path(path)
    if suffix is not None and p.suffix.lower() != suffix:
        raise WorkbenchError(f"{option}: output must be a {suffix} file, got {str(path)!r}")
    if p.is_dir():
        raise WorkbenchError(f"{option}: {p} is a folder, expected a file name")
    if p.exists() and not p.is_file():
        raise WorkbenchError(f"{option}: {p} exists and is not a regular file")
    _writable_parent(p, option)
    return p


def check_output_dir(path: str | os.PathLike, option: str) -> Path:
    """Refuse an output folder that cannot be created or written, naming ``option``."""
    p = Path(path)
    if p.exists():
        if not p.is_dir():
            raise WorkbenchError(f"{option}: {p} is a file, expected a folder")
        _probe(p, f"{option}: cannot write into the folder")
        return p
    _writable_parent(p, option)
    return p


def check_distinct(paths: dict[str, str | os.PathLike | None]) -> None:
    """Two outputs of one command must not be the same file (``{option: path}``)."""
    seen: dict[Path, str] = {}
    for option, path in paths.items():
        if path is None:
            continue
        key = Path(path).resolve()
        if key in seen:
            raise WorkbenchError(f"{option} and {seen[key]} name the same file {path}")
        seen[key] = option


def write_together(writers: list[tuple[str | os.PathLike, Callable[[str], None]]]) -> None:
    """Write several files all or nothing: each ``write(tmp_path)`` fills a temporary file next
    to its destination; only when every one succeeded are they renamed into place
    (``os.replace``, atomic per file).  On any error the temporaries are removed and no
    destination is touched."""
    umask = os.umask(0)
    os.umask(umask)
    staged: list[tuple[str, Path]] = []
    try:
        for path, write in writers:
            dest = Path(path)
            dest.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=dest.parent, prefix=".tmp-", suffix=dest.suffix)
            os.close(fd)
            staged.append((tmp, dest))
            write(tmp)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file the usual mode
        for tmp, dest in staged:
            os.replace(tmp, dest)
    finally:
        for tmp, _ in staged:
            Path(tmp).unlink(missing_ok=True)
