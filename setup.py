"""Package discovery and the data-folder mapping (the rest of the metadata is in pyproject.toml).

The repository keeps ``shaders/``, ``scenes/``, ``stress/`` and ``examples/`` at its top level; a wheel installs
each inside the package as ``workbench/_data/NAME`` (package ``workbench._data.NAME`` mapped to
the folder ``NAME``).  ``workbench.core.resources.data_dir`` finds them in either layout.
Written here rather than in pyproject.toml because setuptools' ``packages.find`` cannot be
combined with extra mapped packages: ``find_packages`` keeps new subpackages included.
"""
from setuptools import find_packages, setup

DATA_FOLDERS = ("shaders", "scenes", "stress", "examples")

setup(
    packages=find_packages(include=["workbench*"]) + [f"workbench._data.{d}" for d in DATA_FOLDERS],
    package_dir={f"workbench._data.{d}": d for d in DATA_FOLDERS},
    package_data={"workbench.core": ["data/*.csv"], **{f"workbench._data.{d}": ["**/*"] for d in DATA_FOLDERS}},
    exclude_package_data={"": ["__pycache__/*", "*.pyc"]},
)
