"""The renderer protocol, ``RenderResult`` and ``render()``: the one entry point of every method.

A renderer is a class with a ``name``, a ``knob`` (its quality parameter, swept by the study),
a dictionary of accepted ``options`` and a ``render(scene, width, height, **options)`` method
returning a :class:`RenderResult`.  ``render()`` validates the method and options, times the
call, and guarantees that the returned image is finite (non-finite pixels are counted in
``stats["nonfinite_pixels"]`` and replaced by 0, so a NaN is reported, never shown).

Memory: every renderer also has ``estimate_bytes(scene, width, height, **options) -> int``, an
upper bound of the peak memory the render will allocate (patches, form factors, hemicube
buffers, triangles, ray generations, BVH, images...), computed cheaply before anything big is
allocated, and ``memory_options``, the names of the options the estimate grows with.
``render()`` refuses a render whose estimate exceeds the limit of
:func:`workbench.core.memory.memory_limit` with one :class:`WorkbenchError` line that names
the estimate, the limit, the options to lower and how to raise the limit.
"""
from __future__ import annotations

import importlib
import time
from pathlib import Path
from dataclasses import dataclass, field
from typing import Any, Callable, Protocol

import numpy as np

from ..core.errors import OverMemory, WorkbenchError
from ..core.memory import ENV as MEMORY_ENV
from ..core.memory import gib, memory_limit
from ..scene.model import Scene
from .registry import BUILTIN, OPT_IN, USER_SHADING
from .support import Note, SupportTable


@dataclass(frozen=True)
class Knob:
    """A method's quality knob: ``name`` (an option of the method), the sweep ``values`` from
    cheapest to most accurate, and the ``default``."""

    name: str
    values: tuple
    default: Any
    description: str = ""


def callback(v):
    """The converter of a progress option (``on_tile``, ``on_pass``): a callable, or None."""
    if v is None or callable(v):
        return v
    raise ValueError("expected a callable or None")


@dataclass(frozen=True)
class Option:
    """An accepted option: converter (``int``, ``float``, ``bool``, ``str`` or a callable that
    raises ``ValueError``), default, help text, for strings the allowed choices, and for numbers
    the smallest value allowed (``low``; None: any)."""

    kind: Callable
    default: Any
    help: str = ""
    choices: tuple | None = None
    low: float | None = None


@dataclass
class RenderResult:
    """What every method returns.

    image : (H, W, 3) float32, linear RGB, top row first, always finite.
    timings : seconds; ``total`` (wall time of the call), ``compile`` (shader or JIT
        compilation, part of total), and method-specific phases.
    stats : counts and facts (rays, patches, GL_RENDERER, ...).
    features_used / left_out : features of the scene this method built, and notes
        (:class:`.support.Note`: feature, status, reason; printed ``"feature: reason"``) on
        those it did not (not needed by the scene, or left out or approximated by the method,
        from its ``support`` table and the scene's content).
    depth : (H, W) float32 camera-space depth along the view axis (inf where nothing), if given.
    std_error : (H, W, 3) float32 per-pixel standard error of the mean of a Monte Carlo image
        (its own noise estimate), if given; its RMS is ``stats["noise_rmse"]``.
    """

    method: str
    image: np.ndarray
    timings: dict[str, float] = field(default_factory=dict)
    stats: dict[str, Any] = field(default_factory=dict)
    features_used: list[str] = field(default_factory=list)
    left_out: list[Note] = field(default_factory=list)
    options: dict[str, Any] = field(default_factory=dict)
    depth: np.ndarray | None = None
    std_error: np.ndarray | None = None


UI_KINDS = ("gl", "cpu", "child", "progressive")
"""What a renderer is to the interactive window (its ``ui_kind``), which the window asks
instead of listing methods by name:

* ``"gl"``: drawn in the window's own GL context whenever its inputs change; the renderer has
  ``session(scene, tessellation=, ctx=)`` returning a :class:`~.raster.RasterSession`;
* ``"cpu"``: rendered by :func:`render` in a background thread (``on_tile`` when it accepts it);
* ``"child"``: rendered by :func:`render` in a child process (PyOpenGL's EGL platform cannot
  share the window's process);
* ``"progressive"``: refined pass after pass in a background thread; the renderer has
  ``progressive_session(scene, width, height, **options)`` returning an object with
  ``add_samples(n)``, ``image``, ``samples`` and ``noise_rmse``, and its knob (the samples per
  pixel) is the target the panel refines towards.
"""


class Renderer(Protocol):
    name: str
    support: SupportTable
    ui_kind: str
    knob: Knob
    options: dict[str, Option]
    memory_options: tuple[str, ...]

    def render(self, scene: Scene, width: int, height: int, **options) -> RenderResult: ...

    def estimate_bytes(self, scene: Scene, width: int, height: int, **options) -> int: ...


