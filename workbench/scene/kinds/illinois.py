"""The one bracketed root finder of the implicit and swept kinds' kernels (blob, isosurface,
lathe): the Illinois method (Dowell & Jarratt, "A modified regula falsi method for computing the
root of an equation", BIT 11, 1971), regula falsi that halves the value kept at an end that
stays twice, superlinear, with a bisection step wherever the secant point is not strictly inside
the bracket (a NaN value, a flat stretch).  A numba kernel; the kinds pass their function as an
argument (numba compiles one copy per function)."""
from __future__ import annotations

import numba as nb

from ...core.jit_options import INTERNAL
from .crossing_events import BISECTIONS

JIT = dict(cache=True, error_model="numpy", **INTERNAL)
"""Every kernel here is called from compiled code only (``INTERNAL``: no numba wrappers)."""


@nb.njit(**JIT)
def change(f, fargs, a, fa, b, fb):
    """The end past the change of ``f(fargs, t) > 0`` in ``[a, b]`` (``fa``, ``fb``: the values
    at the ends, on the two sides of the change), narrowed to adjacent floats."""
    sa = fa > 0.0
    side = 0
    for _ in range(BISECTIONS):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        c = (a * fb - b * fa) / (fb - fa)
        if not (a < c < b):
            c = m
        fc = f(fargs, c)
        if (fc > 0.0) == sa:
            a, fa = c, fc
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            b, fb = c, fc
            if side == 1:
                fa *= 0.5
            side = 1
    return b
