"""A disk cache of reference images, so that ``compare``, ``study`` and the UI do not re-render
a converged reference they already have.

Where
-----
``$WORKBENCH_REFERENCE_CACHE`` if set, else ``$XDG_CACHE_HOME/workbench/references``, else
``~/.cache/workbench/references``.  Safe to delete at any time (whole folder or single entries):
a missing entry is a miss and is rendered again.

Key
---
SHA-256 of a canonical serialisation of:

* the scene *as data* (every field of the model's dataclasses, arrays by dtype, shape and bytes,
  at the requested resolution; file locations left out), plus the bytes of every file it
  references (image textures, bump and opacity maps, environment images, mesh files).  The data rather than the scene file's
  text: a scene edited in memory (UI sliders) or built in code gets its own key, while the file's
  comments do not matter;
* the method and its options after defaults are filled in (``{}`` and ``{"spp": 64}`` are the
  same key when 64 is the default);
* width and height;
* the workbench version, a fingerprint of its code (SHA-256 over the ``.py`` files of
  ``workbench/core``, ``scene`` and ``renderers``: any change of a renderer invalidates its
  references) and the versions of numpy, numba and mitsuba;
* :data:`CACHE_FORMAT`.

Entry
-----
``<key>.npy`` (the (H, W, 3) float32 image), ``<key>.arrays.npz`` (the stats' arrays, e.g. the
per-pixel standard error ``stderr`` of Mitsuba; the depth image; ``std_error``, a Monte Carlo result's
per-pixel standard error), ``<key>.json`` (method, options, size,
scene name, timings, scalar stats, left_out, features_used, noise estimate, the image's
SHA-256).  Every file is written to a temporary name and renamed (atomic); the JSON is
written last and is the commit mark.  An entry that does not load, whose image does not match
its recorded hash or shape, or that holds a non-finite value is ignored and rendered again.
"""
from __future__ import annotations

import dataclasses
import hashlib
import importlib.metadata
import io
import json
import os
import time
from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..core.imageio import atomic_write_bytes
from ..core.jit_cache import code_fingerprint
from ..renderers.base import RenderResult, convert_options, get_renderer, render
from ..renderers.support import Note
from ..scene.model import Scene
from .outputs import jsonable

#: Bumped whenever the entry layout or the key's content changes.
CACHE_FORMAT = 3
ENV_VAR = "WORKBENCH_REFERENCE_CACHE"
_VERSIONED = ("numpy", "numba", "mitsuba")
_PATH_FIELDS = ("source", "path")


def cache_dir() -> Path:
    """The cache folder (see the module docstring); not created until something is stored."""
    env = os.environ.get(ENV_VAR)
    if env:
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "workbench" / "references"


def _feed(h, x) -> None:
    """Feed a canonical, type-tagged serialisation of ``x`` into hash ``h``."""
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        h.update(f"<{type(x).__name__}>".encode())
        for f in dataclasses.fields(x):
            if f.name in _PATH_FIELDS:  # where files are is not content (their bytes are keyed)
                continue
            h.update(f.name.encode())
            _feed(h, getattr(x, f.name))
        # class-level kind (sphere, box, ...) is not a field
        h.update(str(getattr(x, "kind", "")).encode())
    elif isinstance(x, dict):
        h.update(b"{")
        for k in sorted(x, key=str):
            _feed(h, str(k))
            _feed(h, x[k])
        h.update(b"}")
    elif isinstance(x, (list, tuple)):
        h.update(b"[" + str(len(x)).encode())
        for v in x:
            _feed(h, v)
        h.update(b"]")
    elif isinstance(x, np.ndarray):
        a = np.ascontiguousarray(x)
        h.update(f"<nd {a.dtype.str} {a.shape}>".encode())
        h.update(a.tobytes())
    elif x is None or isinstance(x, (bool, int, float, str, np.generic)):
        h.update(f"<{type(x).__name__} {x!r}>".encode())
    else:
        raise WorkbenchError(f"reference cache: cannot key a value of type {type(x).__name__} ({x!r:.60})")


def _asset_paths(scene: Scene) -> list[str]:
    """Files the scene references (textures, bump / opacity maps, environment image, meshes)."""
    paths = set()
    for mat in scene.materials.values():
        for sub in (mat.texture, mat.bump, mat.opacity):
            if sub is not None and getattr(sub, "path", None):
                paths.add(sub.path)
    if scene.environment is not None and scene.environment.path:
        paths.add(scene.environment.path)

    def walk(obj):
        src = getattr(obj, "source", "")
        if src and os.path.isfile(src):
            paths.add(src)
        for child in (getattr(obj, "left", None), getattr(obj, "right", None)):
            if child is not None:
                walk(child)
    for obj in scene.objects:
        walk(obj)
    return sorted(paths)


def _versions() -> dict:
    out = {}
    for name in ("workbench",) + _VERSIONED:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = None
    return out


def _key_and_options(scene: Scene, method: str, width: int, height: int, options: dict) -> tuple[str, dict]:
    opts = convert_options(get_renderer(method), options)
    h = hashlib.sha256()
    _feed(h, {"format": CACHE_FORMAT, "method": method, "options": opts, "size": [int(width), int(height)],
              "versions": _versions(), "code": code_fingerprint()})
    _feed(h, scene.with_camera(scene.camera.with_resolution(width, height)))
    for digest in sorted(hashlib.sha256(Path(p).read_bytes()).hexdigest() for p in _asset_paths(scene)):
        h.update(digest.encode())
    return h.hexdigest(), opts


