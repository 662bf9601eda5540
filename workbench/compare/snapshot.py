"""Snapshot tests for users: a method's image of a scene stored once, later renders compared
with it under a tolerance (``workbench snapshot``, :mod:`workbench.testing`).

Files of one snapshot, in its folder, ``STEM = <scene name>.<method file stem>`` (or a name the
caller gives; :func:`workbench.renderers.base.file_stem` for ``glsl:`` methods):

* ``STEM.npy`` the stored image: (H, W, 3) float32 linear RGB, the value compared (exact, no
  8-bit rounding);
* ``STEM.png`` its sRGB 8-bit preview; ``STEM.json`` the scene, method, options, size, GL
  renderer and date of the recording;
* on a failed check, next to them: ``STEM.actual.png`` / ``STEM.actual.npy`` (the new image),
  ``STEM.diff.png`` (|actual - stored| per channel, linear values clipped to [0, 1], sRGB-encoded,
  unscaled) and ``STEM.heat.png`` (the metric's per-pixel map in false colour with its scale).
  They are removed when the snapshot passes again or is updated.

Metrics (:mod:`.metrics`): ``rmse`` (linear values clipped to [0, 1]) or ``flip`` (mean FLIP,
LDR).  Default tolerances, :data:`DEFAULT_TOLERANCE`: RMSE 0.005 (about 1/200 of display
white: far above llvmpipe's run-to-run differences, which are 0 for the raster methods, and
below a visible change), FLIP 0.02.
"""
from __future__ import annotations

import datetime as _dt
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..core.imageio import atomic_write_text, save_npy, save_png, save_png8
from ..core.tol import tol
from ..renderers.base import check_methods, file_stem, render
from ..scene.model import Scene

METRICS = ("rmse", "flip")
DEFAULT_TOLERANCE = {"rmse": 0.005, "flip": 0.02}
#: Files written next to a snapshot when a check fails (suffixes of its stem).
FAILURE_FILES = (".actual.png", ".actual.npy", ".diff.png", ".heat.png")


@dataclass
class Outcome:
    """What a record or check did.

    status : ``"recorded"``, ``"passed"``, ``"updated"`` (failed or missing, rewritten on
        request), ``"failed"`` or ``"missing"``.
    message : one line naming scene, method, metric, value and tolerance (and the files
        written, or the command that records a missing snapshot).
    """

    scene: str
    method: str
    status: str
    message: str
    stored: Path
    metric: str = ""
    value: float = float("nan")
    tolerance: float = float("nan")
    written: list[Path] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.status in ("recorded", "passed", "updated")


def check_settings(metric: str, tolerance: float | None) -> float:
    """The tolerance to use (the metric's default when None); raises one line for an unknown
    metric or a tolerance that is not a finite number >= 0."""
    if metric not in METRICS:
        raise WorkbenchError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    if tolerance is None:
        return DEFAULT_TOLERANCE[metric]
    try:
        t = float(tolerance)
    except (TypeError, ValueError):
        raise WorkbenchError(f"tolerance must be a number, got {tolerance!r}") from None
    if not (math.isfinite(t) and t >= 0.0):
        raise WorkbenchError(f"tolerance must be a finite number >= 0, got {tolerance!r}")
    return t


def stored_path(directory: str | Path, scene: Scene, method: str, name: str | None = None) -> Path:
    """``DIR/STEM.npy`` of a snapshot (see the module docstring)."""
    stem = name or f"{scene.name}.{file_stem(method)}"
    if not stem or "/" in stem or "\\" in stem or stem.startswith("."):
        raise WorkbenchError(f"snapshot name {stem!r} must be a plain file name")
    return Path(directory) / f"{stem}.npy"


def _sibling(stored: Path, suffix: str) -> Path:
    return stored.with_name(stored.name[:-len(".npy")] + suffix)


def _remove_failure_files(stored: Path) -> None:
    for s in FAILURE_FILES:
        _sibling(stored, s).unlink(missing_ok=True)


def _render(scene: Scene, method: str, size, options: dict):
    w, h = size if size else (None, None)
    return render(scene, method, width=w, height=h, **(options or {}))


