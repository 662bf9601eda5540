"""Running a kernel's work items on several threads without numba's ``parallel=True``.

A driver compiled with ``parallel=True`` pays numba's parallel-loop passes and compiles its
loop body twice, for seconds of a first render; the drivers here are ordinary kernels compiled
with ``nogil=True`` that do work items ``c, c + n, c + 2 n, ...`` of ``n`` (a task), and
:func:`run_tasks` calls one per task on a pool of ``numba.get_num_threads()`` Python threads,
which run concurrently since the kernels release the GIL.  Each work item writes its own
pixels, so the result does not depend on the thread that ran it.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor


def run_tasks(kernel, ntasks: int, *args, per_task=None) -> None:
    """Call ``kernel(*args, *per_task(c), c, ntasks)`` for ``c = 0 .. ntasks - 1`` (``per_task``:
    the task's own arguments, its scratch arrays; none when omitted), on as many threads as
    numba is set to use (``numba.set_num_threads``), and wait for all; an exception of any
    call is raised here."""
    def task_args(c):
        return (*args, *(per_task(c) if per_task is not None else ()), c, ntasks)

    threads = max(1, min(ntasks, _numba_threads()))
    if threads == 1:
        for c in range(ntasks):
            kernel(*task_args(c))
        return
    with ThreadPoolExecutor(max_workers=threads) as pool:
        for f in [pool.submit(kernel, *task_args(c)) for c in range(ntasks)]:
            f.result()


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