_instances: dict[str, Renderer] = {}


def stats_for_display(stats: dict) -> dict:
    """``stats`` with every array (e.g. a per-pixel noise image) replaced by a one-line summary
    ``"array (H, W, 3) float32, RMS x"`` and every numpy scalar (also inside lists, tuples and
    dicts, and a one-element array) by the Python number it holds: what reports and the CLI print
    and write to JSON (the arrays themselves stay in ``RenderResult.stats``).  A numpy scalar
    printed inside a list shows as ``np.float32(0.1)`` under numpy 2, and json writes it as text."""
    out = {}
    for k, v in stats.items():
        if isinstance(v, np.ndarray) and v.size > 1:
            a = v.astype(np.float64)
            rms = float(np.sqrt(np.mean(a * a))) if a.size and np.isfinite(a).all() else float("nan")
            out[k] = f"array {tuple(v.shape)} {v.dtype}, RMS {rms:.4g}"
        else:
            out[k] = _plain(v)
    return out


def _plain(v):
    """``v`` with numpy scalars and one-element arrays turned into Python numbers, recursively
    through lists, tuples and dicts (a tuple stays a tuple); anything else unchanged."""
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return (tuple if isinstance(v, tuple) else list)(_plain(x) for x in v)
    if isinstance(v, (np.generic, np.ndarray)):
        return v.item() if v.size == 1 else v.tolist()
    return v


def available() -> list[str]:
    """Names of the registered methods."""
    return list(BUILTIN)


def default_methods() -> list[str]:
    """The methods ``compare`` and ``study`` run when none are named: every registered one except
    the opt-in outside references (``registry.OPT_IN``)."""
    return [m for m in BUILTIN if m not in OPT_IN]


#: Method names ``glsl:PATH``: a user's shading model in the file PATH (:mod:`.user_shading`).
USER_PREFIX = "glsl:"


def get_renderer(method: str) -> Renderer:
    """The (cached) renderer instance registered as ``method``; for ``glsl:PATH`` a new
    renderer of the user's shading model in PATH (checked: a missing or invalid file raises
    :class:`WorkbenchError`), not registered nor cached."""
    if method.startswith(USER_PREFIX):
        mod, attr = USER_SHADING.split(":")
        return getattr(importlib.import_module(mod), attr)(method[len(USER_PREFIX):], name=method)
    if method not in BUILTIN:
        raise WorkbenchError(f"unknown method {method!r} (available: {', '.join(available())})")
    if method not in _instances:
        mod, attr = BUILTIN[method].split(":")
        _instances[method] = getattr(importlib.import_module(mod), attr)()
    return _instances[method]


def check_methods(names: list[str]) -> None:
    """Raise one :class:`WorkbenchError` naming every unknown method of ``names``, or the
    first ``glsl:`` file that cannot be used."""
    unknown = [m for m in names if m not in BUILTIN and not m.startswith(USER_PREFIX)]
    if unknown:
        raise WorkbenchError(f"unknown method(s) {', '.join(unknown)} (available: {', '.join(available())}, "
                             f"or {USER_PREFIX}FILE for a shading model in GLSL)")
    for m in names:
        if m.startswith(USER_PREFIX):
            get_renderer(m)
    stems = [file_stem(m) for m in names]
    clash = sorted({s for s in stems if stems.count(s) > 1})
    if clash:
        raise WorkbenchError(f"methods {', '.join(m for m in names if file_stem(m) in clash)} would write "
                             f"the same files ({', '.join(clash)}): name the shading models' files apart")


def file_stem(method: str) -> str:
    """A file-name-safe stem for a method's output files: the name of a registered method,
    ``glsl_<file stem>`` for a user's shading model ``glsl:PATH``."""
    if not method.startswith(USER_PREFIX):
        return method
    stem = "".join(c if c.isalnum() or c in "_.-" else "_" for c in Path(method[len(USER_PREFIX):]).stem)
    return f"glsl_{stem or 'model'}"


