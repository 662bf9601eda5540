"""Readers of a kind's scene-file table (a ``dict`` from TOML or JSON): each checks one key and
raises a one-line :class:`~workbench.core.errors.WorkbenchError` ``"<where>.<key>: <what was
expected>, got <value>"``; the scene reader prefixes the file name."""
from __future__ import annotations

import math

import numpy as np

from ...core.errors import WorkbenchError


COMMON = frozenset({"type", "material", "transform", "name", "tessellation"})
"""Keys every object table may have, read by the scene reader before the kind's own parser."""


def fail(where: str, msg: str):
    raise WorkbenchError(f"{where}: {msg}")


def parse_with(ctx, read, t: dict, where: str, common: dict):
    """The registry's ``parse(ctx, t, w, common)``: run a kind's ``read`` and hand its error to
    ``ctx.fail(where, what)`` (the scene reader's, which names the file)."""
    try:
        return read(t, where, common)
    except WorkbenchError as e:
        at, _, what = str(e).partition(": ")
        ctx.fail(at, what)


def check_keys(t, where: str, allowed: set[str], required: set[str] = frozenset()):
    """``t`` is a table with only ``allowed`` keys and every ``required`` one."""
    if not isinstance(t, dict):
        fail(where, f"expected a table, got {type(t).__name__}")
    unknown = sorted(set(t) - allowed)
    if unknown:
        fail(f"{where}.{unknown[0]}", f"unknown key (expected one of: {', '.join(sorted(allowed))})")
    missing = sorted(set(required) - set(t))
    if missing:
        fail(f"{where}.{missing[0]}", "missing required key")


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def number(t, where: str, key: str, default=None, *, lo=None, lo_open=False, hi=None,
           integer=False):
    """A finite number (``int`` when ``integer``), within ``[lo, hi]`` (``lo`` excluded when
    ``lo_open``); ``default`` when absent (required when ``default`` is None)."""
    if key not in t:
        if default is None:
            fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    if not _is_number(v) or (integer and not isinstance(v, int)):
        fail(f"{where}.{key}", f"expected {'an integer' if integer else 'a finite number'}, got {v!r}")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        fail(f"{where}.{key}", f"expected a number {'>' if lo_open else '>='} {lo}, got {v!r}")
    if hi is not None and v > hi:
        fail(f"{where}.{key}", f"expected a number <= {hi}, got {v!r}")
    return int(v) if integer else float(v)


def vector(t, where: str, key: str, n: int = 3, default=None) -> tuple[float, ...]:
    """A list of ``n`` finite numbers."""
    if key not in t:
        if default is None:
            fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    if not (isinstance(v, list) and len(v) == n and all(_is_number(x) for x in v)):
        fail(f"{where}.{key}", f"expected a list of {n} finite numbers, got {v!r}")
    return tuple(float(x) for x in v)


def points(t, where: str, key: str, n: int, *, least: int, most: int) -> np.ndarray:
    """A list of ``least..most`` points, each a list of ``n`` finite numbers: (k, n) float64."""
    if key not in t:
        fail(f"{where}.{key}", "missing required key")
    v = t[key]
    if not isinstance(v, list) or not least <= len(v) <= most:
        fail(f"{where}.{key}", f"expected a list of {least} to {most} points, got "
                               f"{len(v) if isinstance(v, list) else repr(v)}")
    for i, p in enumerate(v):
        if not (isinstance(p, list) and len(p) == n and all(_is_number(x) for x in p)):
            fail(f"{where}.{key}[{i}]", f"expected a list of {n} finite numbers, got {p!r}")
    return np.array(v, dtype=np.float64).reshape(-1, n)


def box(t, where: str, key: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``key = {min = [..], max = [..]}`` with ``max > min`` on every axis."""
    if key not in t:
        fail(f"{where}.{key}", "missing required key: bounds = {min = [x, y, z], max = [x, y, z]}")
    w = f"{where}.{key}"
    check_keys(t[key], w, {"min", "max"}, {"min", "max"})
    lo, hi = vector(t[key], w, "min"), vector(t[key], w, "max")
    if any(a >= b for a, b in zip(lo, hi)):
        fail(f"{w}.max", f"must exceed min on every axis (min {list(lo)}, max {list(hi)})")
    return lo, hi


MARCH_STEPS = (2, 1 << 16)
"""The march's steps across a medium's bounding sphere that a medium kind's ``step`` must give
(hypertexture, fur): at least the first, at most the second (a step that tiny makes a render of
hours)."""


def march_step(where: str, step: float, radius: float, what: str) -> None:
    """``step`` gives :data:`MARCH_STEPS` steps across the diameter of ``what``'s bounding
    sphere of ``radius``."""
    steps = 2.0 * radius / step
    lo, hi = MARCH_STEPS
    if not lo <= steps <= hi:
        fail(f"{where}.step", f"gives {steps:.3g} steps across {what}'s bounding sphere "
             f"(diameter {2 * radius:.4g}); expected {lo} to {hi}")
