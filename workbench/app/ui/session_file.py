"""``workbench ui --script FILE.py:NAME``: a scripted session of the window, loaded from a Python file.

``NAME`` is a callable of the file (a class or a function); ``NAME(out)`` (``out``: the ``--out``
folder, a :class:`~pathlib.Path`) makes the session, which the window calls once per frame with
its :class:`~.state.AppState`, after the panels' images are updated.  A session acts through the
functions the window's widgets call (:mod:`.state`, :mod:`.camera`), records what it wants into
``out`` and ends the run by setting ``state.quit``.  Optional attributes of the session:
``log``, a JSON-able dict written to ``summary.json`` as ``"script"``, and ``keeps_awake``
(default true), which keeps the window drawing every frame instead of idling.

The file is loaded as ``python FILE.py`` would run it: its folder is put first on ``sys.path``,
so it may import modules beside it.  The state's fields are the window's internals, not a stable
API.  The project's tests and benchmarks keep their sessions in ``tests/app/ui/sessions.py``.
"""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Callable

from ...core.errors import WorkbenchError


def load_session(spec: str) -> Callable:
    """The session factory ``NAME`` of ``spec`` = ``"FILE.py:NAME"``; a :class:`WorkbenchError`
    naming what is wrong (the form, a missing file, an error while the file runs, a missing or
    non-callable ``NAME``)."""
    path, sep, name = spec.rpartition(":")
    if not sep or not path or not name.isidentifier():
        raise WorkbenchError(f"--script {spec!r}: expected FILE.py:NAME (a Python file and the "
                             "name of the session class or function in it)")
    file = Path(path)
    if file.suffix != ".py":
        raise WorkbenchError(f"--script {spec!r}: {path} is not a .py file")
    if not file.is_file():
        raise WorkbenchError(f"--script {spec!r}: no file {path}")
    folder = str(file.resolve().parent)
    if folder not in sys.path:
        sys.path.insert(0, folder)
    module_spec = importlib.util.spec_from_file_location(f"workbench_session_{file.stem}", file)
    module = importlib.util.module_from_spec(module_spec)
    try:
        module_spec.loader.exec_module(module)
    except Exception as e:  # a user's file: any error it raises is reported in one line
        raise WorkbenchError(f"--script {spec!r}: {path} failed to load "
                             f"({type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''})") from None
    factory = getattr(module, name, None)
    if not callable(factory):
        raise WorkbenchError(f"--script {spec!r}: {path} has no session {name!r} (a class or "
                             "function taking the output folder)")
    return factory
