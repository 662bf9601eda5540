"""The test process's own child processes, alive or not yet reaped (Linux ``/proc``): a test
that stops an outside program checks that none is left behind."""
from __future__ import annotations

import os
from pathlib import Path


def children() -> set[int]:
    """Process ids whose parent is this process."""
    me, out = os.getpid(), set()
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:  # ended meanwhile
            continue
        if int(fields[1]) == me:
            out.add(int(d.name))
    return out
