"""No dead code the linter can see: pyflakes reports nothing on the package, the tests and the
benchmarks (unused locals and imports, undefined names, redefinitions), except the
re-exports of ``__init__.py`` files (their imports are the package's public names)."""
from __future__ import annotations

from pathlib import Path

from pyflakes import api, messages, reporter

ROOT = Path(__file__).resolve().parents[1]


class _Collect(reporter.Reporter):
    def __init__(self):
        self.found: list[str] = []

    def flake(self, message):
        if isinstance(message, messages.UnusedImport) and Path(message.filename).name == "__init__.py":
            return
        self.found.append(str(message))

    def unexpectedError(self, filename, msg):
        self.found.append(f"{filename}: {msg}")

    def syntaxError(self, filename, msg, lineno, offset, text):
        self.found.append(f"{filename}:{lineno}: {msg}")


def test_pyflakes_reports_nothing():
    rep = _Collect()
    files = sorted(str(p) for d in ("workbench", "tests", "bench") for p in (ROOT / d).rglob("*.py"))
    assert len(files) > 50
    api.checkRecursive(files, rep)
    assert not rep.found, "\n".join(rep.found)
