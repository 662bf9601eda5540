"""The memory limit every render is checked against before it allocates.

One limit, resolved in this order:

1. ``max_memory=`` given to :func:`workbench.render` (bytes, or a size text such as ``"8G"``);
2. the environment variable ``WORKBENCH_MAX_MEMORY`` (a size text; the CLI's ``--max-memory``
   sets it for one command, so compare, study, stress, the UI's jobs and child processes see
   the same limit);
3. otherwise ``DEFAULT_FRACTION`` of the machine's physical memory (``os.sysconf``).

Sizes: a number of bytes, optionally with a binary suffix ``K``, ``M``, ``G``, ``T`` (also
``KiB``, ``KB``, ... all meaning powers of 1024), e.g. ``512M``, ``1.5G``.
"""
from __future__ import annotations

import math
import os
import re

from .errors import OverMemory, WorkbenchError

ENV = "WORKBENCH_MAX_MEMORY"
DEFAULT_FRACTION = 0.5
"""Share of physical memory a render may use when no limit is given."""
_UNITS = {"": 0, "K": 1, "M": 2, "G": 3, "T": 4}
_SIZE = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?|\.[0-9]+)\s*([KMGT]?)(?:I?B)?\s*$", re.IGNORECASE)


def parse_size(text, what: str = "memory limit") -> int:
    """Bytes of a size text (``"8G"``, ``"512MiB"``, ``"1000000"``) or a positive number."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = float(text)
    else:
        m = _SIZE.match(str(text))
        if m is None:
            raise WorkbenchError(f"{what} must be a size such as 8G, 512M or a number of bytes, got {text!r}")
        value = float(m.group(1)) * 1024 ** _UNITS[m.group(2).upper()]
    if not (math.isfinite(value) and value >= 1):
        raise WorkbenchError(f"{what} must be a positive, finite number of bytes, got {text!r}")
    return int(value)


def physical_memory() -> int:
    """Bytes of physical memory (``SC_PAGE_SIZE x SC_PHYS_PAGES``)."""
    return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))


def memory_limit(max_memory=None) -> int:
    """The limit in bytes (see the module docstring for the order of the sources)."""
    if max_memory is not None:
        return parse_size(max_memory, "max_memory")
    env = os.environ.get(ENV, "").strip()
    if env:
        return parse_size(env, ENV)
    return int(DEFAULT_FRACTION * physical_memory())


def check_limit(need: int, what: str, max_memory=None) -> None:
    """Refuse (one :class:`WorkbenchError` line) work estimated at ``need`` bytes above the limit
    (:func:`memory_limit` of ``max_memory``), before it allocates; ``what`` names the work."""
    limit = memory_limit(max_memory)
    if need > limit:
        raise OverMemory(f"{what} needs about {gib(need)} of memory, above the limit of {gib(limit)}: "
                             f"use a smaller image, or raise the limit (--max-memory, {ENV} or max_memory=)")


def gib(nbytes: float) -> str:
    """``nbytes`` for a message in the largest unit it fills: ``"412.0 MiB"``, ``"53.9 GiB"``,
    ``"1.8e+09 TiB"``, ``"1.0 KiB"``, ``"12 bytes"`` (a small limit is not shown as 0.0 MiB)."""
    for unit, power in (("TiB", 40), ("GiB", 30), ("MiB", 20), ("KiB", 10)):
        if nbytes >= 2 ** power:
            value = nbytes / 2 ** power
            return f"{value:.1f} {unit}" if value < 1e6 else f"{value:.2g} {unit}"
    return f"{int(nbytes)} bytes"
