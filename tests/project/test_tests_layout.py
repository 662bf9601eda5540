"""The tests sit in folders that mirror the package (``tests/scene/kinds`` tests
``workbench/scene/kinds``, ``tests/renderers/raster`` the module ``workbench/renderers/raster.py``
and its ``raster_*`` siblings, ...), plus ``tests/project`` for what concerns the repository as a
whole (lint, docs, packaging, benchmarks, the suite's statistics budget); ``tests/`` itself holds
only the shared helpers and ``conftest.py``.  Test module names are unique across folders (the
suite runs in pytest's default import mode, without ``__init__.py`` files)."""
from __future__ import annotations

from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TESTS = ROOT / "tests"
OWN_FOLDERS = {"project", "golden", "data"}
"""Folders of ``tests/`` that mirror no package: repository-wide checks and test data."""


def test_no_test_module_at_the_top_of_tests():
    assert sorted(p.name for p in TESTS.glob("test_*.py")) == []


def test_every_test_folder_mirrors_a_package_folder():
    folders = {p.parent.relative_to(TESTS) for p in TESTS.rglob("test_*.py")}
    stray = sorted(str(f) for f in folders
                   if f.parts[0] not in OWN_FOLDERS and not (ROOT / "workbench" / f).is_dir()
                   and not (ROOT / "workbench" / f).with_suffix(".py").is_file())
    assert len(folders) >= 8 and not stray, stray


def test_test_module_names_are_unique():
    names = Counter(p.name for p in TESTS.rglob("test_*.py"))
    assert not [n for n, k in names.items() if k > 1]
