"""Peak memory of a call: Python/numpy allocations (``tracemalloc``) and native ones (numba's
runtime, OpenGL drivers, LAPACK), the latter as the rise of the process's peak resident set
(``VmHWM``, reset through ``/proc/self/clear_refs``; Linux >= 4.0)."""
from __future__ import annotations

import re
import tracemalloc
from pathlib import Path

_STATUS = Path("/proc/self/status")


def _kib(key: str) -> int:
    return int(re.search(rf"{key}:\s+(\d+)", _STATUS.read_text()).group(1))


def peak_bytes(fn, *args, **kwargs) -> tuple[object, int]:
    """``(fn(*args, **kwargs), peak)``: peak = max(tracemalloc's peak, rise of the peak RSS
    above the RSS before the call), in bytes."""
    Path("/proc/self/clear_refs").write_text("5")   # VmHWM := VmRSS
    rss0 = _kib("VmRSS")
    tracemalloc.start()
    try:
        out = fn(*args, **kwargs)
        _, traced = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    native = (_kib("VmHWM") - rss0) * 1024
    return out, max(traced, native)
