"""Where the bundled data folders are: the one place that knows the two layouts.

The repository keeps ``shaders/``, ``scenes/``, ``stress/`` and ``examples/`` at its top level (beside the
``workbench`` package).  A wheel installs them inside the package, as ``workbench/_data/NAME``
(``setup.py`` maps each folder to the package ``workbench._data.NAME``).  So:

* installed from a wheel: ``<site-packages>/workbench/_data/NAME``;
* a checkout (``pip install -e``, or ``PYTHONPATH`` pointing at it): ``<checkout>/NAME``, the
  folder beside the package (there is no ``workbench/_data`` in a checkout).

The package's own location comes from :func:`importlib.resources.files`; the folders are real
directories in both layouts (wheels install unzipped), so callers get :class:`pathlib.Path`
objects they can read, glob and hand to other programs.
"""
from __future__ import annotations

from importlib import resources
from pathlib import Path

from .errors import WorkbenchError

FOLDERS = ("shaders", "scenes", "stress", "examples")
"""The bundled folders, by their name in the repository."""


def data_dir(name: str) -> Path:
    """The directory of the bundled folder ``name`` (one of :data:`FOLDERS`).

    The installed layout (``workbench/_data/NAME``) is looked up first, then the checkout's
    (``NAME`` beside the package).  Raises :class:`WorkbenchError` when neither exists (a broken
    install), naming both places looked at.
    """
    if name not in FOLDERS:
        raise WorkbenchError(f"unknown data folder {name!r} (bundled: {', '.join(FOLDERS)})")
    package = Path(str(resources.files("workbench")))
    candidates = (package / "_data" / name, package.parent / name)
    for path in candidates:
        if path.is_dir():
            return path.resolve()
    raise WorkbenchError(f"bundled folder {name!r} not found (looked in {candidates[0]} and "
                         f"{candidates[1]}): the workbench installation is incomplete")
