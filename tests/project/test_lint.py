"""No dead code the linter can see: pyflakes reports nothing on the package, the tests and the
benchmarks (unused locals and imports, undefined names, redefinitions), except the
re-exports of ``__init__.py`` files (their imports are the package's public names).  And the
package's imports (read with ``ast``) form no circle and go one way through the layers
core -> scene -> renderers -> compare -> app."""
from __future__ import annotations

from pathlib import Path

from pyflakes import api, messages, reporter

from import_graph import cycles, import_graph

ROOT = Path(__file__).resolve().parents[2]


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


# --------------------------------------------------------------------------- import graph
LAYERS = ("core", "scene", "renderers", "compare", "app")
"""The package's layers, lowest first: a module imports only from its own layer or below."""


def _layer(module: str) -> int | None:
    parts = module.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else None


def test_import_graph_has_no_cycle():
    """No circle of imports (module level or inside functions) anywhere in the package, but
    the known UI ones."""
    graph = import_graph()
    assert "workbench.scene.kinds.sphere" in graph and len(graph) > 100
    found = cycles(graph)
    assert not found, "import cycles:\n" + "\n".join(" <-> ".join(c) for c in found)


def test_imports_go_one_way_through_the_layers():
    """core -> scene -> renderers -> compare -> app: no module imports from a higher layer."""
    graph = import_graph()
    up = sorted(f"{a} imports {b}" for a, targets in graph.items() for b in targets
                if _layer(a) is not None and _layer(b) is not None and _layer(b) > _layer(a))
    assert not up, "\n".join(up)


def test_the_cycle_finder_finds_a_planted_cycle():
    """The checks above can fail: a circle a -> b -> c -> a and an upward import are found."""
    graph = {"workbench.scene.a": {"workbench.scene.b"}, "workbench.scene.b": {"workbench.scene.c"},
             "workbench.scene.c": {"workbench.scene.a"}, "workbench.core.d": {"workbench.app.e"},
             "workbench.app.e": set()}
    assert cycles(graph) == [["workbench.scene.a", "workbench.scene.b", "workbench.scene.c"]]
    assert _layer("workbench.app.e") > _layer("workbench.core.d")
