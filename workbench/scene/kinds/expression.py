"""A safe arithmetic expression of ``x, y, z`` (an isosurface's function), compiled once to a
postfix program that a numba stack machine evaluates (:mod:`.expression_kernels`).  Never Python ``eval``.

Grammar (recursive descent, one function per rule; ``^`` and ``**`` are the same operator,
right-associative and binding tighter than unary minus, so ``-x^2 = -(x^2)`` as in
mathematics and POV-Ray)::

    expr    := term (('+' | '-') term)*
    term    := unary (('*' | '/') unary)*
    unary   := ('-' | '+') unary | power
    power   := atom (('^' | '**') unary)?
    atom    := NUMBER | 'x' | 'y' | 'z' | 'pi' | 'e' | NAME '(' expr (',' expr)* ')' | '(' expr ')'

Functions: the one-argument ones in :data:`UNARY` (``sin cos tan asin acos atan sinh cosh tanh
sqrt exp log abs floor``), ``atan2(y, x)``, ``pow(a, b)``, and ``min``/``max`` of two or more
arguments.  A value outside a function's domain (``sqrt(-1)``, ``log(0)``) is NaN or an
infinity, as IEEE 754 says; the isosurface refuses a function that is not finite at one of
the points where it samples it at load, and counts such points elsewhere as outside.

Program format (:func:`compile_expression`): a flat float64 array of ``(opcode, argument)``
pairs, the argument used by ``CONST`` only, so that it travels in a kind's aux array with the
rest of the scene.  Errors are one :class:`~workbench.core.errors.WorkbenchError` line naming
the 1-based character position, e.g. ``expression 'x^2 +': position 5: expected a number, a
name or '(' (got the end)``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...core.errors import WorkbenchError

CONST, VAR_X, VAR_Y, VAR_Z, ADD, SUB, MUL, DIV, POW, NEG, MIN, MAX, ATAN2 = range(13)
UNARY = ("sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "sqrt", "exp", "log",
         "abs", "floor")
"""One-argument functions, opcodes ``FIRST_UNARY + index``."""
FIRST_UNARY = 16
_BINARY_OPS = {"+": ADD, "-": SUB, "*": MUL, "/": DIV, "^": POW}
_FUNCTIONS_2 = {"atan2": ATAN2, "pow": POW}
_VARIADIC = {"min": MIN, "max": MAX}
_CONSTANTS = {"pi": math.pi, "e": math.e}
MAX_STACK = 64
"""Deepest operand stack a program may need (the evaluators' scratch size; deeper nesting is
refused at compile time)."""
MAX_LENGTH = 4096
"""Longest expression text accepted (characters)."""


@dataclass(frozen=True)
class Program:
    """A compiled expression.

    Attributes
    ----------
    code : (2 n,) float64 ``(opcode, argument)`` pairs in postfix order.
    depth : int, the operand stack depth its evaluation needs (<= :data:`MAX_STACK`).
    text : the source expression.
    """

    code: np.ndarray
    depth: int
    text: str

    @property
    def length(self) -> int:
        return len(self.code) // 2


# --------------------------------------------------------------------------- tokenizer
def _tokens(text: str, fail) -> list[tuple[str, object, int]]:
    """``(kind, value, position)`` tokens; kinds ``num``, ``name``, ``op``, ``end``."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c.isspace():
            i += 1
        elif c.isdigit() or (c == "." and i + 1 < n and text[i + 1].isdigit()):
            j = i
            while j < n and (text[j].isdigit() or text[j] == "."):
                j += 1
            if j < n and text[j] in "eE" and (j + 1 < n and (text[j + 1].isdigit()
                                                            or (text[j + 1] in "+-" and j + 2 < n and text[j + 2].isdigit()))):
                j += 2
                while j < n and text[j].isdigit():
                    j += 1
            try:
                value = float(text[i:j])
            except ValueError:
                fail(i, f"malformed number {text[i:j]!r}")
            if not math.isfinite(value):
                fail(i, f"number {text[i:j]} is beyond the float64 range")
            out.append(("num", value, i))
            i = j
        elif c.isalpha() or c == "_":
            j = i
            while j < n and (text[j].isalnum() or text[j] == "_"):
                j += 1
            out.append(("name", text[i:j].lower(), i))
            i = j
        elif text.startswith("**", i):
            out.append(("op", "^", i))
            i += 2
        elif c in "+-*/^(),":
            out.append(("op", c, i))
            i += 1
        else:
            fail(i, f"unexpected character {c!r}")
    out.append(("end", None, n))
    return out


