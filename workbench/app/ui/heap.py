"""The window's C heap: large blocks mapped and unmapped, not kept in the malloc arenas.

glibc's malloc serves a request above its mmap threshold with a mapping of its own, returned to
the system when freed, and smaller ones from an arena (one per thread that allocates, up to
8 per core).  The threshold starts at 128 KiB but is *dynamic*: each freed mapped block raises
it to that block's size, up to 32 MiB (mallopt(3), ``M_MMAP_THRESHOLD``).  In the window, whose
job, display-mode and numba threads allocate and free images of 0.5 to 30 MB all the time, the
threshold soon sits above the images' size: they then come from the arenas, whose freed holes
between live blocks are kept, and the resident size grows with the session (issue #29, item 3).
Setting the threshold fixes it (glibc then stops adjusting it): the images are mapped again, and
the arenas keep only small blocks (the soak session before and after: docs/benchmarks/history.md,
"Memory over a long session").
"""
from __future__ import annotations

import ctypes
import ctypes.util

M_MMAP_THRESHOLD = -3
"""mallopt's parameter number of the mmap threshold (glibc's malloc.h)."""
MMAP_THRESHOLD = 256 * 1024
"""Bytes from which a block is mapped of its own: above the images of tiles and small panels'
rows, below any panel's image (a 96 x 72 panel's float32 image is 81 KiB, a 256 x 192 one's
576 KiB)."""


def map_large_blocks(threshold: int = MMAP_THRESHOLD) -> bool:
    """Fix glibc's mmap threshold at ``threshold`` bytes for this process (``mallopt``);
    returns False where the C library has no ``mallopt`` (not glibc: nothing changed)."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return mallopt(M_MMAP_THRESHOLD, int(threshold)) == 1
