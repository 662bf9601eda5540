"""CSG by interval lists (Roth 1982; the course's ``intersect`` / ``composite_intersect``).

Along a ray, a solid is a sorted list of boundary crossings that alternate entering / leaving.
Combining two solids by ``union``, ``intersection`` or ``difference`` sweeps both lists in
order and keeps a crossing wherever the boolean of "inside left" and "inside right" changes.
Crossings closer than ``eps`` are one event (coincident surfaces: ``A - A`` is empty,
``A n A = A u A = A``), and intervals shorter than ``eps`` are dropped.  A difference turns the
right solid inside out: its surfaces' normals are flipped.

Readable version (lists of :class:`Crossing`); :func:`.kernels.combine` is the numba twin.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

OPS = {
    "union": lambda a, b: a or b,
    "intersection": lambda a, b: a and b,
    "difference": lambda a, b: a and not b,
}


@dataclass(frozen=True)
class Crossing:
    """A boundary crossing at ``t`` of surface ``face`` of leaf ``leaf``; ``flip`` when the
    leaf's outward normal points into the composite solid (right side of a difference)."""

    t: float
    leaf: Any
    face: int = 0
    flip: bool = False


def combine(op: str, left: list[Crossing], right: list[Crossing], eps: float) -> list[Crossing]:
    """``composite_intersect``: the interval list of ``left op right``."""
    if op == "difference":
        right = [replace(c, flip=not c.flip) for c in right]
    inside = OPS[op]
    i = j = 0
    in_l = in_r = state = False
    out: list[Crossing] = []
    while i < len(left) or j < len(right):
        t = min(left[i].t if i < len(left) else float("inf"), right[j].t if j < len(right) else float("inf"))
        event = None
        while i < len(left) and left[i].t <= t + eps:  # every crossing of this instant
            in_l, event = not in_l, left[i]
            i += 1
        while j < len(right) and right[j].t <= t + eps:
            in_r = not in_r
            event = event or right[j]
            j += 1
        new = inside(in_l, in_r)
        if new != state:
            state = new
            if not new and out and event.t - out[-1].t <= eps:
                out.pop()  # an interval of zero length is no solid
            else:
                out.append(event)
    return out
