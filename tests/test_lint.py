"""No dead code the linter can see: pyflakes reports nothing on the package, the tests and the
benchmarks (unused locals and imports, undefined names, redefinitions), except the
re-exports of ``__init__.py`` files (their imports are the package's public names).  And the
package's imports (read with ``ast``) form no circle and go one way through the layers
core -> scene -> renderers -> compare -> app."""
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


# --------------------------------------------------------------------------- import graph
LAYERS = ("core", "scene", "renderers", "compare", "app")
"""The package's layers, lowest first: a module imports only from its own layer or below."""


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph() -> dict[str, set[str]]:
    """Every module of the ``workbench`` package -> the package modules it imports, anywhere in
    it (module level, inside functions, under ``TYPE_CHECKING``).  ``from P import name`` is an
    edge to the module ``P.name`` when there is one, else to ``P``; a package's ``__init__`` is
    the module named like the package, and importing a submodule is not counted as importing
    its parent packages' ``__init__``."""
    import ast
    files = {_module_name(p): p for p in (ROOT / "workbench").rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for name, path in files.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        edges: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[:len(base) - (node.level - 1)]
                    src = ".".join(base + ([node.module] if node.module else []))
                else:
                    src = node.module or ""
                targets = [f"{src}.{a.name}" if f"{src}.{a.name}" in files else src for a in node.names]
            else:
                continue
            for t in targets:
                while t and t not in files:   # "workbench.scene.model.Scene" -> the module
                    t = t.rpartition(".")[0]
                if t and t != name and t.startswith("workbench"):
                    edges.add(t)
        graph[name] = edges
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan 1972), sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(out)


def _layer(module: str) -> int | None:
    parts = module.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else None


def test_import_graph_has_no_cycle():
    """No circle of imports (module level or inside functions) anywhere in the package, but
    the known UI ones."""
    graph = import_graph()
    assert "workbench.scene.kinds.sphere" in graph and len(graph) > 100
    cycles = _cycles(graph)
    assert not cycles, "import cycles:\n" + "\n".join(" <-> ".join(c) for c in cycles)


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
    assert _cycles(graph) == [["workbench.scene.a", "workbench.scene.b", "workbench.scene.c"]]
    assert _layer("workbench.app.e") > _layer("workbench.core.d")
