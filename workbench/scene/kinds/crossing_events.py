"""Interval lists of solids bounded by pieces (lathe segments, prism walls and caps): the
crossings of a line with every piece, sorted, kept only where the solid's status changes.

A line through an edge shared by two pieces meets both at the same ``t`` and a line tangent
to a piece meets it without entering; counting crossings would break the alternation of
entering and leaving that CSG needs.  Testing the point midway between consecutive
crossings (and far before the first and after the last: outside, the solids are bounded)
decides each one instead.

A kind's kernel module (its ``KERNELS``: blob, isosurface, lathe, prism, any plugin) defines
one function per role, by these names and signatures, so that the kernels' dispatch over
``ptype`` (:mod:`workbench.renderers.kernels.specialise`) is generated from the registry:

* ``first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack)
  -> (t, face)``: nearest hit in ``(tmin, tmax)``, ``(inf, 0)`` on a miss;
* ``events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack) -> count``:
  the interval list along the whole line (a CSG leaf);
* ``normal(par, k, aux, face, x, y, z, stack) -> (nx, ny, nz)``: outward, object space;
* ``inside(par, k, aux, x, y, z, stack) -> bool``.

``par`` is the (P, NPAR) parameter table and ``k`` the kind's row, ``aux`` the flat float64
array of variable-length data (each row holds its offset and count); ``out_t`` (float64),
``out_f`` (int64) and ``stack`` ((MAX_STACK, 4) float64, the isosurface's expression
evaluator) are the caller's scratch: nothing is allocated.
"""
from __future__ import annotations

import numpy as np

BISECTIONS = 200
"""Steps cap of the kinds' bracketed root searches (the readable twins' bisections and the
kernels' :func:`.illinois.change`): enough to reach adjacent floats from any bracket of finite
width."""


def alternate(hits: list[tuple[float, int]], inside_at) -> list[tuple[float, int]]:
    """Readable: ``hits`` (t, face) of the line with every piece, and ``inside_at(t)`` the
    solid's status at the line's point ``t``.  Returns the crossings where the status changes,
    sorted: they alternate entering / leaving."""
    hits = sorted(hits)
    out, status = [], False
    for i, (t, f) in enumerate(hits):
        nxt = hits[i + 1][0] if i + 1 < len(hits) else np.inf
        if nxt == t:
            continue
        after = inside_at(0.5 * (t + nxt)) if nxt < np.inf else False
        if after != status:
            out.append((t, f))
            status = after
    return out
