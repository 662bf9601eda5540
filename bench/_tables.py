"""Render ``docs/benchmarks/NAME.md`` of every bench script from its stored result
``bench/results/NAME.json``: the pages of the last measured runs, without measuring anything
(each script's ``--from-json`` does the same for one script).

    .venv/bin/python bench/_tables.py [--docs docs/benchmarks] [--results bench/results] [NAME ...]

A script without a stored result is reported and skipped; a page whose tables cannot be rendered
from its JSON says so in the page and here (exit status 1).
"""
from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

from _common import DOCS, RESULTS  # noqa: E402


def scripts() -> list[Path]:
    """The bench scripts (``bench/*.py`` but the helpers whose names start with ``_``)."""
    return sorted(p for p in BENCH.glob("*.py") if not p.name.startswith("_"))


def load(path: Path):
    """Import a bench script as a module (nothing runs: each keeps its work under ``main``)."""
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[path.stem] = mod
    spec.loader.exec_module(mod)
    return mod


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help="script stems (default: every bench script)")
    ap.add_argument("--docs", type=Path, default=DOCS)
    ap.add_argument("--results", type=Path, default=RESULTS)
    a = ap.parse_args(argv)
    bad = 0
    for path in scripts():
        if a.names and path.stem not in a.names:
            continue
        src = a.results / f"{path.stem}.json"
        if not src.exists():
            print(f"{path.stem}: no stored result {src}: skipped")
            continue
        page = load(path).PAGE
        md = page.render_stored(src, a.docs)
        failed = "could not be rendered" in md.read_text()
        bad += failed
        print(f"{path.stem}: {md}{'  (TABLES FAILED)' if failed else ''}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