def convert_options(r: Renderer, options: dict) -> dict:
    out = {k: o.default for k, o in r.options.items()}
    for k, v in options.items():
        if k not in r.options:
            raise WorkbenchError(f"method {r.name!r}: unknown option {k!r} "
                                 f"(accepted: {', '.join(sorted(r.options)) or 'none'})")
        o = r.options[k]
        try:
            if o.kind is bool and isinstance(v, str):
                if v.lower() not in ("1", "0", "true", "false", "yes", "no", "on", "off"):
                    raise ValueError(v)
                val = v.lower() in ("1", "true", "yes", "on")
            else:
                val = o.kind(v)
        except (TypeError, ValueError):
            raise WorkbenchError(f"method {r.name!r}: option {k!r} expects {getattr(o.kind, '__name__', 'a valid value')}"
                                 f" ({o.help}), got {v!r}") from None
        if isinstance(val, float) and not np.isfinite(val):
            raise WorkbenchError(f"method {r.name!r}: option {k!r} must be a finite number, got {v!r}")
        if o.low is not None and val < o.low:
            raise WorkbenchError(f"method {r.name!r}: option {k!r} must be >= {o.low:g} ({o.help}), got {v!r}")
        if o.choices is not None and val not in o.choices:
            raise WorkbenchError(f"method {r.name!r}: option {k!r} must be one of {', '.join(map(str, o.choices))}, got {v!r}")
        out[k] = val
    return out


def _pixels(name: str, value, default: int) -> int:
    """An image size given to :func:`render`: an integer (not a bool, a float or a string)."""
    if value is None:
        return int(default)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise WorkbenchError(f"render: {name} must be an integer number of pixels, got "
                             f"{type(value).__name__} {value!r:.80}")
    return int(value)


def check_memory(r: Renderer, scene: Scene, width: int, height: int, options: dict,
                 max_memory=None) -> int:
    """``r.estimate_bytes(...)`` (converted options), checked against
    :func:`~workbench.core.memory.memory_limit` (``max_memory``, else the environment variable
    ``WORKBENCH_MAX_MEMORY``, else a share of physical memory).  Returns the estimate.

    Raises
    ------
    WorkbenchError
        One line naming the estimate, the limit, the options to lower and the ways to raise
        the limit, when the estimate exceeds it.
    """
    limit = memory_limit(max_memory)
    est = r.estimate_bytes(scene, width, height, **options)
    if not isinstance(est, (int, np.integer)) or est <= 0:
        raise TypeError(f"{type(r).__name__}.estimate_bytes returned {est!r}, not a positive int")
    if est > limit:
        named = [k for k in r.memory_options if k in options]  # (an API call may leave some at their default)
        knobs = "".join(f"{k}={options[k]!r}, " for k in named) + ("or " if named else "")
        raise OverMemory(
            f"method {r.name!r}: {width}x{height} needs about {gib(est)} of memory, above the limit "
            f"of {gib(limit)}: change {knobs}the image size, or raise the limit "
            f"(--max-memory, {MEMORY_ENV} or max_memory=)")
    return int(est)


def render(scene: Scene, method: str, *, width: int | None = None, height: int | None = None,
           max_memory=None, **options) -> RenderResult:
    """Render ``scene`` with the method registered as ``method``.

    Parameters
    ----------
    width, height : int, optional
        Image size; the scene camera's resolution by default.  The camera (and its vertical
        field of view) is otherwise the scene's: every method sees the same view.
    max_memory : int or str, optional
        Memory limit of this render in bytes or as ``"8G"``; by default the environment
        variable ``WORKBENCH_MAX_MEMORY``, else half the physical memory
        (:mod:`workbench.core.memory`).  The method's ``estimate_bytes`` is checked against it
        before anything is allocated (:func:`check_memory`).
    **options
        Method options (see ``workbench methods``); unknown ones are an error.
    """
    if not isinstance(scene, Scene):
        raise WorkbenchError(f"render: scene must be a Scene (from workbench.load_scene), got "
                             f"{type(scene).__name__} {scene!r:.80}")
    if not isinstance(method, str):
        raise WorkbenchError(f"render: method must be a registered method's name (str), got "
                             f"{type(method).__name__} {method!r:.80}")
    r = get_renderer(method)
    w = _pixels("width", width, scene.camera.width)
    h = _pixels("height", height, scene.camera.height)
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise WorkbenchError(f"image size must be within 1..16384 pixels, got {w}x{h}")
    opts = convert_options(r, options)
    sized = scene.with_camera(scene.camera.with_resolution(w, h))
    estimate = check_memory(r, sized, w, h, opts, max_memory)
    t0 = time.perf_counter()
    result = r.render(sized, w, h, **opts)
    result.timings["total"] = time.perf_counter() - t0
    result.timings.setdefault("compile", 0.0)
    result.options = opts
    result.stats["memory_estimate_bytes"] = estimate
    img = np.asarray(result.image, dtype=np.float32)
    bad = ~np.isfinite(img)
    result.stats["nonfinite_pixels"] = int(bad.any(-1).sum())
    if bad.any():
        img = np.where(bad, 0.0, img).astype(np.float32)
    result.image = img
    return result
