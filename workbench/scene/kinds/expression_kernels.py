"""The numba stack machine of :mod:`.expression`: a compiled program's value (:func:`evaluate`)
and its exact gradient by forward-mode automatic differentiation (:func:`evaluate_gradient`).
Apart from the parser so that reading a scene does not import numba."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .expression import (ADD, CONST, DIV, FIRST_UNARY, MAX, MIN, MUL, NEG, POW, SUB, VAR_X, VAR_Y,
                         VAR_Z)

JIT = dict(cache=True, error_model="numpy", **INTERNAL)
"""Every kernel here is called from compiled code only (``INTERNAL``: no numba wrappers)."""


@nb.njit(**JIT)
def evaluate(code, start, n, x, y, z, stack):
    """The numba stack machine: value of the program ``code[start : start + 2 n]`` (pairs) at
    ``(x, y, z)``; ``stack`` is (depth, 4) scratch (the one :func:`evaluate_gradient` takes;
    this uses its first column)."""
    sp = 0
    for i in range(n):
        op = int(code[start + 2 * i])
        if op == CONST:
            stack[sp, 0] = code[start + 2 * i + 1]
            sp += 1
        elif op == VAR_X:
            stack[sp, 0] = x
            sp += 1
        elif op == VAR_Y:
            stack[sp, 0] = y
            sp += 1
        elif op == VAR_Z:
            stack[sp, 0] = z
            sp += 1
        elif op == NEG:
            stack[sp - 1, 0] = -stack[sp - 1, 0]
        elif op >= FIRST_UNARY:
            v = stack[sp - 1, 0]
            u = op - FIRST_UNARY
            if u == 0:
                r = math.sin(v)
            elif u == 1:
                r = math.cos(v)
            elif u == 2:
                r = math.tan(v)
            elif u == 3:
                r = math.asin(v) if -1.0 <= v <= 1.0 else np.nan
            elif u == 4:
                r = math.acos(v) if -1.0 <= v <= 1.0 else np.nan
            elif u == 5:
                r = math.atan(v)
            elif u == 6:
                r = math.sinh(v)
            elif u == 7:
                r = math.cosh(v)
            elif u == 8:
                r = math.tanh(v)
            elif u == 9:
                r = math.sqrt(v) if v >= 0.0 else np.nan
            elif u == 10:
                r = math.exp(v)
            elif u == 11:
                r = math.log(v) if v > 0.0 else (-np.inf if v == 0.0 else np.nan)
            elif u == 12:
                r = abs(v)
            else:
                r = float(math.floor(v))
            stack[sp - 1, 0] = r
        else:
            b = stack[sp - 1, 0]
            a = stack[sp - 2, 0]
            sp -= 1
            if op == ADD:
                r = a + b
            elif op == SUB:
                r = a - b
            elif op == MUL:
                r = a * b
            elif op == DIV:
                r = a / b
            elif op == POW:
                r = a ** b
            elif op == MIN or op == MAX:
                if a != a or b != b:   # NaN propagates, as numpy's minimum and maximum
                    r = np.nan
                else:
                    r = min(a, b) if op == MIN else max(a, b)
            else:
                r = math.atan2(a, b)
            stack[sp - 1, 0] = r
    return stack[0, 0]


@nb.njit(**JIT)
def evaluate_gradient(code, start, n, x, y, z, stack):
    """Value and exact gradient at ``(x, y, z)`` by forward-mode automatic differentiation (the
    numba twin of :func:`gradient_numpy`); ``stack`` is (depth, 4) scratch: value, d/dx, d/dy,
    d/dz.  Returns ``(f, fx, fy, fz)``."""
    sp = 0
    for i in range(n):
        op = int(code[start + 2 * i])
        if op <= VAR_Z:
            stack[sp, 0] = code[start + 2 * i + 1] if op == CONST else (x if op == VAR_X else (y if op == VAR_Y else z))
            for c in range(3):
                stack[sp, 1 + c] = 1.0 if op - VAR_X == c else 0.0
            sp += 1
        elif op == NEG:
            for c in range(4):
                stack[sp - 1, c] = -stack[sp - 1, c]
        elif op >= FIRST_UNARY:
            v = stack[sp - 1, 0]
            u = op - FIRST_UNARY
            if u == 0:
                r, dr = math.sin(v), math.cos(v)
            elif u == 1:
                r, dr = math.cos(v), -math.sin(v)
            elif u == 2:
                r = math.tan(v)
                dr = 1.0 + r * r
            elif u == 3 or u == 4:
                if -1.0 <= v <= 1.0:
                    r = math.asin(v) if u == 3 else math.acos(v)
                    dr = 1.0 / math.sqrt(1.0 - v * v)
                    if u == 4:
                        dr = -dr
                else:
                    r, dr = np.nan, np.nan
            elif u == 5:
                r, dr = math.atan(v), 1.0 / (1.0 + v * v)
            elif u == 6:
                r, dr = math.sinh(v), math.cosh(v)
            elif u == 7:
                r, dr = math.cosh(v), math.sinh(v)
            elif u == 8:
                r = math.tanh(v)
                dr = 1.0 - r * r
            elif u == 9:
                if v >= 0.0:
                    r = math.sqrt(v)
                    dr = 0.5 / r
                else:
                    r, dr = np.nan, np.nan
            elif u == 10:
                r = math.exp(v)
                dr = r
            elif u == 11:
                if v > 0.0:
                    r, dr = math.log(v), 1.0 / v
                else:
                    r, dr = (-np.inf if v == 0.0 else np.nan), np.nan
            elif u == 12:
                r, dr = abs(v), (1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0))
            else:
                r, dr = float(math.floor(v)), 0.0
            stack[sp - 1, 0] = r
            for c in range(1, 4):
                stack[sp - 1, c] = dr * stack[sp - 1, c]
        else:
            b, a = stack[sp - 1, 0], stack[sp - 2, 0]
            sp -= 1
            t = sp - 1
            if op == ADD:
                stack[t, 0] = a + b
                for c in range(1, 4):
                    stack[t, c] = stack[t, c] + stack[sp, c]
            elif op == SUB:
                stack[t, 0] = a - b
                for c in range(1, 4):
                    stack[t, c] = stack[t, c] - stack[sp, c]
            elif op == MUL:
                stack[t, 0] = a * b
                for c in range(1, 4):
                    stack[t, c] = stack[t, c] * b + a * stack[sp, c]
            elif op == DIV:
                stack[t, 0] = a / b
                for c in range(1, 4):
                    stack[t, c] = (stack[t, c] * b - a * stack[sp, c]) / (b * b)
            elif op == POW:
                p = a ** b
                varies = stack[sp, 1] != 0.0 or stack[sp, 2] != 0.0 or stack[sp, 3] != 0.0
                lg = p * math.log(a) if (varies and a > 0.0) else (np.nan if varies else 0.0)
                da = b * a ** (b - 1.0)
                stack[t, 0] = p
                for c in range(1, 4):
                    stack[t, c] = da * stack[t, c] + lg * stack[sp, c]
            elif op == MIN or op == MAX:
                pick_a = (a <= b) if op == MIN else (a >= b)
                if a != a or b != b:
                    stack[t, 0] = np.nan
                elif not pick_a:
                    for c in range(4):
                        stack[t, c] = stack[sp, c]
            else:
                den = a * a + b * b
                stack[t, 0] = math.atan2(a, b)
                for c in range(1, 4):
                    stack[t, c] = (b * stack[t, c] - a * stack[sp, c]) / den
    return stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3]