def _write(stored: Path, scene: Scene, method: str, result) -> list[Path]:
    stored.parent.mkdir(parents=True, exist_ok=True)
    h, w = result.image.shape[:2]
    meta = {"scene": scene.name, "scene_source": scene.source, "method": method,
            "options": {k: str(v) for k, v in result.options.items()}, "size": [w, h],
            "gl_renderer": result.stats.get("gl_renderer", ""),
            "recorded": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")}
    png, js = _sibling(stored, ".png"), _sibling(stored, ".json")
    save_png(png, result.image)
    atomic_write_text(js, json.dumps(meta, indent=2))
    save_npy(stored, result.image)  # last: a snapshot exists only once its files do
    _remove_failure_files(stored)
    return [stored, png, js]


def record(scene: Scene, method: str, directory: str | Path, *, size: tuple[int, int] | None = None,
           name: str | None = None, options: dict | None = None) -> Outcome:
    """Render ``scene`` with ``method`` and store it as a snapshot, replacing one of the same
    scene file; a snapshot of another scene file stored under the same name is refused
    (:class:`WorkbenchError`, before rendering): two scenes named alike would overwrite each
    other's snapshots."""
    check_methods([method])
    stored = stored_path(directory, scene, method, name)
    meta = _sibling(stored, ".json")
    if stored.exists() and meta.exists():
        try:
            held = json.loads(meta.read_text()).get("scene_source", "")
        except (OSError, ValueError):
            held = ""
        if held and scene.source and Path(held).resolve() != Path(scene.source).resolve():
            raise WorkbenchError(f"snapshot {stored} holds scene {scene.name!r} from {held}, not from "
                                 f"{scene.source}: record into another --dir (or remove it)")
    result = _render(scene, method, size, options or {})
    h, w = result.image.shape[:2]
    written = _write(stored, scene, method, result)
    return Outcome(scene.name, method, "recorded", f"snapshot {scene.name} / {method}: recorded {w}x{h} "
                   f"in {stored}", stored, written=written)


def _load_stored(stored: Path) -> np.ndarray:
    try:
        img = np.load(stored, allow_pickle=False)
    except (OSError, ValueError) as e:
        raise WorkbenchError(f"{stored}: not a snapshot image ({e})") from None
    if img.ndim != 3 or img.shape[-1] != 3 or img.dtype != np.float32 or not np.isfinite(img).all():
        raise WorkbenchError(f"{stored}: not a snapshot image (expected finite (H, W, 3) float32, "
                             f"got {img.dtype} {img.shape})")
    return img


def check(scene: Scene, method: str, directory: str | Path, *, size: tuple[int, int] | None = None,
          metric: str = "rmse", tolerance: float | None = None, update: bool = False,
          name: str | None = None, options: dict | None = None, record_hint: str = "") -> Outcome:
    """Render ``scene`` with ``method`` and compare it with the stored snapshot.

    Parameters
    ----------
    size : (width, height); default the stored image's size (a different one fails).
    metric, tolerance : ``rmse`` or ``flip``; passes when ``value <= tolerance``.
    update : rewrite a failing or missing snapshot with the new image (status ``updated``).
    record_hint : how to record a missing snapshot, quoted in its message.

    Returns
    -------
    :class:`Outcome`; a failure writes the actual image, the difference image and the heat
    map next to the stored one (module docstring).
    """
    tolerance = check_settings(metric, tolerance)
    check_methods([method])
    stored = stored_path(directory, scene, method, name)
    label = f"snapshot {scene.name} / {method}"
    if not stored.is_file():
        if update:
            result = _render(scene, method, size, options or {})
            return Outcome(scene.name, method, "updated", f"{label}: missing, recorded in {stored}", stored,
                           metric, written=_write(stored, scene, method, result))
        hint = f"; record it with: {record_hint}" if record_hint else ""
        return Outcome(scene.name, method, "missing", f"{label}: no stored image {stored}{hint}", stored,
                       metric, tolerance=tolerance)
    ref = _load_stored(stored)
    h, w = ref.shape[:2]
    if size and tuple(size) != (w, h) and not update:
        return Outcome(scene.name, method, "failed", f"{label}: size {size[0]}x{size[1]} differs from the "
                       f"stored {w}x{h} ({stored})", stored, metric, tolerance=tolerance)
    result = _render(scene, method, size or (w, h), options or {})
    image = result.image
    if image.shape != ref.shape:  # only with update and a new size
        return Outcome(scene.name, method, "updated", f"{label}: recorded at the new size in {stored}",
                       stored, metric, written=_write(stored, scene, method, result))
    from .metrics import error_map, flip
    if metric == "flip":
        value, emap = flip(image, ref)
        scale, what = 1.0, "FLIP"
    else:
        emap = error_map(image, ref, "abs")
        value = float(np.sqrt(np.mean((np.clip(image, 0.0, 1.0) - np.clip(ref, 0.0, 1.0)) ** 2)))
        scale, what = max(float(emap.max()), tol.zero), "|linear error|, mean over RGB"
    numbers = f"{metric} {value:.4g} {'<=' if value <= tolerance else '>'} tolerance {tolerance:g}"
    if value <= tolerance:
        _remove_failure_files(stored)
        return Outcome(scene.name, method, "passed", f"{label}: {numbers}", stored, metric, value, tolerance)
    if update:
        return Outcome(scene.name, method, "updated", f"{label}: {numbers}; updated {stored}", stored,
                       metric, value, tolerance, _write(stored, scene, method, result))
    from . import figures
    paths = {s: _sibling(stored, s) for s in FAILURE_FILES}
    save_png(paths[".actual.png"], image)
    save_npy(paths[".actual.npy"], image)
    save_png(paths[".diff.png"], np.abs(np.clip(image, 0.0, 1.0) - np.clip(ref, 0.0, 1.0)))
    save_png8(paths[".heat.png"], figures.heatmap(emap, 0.0, scale, what, f"{scene.name} / {method}"))
    return Outcome(scene.name, method, "failed", f"{label}: {numbers} (difference {paths['.diff.png']}, "
                   f"heat map {paths['.heat.png']})", stored, metric, value, tolerance, list(paths.values()))
