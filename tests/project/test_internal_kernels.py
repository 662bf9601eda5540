"""No Python code calls a kernel compiled without numba's wrappers.

A kernel compiled with ``workbench.core.jit_options.INTERNAL`` (no CPython wrapper: the helpers and gates that only
compiled code calls) crashes the process when Python calls it, where a user would expect at
worst an exception.  Tests and benches call such a helper through ``workbench.core.jit_options.python_twin``.  This
test reads the package, the tests and the benchmarks with ``ast`` and lists every call, outside
a jitted function, whose callee resolves through the file's imports (or its own module) to such
a kernel: ``name(...)`` of ``from module import name``, ``alias.name(...)`` of ``import module as
alias``, and so on along attribute chains.  Calls through variables (``k = ...; k.f()``) are not
followed."""
from __future__ import annotations

import ast
import importlib
import pkgutil
from pathlib import Path

import workbench
from workbench.core.jit_options import wrapperless

ROOT = Path(__file__).resolve().parents[2]
JIT_DECORATORS = ("njit", "jit", "overload", "intrinsic", "register_jitable", "lower_builtin")
"""A function decorated with a name holding one of these is compiled code: its calls are not Python's."""


def _module(name: str):
    """The workbench module ``name``, imported; ``None`` for another package's or one that is
    not a module (a name imported from a module)."""
    if not (name == "workbench" or name.startswith("workbench.")) or name.startswith("workbench.app.ui"):
        return None
    try:
        return importlib.import_module(name)
    except ImportError:
        return None


def _module_name(path: Path) -> str | None:
    if not path.is_relative_to(ROOT / "workbench"):
        return None
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _aliases(tree: ast.Module, own: str | None, is_package: bool) -> dict[str, tuple[str, str | None]]:
    """Local name -> (module, attribute or None) for every import of the file (any depth)."""
    out: dict[str, tuple[str, str | None]] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.asname:
                    out[a.asname] = (a.name, None)
                else:
                    out[a.name.split(".")[0]] = (a.name.split(".")[0], None)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                if own is None:
                    continue
                pkg = own.split(".") if is_package else own.split(".")[:-1]
                pkg = pkg[:len(pkg) - (node.level - 1)]
                base = ".".join(pkg + ([base] if base else []))
            for a in node.names:
                out[a.asname or a.name] = (base, a.name)
    return out


def _resolve(expr: ast.expr, aliases, own_module):
    """The object ``expr`` (a name or an attribute chain) names, or ``None`` if not resolved."""
    chain = []
    while isinstance(expr, ast.Attribute):
        chain.append(expr.attr)
        expr = expr.value
    if not isinstance(expr, ast.Name):
        return None
    if expr.id in aliases:
        mod, attr = aliases[expr.id]
        obj = _module(f"{mod}.{attr}") if attr else _module(mod)
        if obj is None and attr:
            base = _module(mod)
            obj = getattr(base, attr, None) if base is not None else None
    elif own_module is not None:
        obj = getattr(own_module, expr.id, None)
    else:
        return None
    for name in reversed(chain):
        if obj is None:
            return None
        obj = getattr(obj, name, None)
    return obj


def _jitted(fn: ast.FunctionDef) -> bool:
    return any(any(k in ast.unparse(d) for k in JIT_DECORATORS) for d in fn.decorator_list)


def _python_calls_of_internal_kernels(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    own = _module_name(path)
    aliases = _aliases(tree, own, path.name == "__init__.py")
    own_module = _module(own) if own else None
    where = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path.name
    found = []

    def visit(node, in_jit):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            in_jit = in_jit or _jitted(node)
        if isinstance(node, ast.Call) and not in_jit and wrapperless(_resolve(node.func, aliases, own_module)):
            found.append(f"{where}:{node.lineno}: {ast.unparse(node.func)}(...)")
        for child in ast.iter_child_nodes(node):
            visit(child, in_jit)

    visit(tree, False)
    return found


def _internal_kernels() -> list[str]:
    names = []
    for info in pkgutil.walk_packages(workbench.__path__, "workbench."):
        module = _module(info.name)
        if module is not None:
            names += [f"{info.name}.{k}" for k, v in vars(module).items()
                      if wrapperless(v) and v.__module__ == info.name]
    return names


def test_no_python_code_calls_a_wrapperless_kernel():
    kernels = _internal_kernels()
    assert len(kernels) > 50, kernels  # the package's helpers and gates were found
    files = sorted(p for d in ("workbench", "tests", "bench") for p in (ROOT / d).rglob("*.py"))
    found = [line for p in files for line in _python_calls_of_internal_kernels(p)]
    assert not found, "\n".join(found)


def test_the_scan_finds_such_a_call(tmp_path):
    """The scan sees the three spellings of a call (a bad file, written for the test)."""
    bad = tmp_path / "probe.py"
    bad.write_text("from workbench.renderers.kernels import walks\n"
                   "from workbench.renderers.kernels.walks import bvh_hit\n"
                   "import workbench.renderers.kernels.walks as W\n"
                   "import numba as nb\n"
                   "def f():\n"
                   "    walks.bvh_hit()\n"
                   "    bvh_hit()\n"
                   "    W.bvh_hit()\n"
                   "@nb.njit\n"
                   "def g():\n"
                   "    bvh_hit()\n")
    found = _python_calls_of_internal_kernels(bad)
    assert [line.split(": ")[1] for line in found] == ["walks.bvh_hit(...)", "bvh_hit(...)", "W.bvh_hit(...)"]
