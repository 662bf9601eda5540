"""Named columns of the float64 tables the numba kernels read (issue 27, item 1).

A table's columns are named by a :class:`Columns` enum: each member is the first column of a
run of ``span`` columns (``Mat.COLOR = 0, 3`` names columns 0-2, so ``Mat.COLOR + 1`` is green;
a member given one number spans one column).  Numba compiles ``tab[i, Mat.KD]`` to the same
load as a literal column.  Builders write rows by name through :func:`pack`, which refuses a
row with a column left unnamed or unset, and :func:`width` refuses a table whose runs leave a
gap or overlap.
"""
from __future__ import annotations

from enum import IntEnum

import numpy as np


class Columns(IntEnum):
    """Base of the column enums: ``NAME = first`` or ``NAME = first, span``."""

    def __new__(cls, first: int, span: int = 1):
        member = int.__new__(cls, first)
        member._value_ = first
        member.span = span
        return member


def width(columns: type[Columns]) -> int:
    """Number of columns of the table ``columns`` names; ``ValueError`` unless its runs tile
    ``0 .. width - 1`` exactly."""
    taken = sorted(c for member in columns for c in range(member, member + member.span))
    if taken != list(range(len(taken))):
        raise ValueError(f"{columns.__name__}: its runs leave a gap or overlap: columns {taken}")
    return len(taken)


def pack(columns: type[Columns], **values) -> np.ndarray:
    """One row (``width(columns)``,) of a table named by ``columns``, every member given by its
    lower-case name (a scalar, or a sequence of the member's span).  Raises ``KeyError`` on a
    missing or unknown name and ``ValueError`` on a wrong length: a column is never left at a
    silent zero."""
    given = {k.upper() for k in values}
    names = {c.name for c in columns}
    if given != names:
        raise KeyError(f"{columns.__name__}: missing {sorted(names - given)}, unknown {sorted(given - names)}")
    row = np.zeros(width(columns))
    for c in columns:
        v = np.atleast_1d(np.asarray(values[c.name.lower()], dtype=np.float64))
        if v.shape != (c.span,):
            raise ValueError(f"{columns.__name__}.{c.name}: {v.shape[0]} values for {c.span} columns")
        row[c:c + len(v)] = v
    return row


def cell(row: np.ndarray, c: Columns):
    """Member ``c``'s value in ``row`` (a table row of ``type(c)``'s columns): a float, or the
    ``(c.span,)`` run of a member that names several columns."""
    return row[c] if c.span == 1 else row[c:c + c.span]