# --------------------------------------------------------------------------- parser
class _Parser:
    """Recursive descent over the tokens, emitting postfix ``(opcode, argument)`` pairs."""

    def __init__(self, text: str):
        self.text = text
        self.toks = _tokens(text, self.fail)
        self.i = 0
        self.nest = 0
        self.code: list[tuple[int, float]] = []

    def fail(self, pos: int, msg: str):
        raise WorkbenchError(f"expression {self.text!r}: position {pos + 1}: {msg}")

    def peek(self):
        return self.toks[self.i]

    def take(self):
        tok = self.toks[self.i]
        self.i += 1
        return tok

    def expect(self, op: str, after: str):
        kind, value, pos = self.take()
        if kind != "op" or value != op:
            self.fail(pos, f"expected {op!r} {after} (got {_describe(kind, value)})")

    def expr(self):
        self.term()
        while self.peek()[0] == "op" and self.peek()[1] in "+-":
            op = self.take()[1]
            self.term()
            self.code.append((_BINARY_OPS[op], 0.0))

    def term(self):
        self.unary()
        while self.peek()[0] == "op" and self.peek()[1] in "*/":
            op = self.take()[1]
            self.unary()
            self.code.append((_BINARY_OPS[op], 0.0))

    def unary(self):
        kind, value, pos = self.peek()
        self.nest += 1      # every nesting (parentheses, arguments, signs, powers) passes here
        if self.nest > MAX_STACK:
            self.fail(pos, f"nested too deeply (more than {MAX_STACK} levels)")
        if kind == "op" and value in "+-":
            self.take()
            self.unary()
            if value == "-":
                self.code.append((NEG, 0.0))
        else:
            self.power()
        self.nest -= 1

    def power(self):
        self.atom()
        if self.peek()[0] == "op" and self.peek()[1] == "^":
            self.take()
            self.unary()
            self.code.append((POW, 0.0))

    def atom(self):
        kind, value, pos = self.take()
        if kind == "num":
            self.code.append((CONST, value))
        elif kind == "name":
            if value in ("x", "y", "z"):
                self.code.append(({"x": VAR_X, "y": VAR_Y, "z": VAR_Z}[value], 0.0))
            elif value in _CONSTANTS:
                self.code.append((CONST, _CONSTANTS[value]))
            elif value in UNARY or value in _FUNCTIONS_2 or value in _VARIADIC:
                self.call(value, pos)
            else:
                self.fail(pos, f"unknown name {value!r} (variables x, y, z; constants pi, e; "
                               f"functions {', '.join(UNARY + tuple(_FUNCTIONS_2) + tuple(_VARIADIC))})")
        elif kind == "op" and value == "(":
            self.expr()
            self.expect(")", "to close the '('")
        else:
            self.fail(pos, f"expected a number, a name or '(' (got {_describe(kind, value)})")

    def call(self, name: str, pos: int):
        self.expect("(", f"after the function name {name!r}")
        self.expr()
        n = 1
        while self.peek()[0] == "op" and self.peek()[1] == ",":
            self.take()
            self.expr()
            n += 1
        self.expect(")", f"to close the arguments of {name!r}")
        if name in UNARY:
            if n != 1:
                self.fail(pos, f"{name} takes 1 argument, got {n}")
            self.code.append((FIRST_UNARY + UNARY.index(name), 0.0))
        elif name in _FUNCTIONS_2:
            if n != 2:
                self.fail(pos, f"{name} takes 2 arguments, got {n}")
            self.code.append((_FUNCTIONS_2[name], 0.0))
        else:
            if n < 2:
                self.fail(pos, f"{name} takes 2 or more arguments, got {n}")
            self.code.extend([(_VARIADIC[name], 0.0)] * (n - 1))


