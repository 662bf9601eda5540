"""Running a kernel's work items on several threads without numba's ``parallel=True``.

A driver compiled with ``parallel=True`` pays numba's parallel-loop passes and compiles its
loop body twice, for seconds of a first render; the drivers here are ordinary kernels compiled
with ``nogil=True`` that do work item ``c`` of ``n`` (a task), and :func:`run_tasks` runs the
tasks on ``numba.get_num_threads()`` Python threads, which run concurrently since the kernels
release the GIL.  Each work item writes its own pixels, so the result does not depend on the
thread that ran it.
"""
from __future__ import annotations

import _thread
import itertools
import threading

import numpy as np

LINE = 64
"""Bytes of a cache line (x86-64, ARMv8)."""


def run_tasks(kernel, ntasks: int, *args, per_thread=None) -> None:
    """Call ``kernel(*args, *scratch, c, ntasks)`` for ``c = 0 .. ntasks - 1`` on as many
    threads as numba is set to use (``numba.set_num_threads``), the calling thread and
    helpers started here, and wait for all; an exception
    of any call is raised here.  ``scratch = per_thread()`` (none when omitted): work arrays
    each thread makes once and hands to every task it runs, so a kernel must not expect them
    fresh.

    Each thread takes the next task number as it finishes one (a ticket counter: tasks in order,
    the expensive parts of an image shared out as they come).  The threads make their own
    scratch: made for every task by the calling thread before the threads started (a pool's
    ``submit`` of each task's arguments), the tasks' arrays kept the GIL from the second thread
    for up to a switch interval at the start of every trace (``docs/kernels.md``).  The arrays
    of each thread's scratch are copied into cache lines of their own (:func:`own_lines`)."""
    threads = max(1, min(ntasks, _numba_threads()))
    if threads == 1:
        own = own_lines(per_thread()) if per_thread is not None else ()
        for c in range(ntasks):
            kernel(*args, *own, c, ntasks)
        return
    tickets = itertools.count()  # next() of a count is atomic under the GIL
    failed = []

    def work():
        try:
            own = own_lines(per_thread()) if per_thread is not None else ()
            for c in tickets:
                if c >= ntasks or failed:
                    return
                kernel(*args, *own, c, ntasks)
        except BaseException as e:  # handed to the caller below
            failed.append(e)

    done = [threading.Event() for _ in range(threads - 1)]

    def helper(ev):
        work()
        ev.set()

    for ev in done:  # started without waiting for it to run (threading.Thread.start waits)
        _thread.start_new_thread(helper, (ev,))
    work()  # the calling thread is one of the threads: it is running already
    for ev in done:
        ev.wait()
    if failed:
        raise failed[0]


def _numba_threads() -> int:
    """``numba.get_num_threads()``, without starting numba's threading layer when it has not
    started: until then no ``numba.set_num_threads`` has been called (it starts the layer), and
    numba's documented default is ``numba.config.NUMBA_NUM_THREADS``.  Starting the layer (the
    OpenMP library and its threads, which the tasks, on Python threads, do not use) costs a
    warm render 36 ms."""
    import numba
    try:
        numba.threading_layer()
    except ValueError:  # "Threading layer is not initialized."
        return numba.config.NUMBA_NUM_THREADS
    return numba.get_num_threads()


def own_lines(x):
    """``x`` (an array, or a tuple of arrays and tuples) with every array copied into whole cache
    lines of its own (:data:`LINE`-aligned, its last line padded): the small scratch arrays two
    threads make (one-row hit records, written every ray) share no cache line.  When they
    did (numpy's allocator placed them side by side), every write of one thread evicted the
    other's line (false sharing: ``docs/kernels.md``)."""
    if isinstance(x, tuple):
        return tuple(own_lines(a) for a in x)
    if not isinstance(x, np.ndarray):
        return x
    buf = np.empty(-(-max(x.nbytes, 1) // LINE) * LINE + LINE, np.uint8)
    start = -buf.ctypes.data % LINE
    out = buf[start:start + x.nbytes].view(x.dtype).reshape(x.shape)
    out[...] = x
    return out
