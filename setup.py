"""Package discovery and the data-folder mapping (the rest of the metadata is in pyproject.toml).

The repository keeps ``shaders/``, ``scenes/``, ``stress/`` and ``examples/`` at its top level; a wheel installs
each inside the package as ``workbench/_data/NAME`` (package ``workbench._data.NAME`` mapped to
the folder ``NAME``).  ``workbench.core.resources.data_dir`` finds them in either layout.

Every folder that holds data files is declared as a package of its own (``workbench._data.shaders.include``,
``workbench.core.data``, ...) with its files as package data, so setuptools builds the wheel without
"Package would be ignored" warnings (data-only folders must be listed in ``packages``).
Written here rather than in pyproject.toml because setuptools' ``packages.find`` cannot be
combined with extra mapped packages: ``find_packages`` keeps new subpackages included.
"""
from pathlib import Path

from setuptools import find_packages, setup

HERE = Path(__file__).resolve().parent
DATA_FOLDERS = ("shaders", "scenes", "stress", "examples")
SKIP = {"__pycache__"}


def data_packages(folder: str, package: str) -> list[str]:
    """``package`` and one dotted package per subfolder of ``folder`` (relative to this file),
    e.g. ``shaders/include`` -> ``workbench._data.shaders.include``."""
    root = HERE / folder
    subs = sorted(p for p in root.rglob("*") if p.is_dir() and not SKIP & set(p.relative_to(root).parts))
    return [package] + [".".join((package, *p.relative_to(root).parts)) for p in subs]


CODE = find_packages(include=["workbench*"])
DATA = {f"workbench._data.{d}": d for d in DATA_FOLDERS}
DATA_PACKAGES = [p for pkg, folder in DATA.items() for p in data_packages(folder, pkg)]
DATA_PACKAGES += data_packages("workbench/core/data", "workbench.core.data")

setup(
    packages=CODE + DATA_PACKAGES,
    package_dir=DATA,  # subpackages follow their parent's folder
    package_data={p: ["*"] for p in DATA_PACKAGES},
    exclude_package_data={"": ["__pycache__/*", "*.pyc"]},
)