def _describe(kind, value) -> str:
    return "the end" if kind == "end" else repr(value) if kind != "num" else f"the number {value!r}"


def _arity(op: int) -> int:
    if op <= VAR_Z:
        return 0
    if op == NEG or op >= FIRST_UNARY:
        return 1
    return 2


def compile_expression(text: str) -> Program:
    """Parse ``text`` and compile it to a postfix :class:`Program`.

    Raises :class:`WorkbenchError` (one line, with the 1-based position) on a syntax error, an
    unknown name, a wrong argument count, a text longer than :data:`MAX_LENGTH` or one nested
    deeper than :data:`MAX_STACK`.
    """
    if not isinstance(text, str):
        raise WorkbenchError(f"expression: expected a string, got {text!r}")
    if len(text) > MAX_LENGTH:
        raise WorkbenchError(f"expression: {len(text)} characters, at most {MAX_LENGTH} accepted")
    p = _Parser(text)
    if p.peek()[0] == "end":
        p.fail(0, "empty expression")
    p.expr()
    kind, value, pos = p.peek()
    if kind != "end":
        p.fail(pos, f"unexpected {_describe(kind, value)} after a complete expression")
    depth = top = 0
    for op, _ in p.code:
        a = _arity(op)
        top += 1 - a
        depth = max(depth, top)
    if depth > MAX_STACK:
        raise WorkbenchError(f"expression {text!r}: nested too deeply (needs a stack of {depth}, "
                             f"at most {MAX_STACK})")
    code = np.array(p.code, dtype=np.float64).reshape(-1)
    return Program(code=code, depth=depth, text=text)


# --------------------------------------------------------------------------- evaluators
_NUMPY_UNARY = (np.sin, np.cos, np.tan, np.arcsin, np.arccos, np.arctan, np.sinh, np.cosh, np.tanh,
                np.sqrt, np.exp, np.log, np.abs, np.floor)


