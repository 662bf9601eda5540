"""Readers of scene-file values: each checks one key of a TOML table and fails with a
:class:`SceneError` whose one line names the file, the key and what was expected.

Shared by :mod:`.io` (the scene's sections) and the object kinds (:mod:`.kinds`), which parse
their own tables with them.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..core import transform as tf
from ..core.errors import WorkbenchError
from ..core.tol import tol

FLOAT32_MAX = float(np.finfo(np.float32).max)

class SceneError(WorkbenchError):
    """A scene file (or scene dictionary) is invalid; the message says where and why."""


class Ctx:
    """Where we are in the file, for messages."""

    def __init__(self, source: str, base_dir: Path):
        self.source, self.base_dir = source, base_dir

    def fail(self, where: str, msg: str):
        raise SceneError(f"{self.source}: {where}: {msg}")


# --------------------------------------------------------------------------- value readers
def check_keys(ctx: Ctx, table: Any, where: str, allowed: set[str], required: set[str] = frozenset()):
    if not isinstance(table, dict):
        ctx.fail(where, f"expected a table, got {type(table).__name__}")
    unknown = sorted(set(table) - allowed)
    if unknown:
        ctx.fail(f"{where}.{unknown[0]}", f"unknown key (expected one of: {', '.join(sorted(allowed))})")
    missing = sorted(required - set(table))
    if missing:
        ctx.fail(f"{where}.{missing[0]}", "missing required key")


def num(ctx, t, where, key, default=None, *, lo=None, hi=None, lo_open=False, integer=False):
    if key not in t:
        if default is None:
            ctx.fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or (integer and not isinstance(v, int)):
        ctx.fail(f"{where}.{key}", f"expected {'an integer' if integer else 'a number'}, got {v!r}")
    if not np.isfinite(v):
        ctx.fail(f"{where}.{key}", f"expected a finite number, got {v!r}")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        ctx.fail(f"{where}.{key}", f"expected a number {'>' if lo_open else '>='} {lo}, got {v!r}")
    if hi is not None and v > hi:
        ctx.fail(f"{where}.{key}", f"expected a number <= {hi}, got {v!r}")
    return int(v) if integer else float(v)


def vec(ctx, t, where, key, default=None, *, n=3, nonzero=False, lo=None):
    if key not in t:
        if default is None:
            ctx.fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    ok = isinstance(v, list) and len(v) == n and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in v)
    if not ok:
        ctx.fail(f"{where}.{key}", f"expected a list of {n} finite numbers, got {v!r}")
    if nonzero and not tf.normalize(v).any():   # a direction: any length has one, 0 has none
        ctx.fail(f"{where}.{key}", f"expected a non-zero vector, got {v!r}")
    if lo is not None and min(v) < lo:
        ctx.fail(f"{where}.{key}", f"expected components >= {lo}, got {v!r}")
    return tuple(float(x) for x in v)


def rgb(ctx, t, where, key, default):
    return vec(ctx, t, where, key, default, n=3, lo=0.0)


def string(ctx, t, where, key, default=None, *, choices=None):
    if key not in t:
        if default is None:
            ctx.fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    if not isinstance(v, str):
        ctx.fail(f"{where}.{key}", f"expected a string, got {v!r}")
    if choices is not None and v not in choices:
        ctx.fail(f"{where}.{key}", f"expected one of {', '.join(repr(c) for c in choices)}, got {v!r}")
    return v


def boolean(ctx, t, where, key, default):
    v = t.get(key, default)
    if not isinstance(v, bool):
        ctx.fail(f"{where}.{key}", f"expected true or false, got {v!r}")
    return v


def matrix(ctx, t, where, key, n=4):
    v = t[key]
    ok = (isinstance(v, list) and len(v) == n and all(isinstance(r, list) and len(r) == n for r in v)
          and all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x)
                  for r in v for x in r))
    if not ok:
        ctx.fail(f"{where}.{key}", f"expected a {n}x{n} matrix (list of {n} lists of {n} numbers)")
    return np.array(v, dtype=np.float64)


def file_path(ctx, t, where, key, required=True):
    if key not in t:
        if required:
            ctx.fail(f"{where}.{key}", "missing required key")
        return None
    p = Path(string(ctx, t, where, key))
    p = p if p.is_absolute() else ctx.base_dir / p
    if not p.is_file():
        ctx.fail(f"{where}.{key}", f"file not found: {p}")
    return str(p)




def parallel(a, b) -> bool:
    """Directions ``a`` and ``b`` (3,), non-zero, at an angle whose sine is at most
    ``tol.degenerate`` (whatever their lengths)."""
    return float(np.linalg.norm(np.cross(tf.normalize(a), tf.normalize(b)))) <= tol.degenerate



def polygon_vertices(ctx, t, w):
    v = t.get("vertices")
    if not (isinstance(v, list) and len(v) >= 3 and all(
            isinstance(p, list) and len(p) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in p) for p in v)):
        ctx.fail(f"{w}.vertices", "expected a list of at least 3 points [x, y, z]")
    v = np.array(v, dtype=np.float64)
    cross = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
    diam = float(np.ptp(v, axis=0).max())
    if np.linalg.norm(cross) <= tol.degenerate * diam * max(diam, float(np.abs(v).max())):
        ctx.fail(f"{w}.vertices", "polygon has zero area (collinear or repeated points)")
    n = cross / np.linalg.norm(cross)
    dev = np.abs((v - v[0]) @ n).max()
    if dev > tol.planar * diam:
        ctx.fail(f"{w}.vertices", f"polygon is not planar (a vertex is {dev:.3g} off its plane)")
    return v

