"""How the tests start the window: the console script ``workbench ui``, as the README tells
users to (the ``workbench`` next to the running interpreter, i.e. the venv's)."""
from __future__ import annotations

import sys
from pathlib import Path

WORKBENCH = str(Path(sys.executable).with_name("workbench"))
"""The console script installed with the package."""


SESSIONS = Path(__file__).resolve().parent / "app" / "ui" / "sessions.py"
"""The project's scripted sessions of the window (``--script FILE.py:NAME``)."""


def script_of(name: str, file: str = "sessions.py") -> str:
    """``--script``'s value for the session ``name`` of ``file`` (beside :data:`SESSIONS`)."""
    return f"{SESSIONS.with_name(file)}:{name}"


def ui_command(*args: str) -> list[str]:
    """``workbench ui ARGS...`` as a subprocess argument list."""
    return [WORKBENCH, "ui", *args]