def evaluate_numpy(program: Program, x, y, z) -> np.ndarray:
    """The readable evaluator: run the postfix program over arrays ``x, y, z`` (any one
    broadcast shape) with NumPy.  Returns float64 values of that shape."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, z)))
    stack: list[np.ndarray] = []
    code = program.code.reshape(-1, 2)
    with np.errstate(all="ignore"):
        for op_f, arg in code:
            op = int(op_f)
            if op == CONST:
                stack.append(np.full(x.shape, arg))
            elif op <= VAR_Z:
                stack.append((x, y, z)[op - VAR_X])
            elif op == NEG:
                stack.append(-stack.pop())
            elif op >= FIRST_UNARY:
                stack.append(_NUMPY_UNARY[op - FIRST_UNARY](stack.pop()))
            else:
                b, a = stack.pop(), stack.pop()
                stack.append({ADD: np.add, SUB: np.subtract, MUL: np.multiply, DIV: np.divide,
                              POW: np.power, MIN: np.minimum, MAX: np.maximum,
                              ATAN2: np.arctan2}[op](a, b))
    return np.asarray(stack[0], dtype=np.float64)


def _unary_derivative(u: int, v):
    """d/dv of one-argument function ``UNARY[u]`` at ``v`` (NumPy)."""
    return (np.cos(v), -np.sin(v), 1.0 + np.tan(v) ** 2, 1.0 / np.sqrt(1.0 - v * v),
            -1.0 / np.sqrt(1.0 - v * v), 1.0 / (1.0 + v * v), np.cosh(v), np.sinh(v),
            1.0 - np.tanh(v) ** 2, 0.5 / np.sqrt(v), np.exp(v), 1.0 / v, np.sign(v),
            np.zeros_like(v))[u]


def gradient_numpy(program: Program, x, y, z) -> tuple[np.ndarray, np.ndarray]:
    """Value and exact gradient of the program (forward-mode automatic differentiation: each
    stack entry carries its value and its three partial derivatives, propagated by the
    chain rule).  Returns ``(f (...), grad (..., 3))`` over the broadcast shape of x, y, z."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, z)))
    zero = np.zeros(x.shape + (3,))
    stack: list[tuple[np.ndarray, np.ndarray]] = []
    with np.errstate(all="ignore"):
        for op_f, arg in program.code.reshape(-1, 2):
            op = int(op_f)
            if op == CONST:
                stack.append((np.full(x.shape, arg), zero))
            elif op <= VAR_Z:
                d = zero.copy()
                d[..., op - VAR_X] = 1.0
                stack.append(((x, y, z)[op - VAR_X], d))
            elif op == NEG:
                v, d = stack.pop()
                stack.append((-v, -d))
            elif op >= FIRST_UNARY:
                v, d = stack.pop()
                u = op - FIRST_UNARY
                stack.append((_NUMPY_UNARY[u](v), _unary_derivative(u, v)[..., None] * d))
            else:
                (b, db), (a, da) = stack.pop(), stack.pop()
                if op == ADD:
                    r = (a + b, da + db)
                elif op == SUB:
                    r = (a - b, da - db)
                elif op == MUL:
                    r = (a * b, da * b[..., None] + a[..., None] * db)
                elif op == DIV:
                    r = (a / b, (da * b[..., None] - a[..., None] * db) / (b * b)[..., None])
                elif op == POW:
                    p = np.power(a, b)
                    # b a^(b-1) a' + a^b ln(a) b'; the second term only where b varies
                    t2 = np.where((db != 0.0).any(-1), p * np.log(a), 0.0)
                    r = (p, (b * np.power(a, b - 1.0))[..., None] * da + t2[..., None] * db)
                elif op in (MIN, MAX):
                    pick_a = (a <= b) if op == MIN else (a >= b)
                    r = ((np.minimum if op == MIN else np.maximum)(a, b), np.where(pick_a[..., None], da, db))
                else:
                    den = (a * a + b * b)[..., None]
                    r = (np.arctan2(a, b), (b[..., None] * da - a[..., None] * db) / den)
                stack.append(r)
    v, d = stack[0]
    return np.asarray(v, dtype=np.float64), np.asarray(d, dtype=np.float64)


# --------------------------------------------------------------------------- POV-Ray
_POVRAY_UNARY = {name: name for name in UNARY} | {"log": "ln"}
"""POV-Ray's names of the one-argument functions (its ``log`` is base 10, ``ln`` natural)."""


def povray_function(program: Program) -> str:
    """The program as the body of a POV-Ray 3.7 ``function { }`` (its "user-defined
    functions" syntax): every operation parenthesised, ``^`` as ``pow(a, b)``, ``log`` as
    ``ln``, constants (``pi``, ``e`` included) with 17 significant digits (the float64 value
    exactly).  Read back from the postfix code, so what POV-Ray evaluates is what our
    evaluators run."""
    names = {ADD: "+", SUB: "-", MUL: "*", DIV: "/"}
    calls = {POW: "pow", MIN: "min", MAX: "max", ATAN2: "atan2"}
    stack: list[str] = []
    for op_f, arg in program.code.reshape(-1, 2):
        op = int(op_f)
        if op == CONST:
            stack.append(f"{float(arg):.17g}" if arg >= 0 else f"(-{-float(arg):.17g})")
        elif op <= VAR_Z:
            stack.append("xyz"[op - VAR_X])
        elif op == NEG:
            stack.append(f"(-{stack.pop()})")
        elif op >= FIRST_UNARY:
            stack.append(f"{_POVRAY_UNARY[UNARY[op - FIRST_UNARY]]}({stack.pop()})")
        else:
            b, a = stack.pop(), stack.pop()
            stack.append(f"({a} {names[op]} {b})" if op in names else f"{calls[op]}({a}, {b})")
    return stack[0]