def cache_key(scene: Scene, method: str, width: int, height: int, **options) -> str:
    """The entry name of a render: hex SHA-256 of everything listed in the module docstring.

    ``options`` are converted and completed with the method's defaults first (unknown options
    are an error, as in :func:`workbench.renderers.base.render`)."""
    return _key_and_options(scene, method, width, height, options)[0]


def _files(directory: Path, key: str) -> tuple[Path, Path, Path]:
    return directory / f"{key}.npy", directory / f"{key}.arrays.npz", directory / f"{key}.json"


def _sha(a: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def load_entry(key: str, directory: Path | None = None) -> RenderResult | None:
    """The cached result under ``key``, or None if absent or not intact (never raises for a
    damaged entry: it is simply a miss)."""
    d = Path(directory) if directory is not None else cache_dir()
    img_p, arr_p, meta_p = _files(d, key)
    try:
        meta = json.loads(meta_p.read_text(encoding="utf-8"))
        if meta.get("format") != CACHE_FORMAT or meta.get("key") != key:
            return None
        image = np.load(img_p, allow_pickle=False)
        if (image.dtype != np.float32 or image.shape != (meta["height"], meta["width"], 3)
                or _sha(image) != meta["image_sha256"] or not np.isfinite(image).all()):
            return None
        arrays = {}
        if meta.get("arrays"):
            with np.load(arr_p, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
            if sorted(arrays) != sorted(meta["arrays"]):
                return None
    except (OSError, ValueError, KeyError, TypeError, EOFError, json.JSONDecodeError):
        return None
    stats = dict(meta["stats"])
    stats.update({k[len("stats."):]: v for k, v in arrays.items() if k.startswith("stats.")})
    stats["cache"] = "hit"
    return RenderResult(meta["method"], image, dict(meta["timings"]), stats, list(meta["features_used"]),
                        [Note.from_dict(n) for n in meta["left_out"]], dict(meta["options"]), arrays.get("depth"),
                        std_error=arrays.get("std_error"))


def store_entry(key: str, result: RenderResult, scene_name: str, options: dict,
                directory: Path | None = None) -> Path:
    """Write ``result`` under ``key`` (atomically per file, the JSON last); returns the JSON path.
    ``options`` are the complete options the key was made from."""
    d = Path(directory) if directory is not None else cache_dir()
    img_p, arr_p, meta_p = _files(d, key)
    image = np.ascontiguousarray(result.image, dtype=np.float32)
    arrays = {f"stats.{k}": np.asarray(v) for k, v in result.stats.items() if isinstance(v, np.ndarray)}
    if result.depth is not None:
        arrays["depth"] = np.asarray(result.depth)
    if result.std_error is not None:
        arrays["std_error"] = np.asarray(result.std_error)
    buf = io.BytesIO()
    np.save(buf, image, allow_pickle=False)
    atomic_write_bytes(img_p, buf.getvalue())
    if arrays:
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        atomic_write_bytes(arr_p, buf.getvalue())
    scalars = {k: v for k, v in result.stats.items() if not isinstance(v, np.ndarray) and k != "cache"}
    meta = {"format": CACHE_FORMAT, "key": key, "method": result.method, "options": options,
            "scene": scene_name, "width": int(image.shape[1]), "height": int(image.shape[0]),
            "image_sha256": _sha(image), "arrays": sorted(arrays), "timings": result.timings,
            "stats": scalars, "left_out": [n.as_dict() for n in result.left_out], "features_used": result.features_used,
            "noise": {"stderr_rms": scalars.get("stderr_rms")}, "created": time.strftime("%Y-%m-%dT%H:%M:%S")}
    text = json.dumps(jsonable(meta), indent=1, allow_nan=False)
    atomic_write_bytes(meta_p, text.encode("utf-8"))
    return meta_p


def cached_render(scene: Scene, method: str, width: int, height: int, *, directory: Path | str | None = None,
                  **options) -> RenderResult:
    """``render(scene, method, width, height, **options)`` through the disk cache.

    A hit returns the stored result with ``stats["cache"] = "hit"`` (timings are those of the
    original render); a miss renders, stores and returns it with ``stats["cache"] = "miss"``.
    ``directory`` overrides :func:`cache_dir`.
    """
    d = Path(directory) if directory is not None else cache_dir()
    key, opts = _key_and_options(scene, method, width, height, options)
    hit = load_entry(key, d)
    if hit is not None:
        return hit
    result = render(scene, method, width=width, height=height, **options)
    result.stats["cache"] = "miss"
    try:
        store_entry(key, result, scene.name, opts, d)
    except OSError as e:  # a read-only or full disk costs the cache, not the render
        result.stats["cache"] = f"miss (not stored: {e})"
    return result


def cache_entries(directory: Path | str | None = None) -> list[dict]:
    """Metadata of the intact-looking entries (their JSON), oldest first."""
    d = Path(directory) if directory is not None else cache_dir()
    out = []
    for p in sorted(d.glob("*.json")) if d.is_dir() else []:
        try:
            out.append(json.loads(p.read_text(encoding="utf-8")))
        except (OSError, ValueError):
            continue
    return sorted(out, key=lambda m: str(m.get("created", "")))


def clear_cache(directory: Path | str | None = None) -> int:
    """Delete every entry file (and leftover temporary files); returns how many files went."""
    d = Path(directory) if directory is not None else cache_dir()
    n = 0
    if d.is_dir():
        for p in list(d.glob("*.npy")) + list(d.glob("*.npz")) + list(d.glob("*.json")) + list(d.glob(".tmp-*")):
            p.unlink(missing_ok=True)
            n += 1
    return n


__all__ = ["CACHE_FORMAT", "ENV_VAR", "cache_dir", "cache_key", "cached_render", "load_entry", "store_entry",
           "cache_entries", "clear_cache"]
