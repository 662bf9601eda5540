"""Rendering workbench: classic image-synthesis methods side by side on one scene, measured.

Public API (stable)::

    import workbench
    scene = workbench.load_scene("whitted")            # a path or a bundled scene's name
    result = workbench.render(scene, "phong", width=320, height=240)
    workbench.compare.metrics(result.image, reference)

Heavy modules (moderngl, numba, pyrender, matplotlib) load only when a method needs them.
``workbench.__version__`` is the installed distribution's version (pyproject.toml's
``[project] version``, the one place it is written), looked up when asked (``importlib.metadata``
takes 20 ms to import, more than a command like ``workbench scenes`` needs in all).
"""
from __future__ import annotations

import importlib
from pathlib import Path


def _version() -> str:
    """The version of the installed ``workbench`` distribution; in a checkout that is not
    installed (``PYTHONPATH=checkout``), the ``[project] version`` of its pyproject.toml; else
    ``"0+unknown"``."""
    import importlib.metadata
    try:
        return importlib.metadata.version("workbench")
    except importlib.metadata.PackageNotFoundError:
        pass
    import tomllib
    try:
        project = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())["project"]
        if project.get("name") == "workbench":
            return str(project["version"])
    except (OSError, KeyError, tomllib.TOMLDecodeError):
        pass
    return "0+unknown"


from .core.jit_cache import use_code_keyed_cache

use_code_keyed_cache()  # before any kernel compiles: numba's cache keyed by this code

from .core.errors import NotApplicable, WorkbenchError  # noqa: E402,F401
from .scene.io import SceneError, load_scene  # noqa: E402,F401

__all__ = ["__version__", "load_scene", "render", "available_methods", "SceneError", "WorkbenchError",
           "NotApplicable", "compare", "raytrace", "radiosity"]

_LAZY = {"compare": "workbench.compare", "raytrace": "workbench.renderers.raytrace",
         "radiosity": "workbench.renderers.radiosity"}


def render(scene, method, *, width=None, height=None, **options):
    """Render ``scene`` with a registered method; see :func:`workbench.renderers.base.render`."""
    from .renderers.base import render as _render
    return _render(scene, method, width=width, height=height, **options)


def available_methods() -> list[str]:
    """Names of the registered methods (the built-in ones; ``glsl:FILE`` names a user model)."""
    from .renderers.base import available
    return available()


def __getattr__(name):
    if name == "__version__":
        return _version()
    if name in _LAZY:
        return importlib.import_module(_LAZY[name])
    raise AttributeError(f"module 'workbench' has no attribute {name!r}")
