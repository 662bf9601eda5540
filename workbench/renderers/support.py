"""What a renderer supports, declared as data (issue #27, item 4).

Every renderer class carries a ``support`` table: for each scene feature of
:data:`workbench.scene.features.ALL` (the needs manifest), a :class:`Support` saying whether
the method computes it (``supported``), stands in for it (``approximated``) or does not
compute it (``left out``), with the reason.  ``RenderResult.left_out`` is a list of
:class:`Note` records (feature, status, reason) built from that table for the features a
scene uses, plus per-scene notes that depend on the scene's content or the options (an object
that tessellates to nothing, an exporter's per-material notes); code reads the records'
fields, and their printed form is ``"feature: reason"`` (``str(note)``).

``workbench methods --support`` prints the feature x method table (:func:`table_rows`).
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from types import MappingProxyType
from typing import Iterable, Mapping

from ..scene import features as ft


class Status(Enum):
    """How a method treats a feature.  ``NOT_NEEDED`` is for notes only: a feature the method
    can build but skipped because the scene does not use it (never in a support table)."""

    SUPPORTED = "supported"
    APPROXIMATED = "approximated"
    LEFT_OUT = "left out"
    NOT_NEEDED = "not needed"


@dataclass(frozen=True)
class Support:
    """One cell of a support table: the status and, unless supported, the reason."""

    status: Status
    reason: str = ""


@dataclass(frozen=True, order=True)
class Note:
    """One entry of ``RenderResult.left_out``: ``feature`` (a name of ``features.ALL``, or a
    per-scene subject such as ``"objects"``, ``"caustics"``, an object kind), why, and the
    status.  Printed as ``"feature: reason"``."""

    feature: str
    reason: str
    status: Status = Status.LEFT_OUT

    def __str__(self) -> str:
        return f"{self.feature}: {self.reason}"

    def as_dict(self) -> dict:
        """Plain data for JSON (reports, the reference cache)."""
        return {"feature": self.feature, "status": self.status.value, "reason": self.reason}

    @classmethod
    def from_dict(cls, d: Mapping) -> "Note":
        """The inverse of :meth:`as_dict`."""
        return cls(str(d["feature"]), str(d["reason"]), Status(d["status"]))


SupportTable = Mapping[str, Support]


def declare(approximated: Mapping[str, str] | None = None,
            left_out: Mapping[str, str] | None = None) -> SupportTable:
    """A complete, read-only support table: the features named in ``approximated`` and
    ``left_out`` (feature -> reason) with that status, every other feature of ``features.ALL``
    supported.  Raises ``ValueError`` for an unknown feature or one declared twice."""
    approximated, left_out = dict(approximated or {}), dict(left_out or {})
    unknown = sorted((set(approximated) | set(left_out)) - set(ft.ALL))
    twice = sorted(set(approximated) & set(left_out))
    if unknown or twice:
        raise ValueError(f"support table: unknown feature(s) {unknown}, declared twice {twice}")
    table = {}
    for f in ft.ALL:
        if f in left_out:
            table[f] = Support(Status.LEFT_OUT, left_out[f])
        elif f in approximated:
            table[f] = Support(Status.APPROXIMATED, approximated[f])
        else:
            table[f] = Support(Status.SUPPORTED)
    return MappingProxyType(table)


def notes(table: SupportTable, needs: Iterable[str],
          statuses: tuple[Status, ...] = (Status.LEFT_OUT,)) -> list[Note]:
    """The table's entries for the features in ``needs`` whose status is in ``statuses``, as
    notes, in the order of ``features.ALL``."""
    needs = set(needs)
    return [Note(f, s.reason, s.status) for f, s in table.items() if f in needs and s.status in statuses]


def used(needs: Iterable[str], left: Iterable[Note]) -> list[str]:
    """The features of ``needs`` that no note of ``left`` names (built as the scene asks), sorted."""
    gone = {n.feature for n in left}
    return sorted(f for f in needs if f not in gone)


def table_rows(tables: Mapping[str, SupportTable]) -> list[list[str]]:
    """The feature x method grid: a header row (``feature`` and the method names), then one row
    per feature of ``features.ALL`` with ``yes`` / ``approx`` / ``no`` per method."""
    mark = {Status.SUPPORTED: "yes", Status.APPROXIMATED: "approx", Status.LEFT_OUT: "no"}
    rows = [["feature", *tables]]
    for f in ft.ALL:
        rows.append([f, *(mark[t[f].status] for t in tables.values())])
    return rows


def complete(table: SupportTable, needs: Iterable[str], left: list[Note]) -> list[Note]:
    """``left`` (an exporter's per-object notes) plus the table's left-out entries for the
    features of ``needs`` that no note of ``left`` names yet."""
    named = {n.feature for n in left}
    return list(left) + [n for n in notes(table, needs) if n.feature not in named]
