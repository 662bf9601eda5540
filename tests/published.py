"""The published reference data bundled in the repository (``references/published_references.json``:
the Cornell box measurements, Howell's view-factor catalogue, two-plate radiosity), by id.

It is part of the clone, so a test that needs an entry always has it: a missing file or id is
an error, never a skipped check."""
from __future__ import annotations

import json
from pathlib import Path

PATH = Path(__file__).resolve().parents[1] / "references" / "published_references.json"


def entries() -> dict[str, dict]:
    """Every entry, by its ``id``."""
    return {e["id"]: e for e in json.loads(PATH.read_text())}


def entry(rid: str) -> dict:
    """The entry ``rid`` (KeyError naming it when absent)."""
    found = entries()
    if rid not in found:
        raise KeyError(f"{rid!r} is not in {PATH}")
    return found[rid]
