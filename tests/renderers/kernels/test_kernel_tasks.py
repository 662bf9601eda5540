"""``kernels.tasks.run_tasks`` runs its tasks on as many threads as numba is set to use (the
calling thread among them): the count ``numba.set_num_threads`` sets, else
``NUMBA_NUM_THREADS`` (read without starting numba's threading layer, which the tasks do not
use); an exception of a task is raised to the caller; each thread makes its scratch once."""
from __future__ import annotations

import os
import subprocess
import sys
import threading

import numba
import numpy as np

from workbench.renderers.kernels.tasks import run_tasks


def _threads_used(ntasks: int) -> set[int]:
    seen = set()

    def task(c, n):
        seen.add(threading.get_ident())
        threading.Event().wait(0.01)  # long enough for a pool's other thread to take a task

    run_tasks(task, ntasks)
    return seen


def test_set_num_threads_is_honoured():
    saved = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        assert _threads_used(6) == {threading.get_ident()}   # one thread: this one, no pool
        if numba.config.NUMBA_NUM_THREADS >= 2:
            numba.set_num_threads(2)
            used = _threads_used(6)                           # this thread and at most one helper
            assert threading.get_ident() in used and 1 <= len(used) <= 2
    finally:
        numba.set_num_threads(saved)


def test_the_default_count_does_not_start_numba_threading_layer():
    code = ("import threading, numba\n"
            "from workbench.renderers.kernels.tasks import run_tasks\n"
            "seen = set()\n"
            "run_tasks(lambda c, n: (seen.add(threading.get_ident()), threading.Event().wait(0.01)), 4)\n"
            "try:\n"
            "    numba.threading_layer(); print('started')\n"
            "except ValueError:\n"
            "    print(threading.get_ident() in seen, len(seen) <= 2)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "NUMBA_NUM_THREADS": "2"})
    assert p.returncode == 0, p.stderr[-2000:]
    assert p.stdout.strip() == "True True"   # this thread and a helper (NUMBA_NUM_THREADS), the layer not started


def test_a_task_exception_reaches_the_caller_and_scratch_is_made_per_thread():
    saved = numba.get_num_threads()
    made = []

    def scratch():
        made.append(1)
        return (bytearray(8),)

    def task(scr, c, n):
        threading.Event().wait(0.005)
        if c == 3:
            raise ValueError("task 3")

    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            made.clear()
            try:
                run_tasks(task, 8, per_thread=scratch)
            except ValueError as e:
                assert str(e) == "task 3"
            else:
                raise AssertionError("the task's exception was not raised")
            assert 1 <= len(made) <= threads
    finally:
        numba.set_num_threads(saved)


def test_each_threads_scratch_has_cache_lines_of_its_own():
    from workbench.renderers.kernels.tasks import LINE, own_lines
    a = (np.arange(6.0).reshape(2, 3), (np.zeros(0), np.ones((0, 1))), np.zeros((1, 7), np.int64), 5)
    b = own_lines(a)
    assert np.array_equal(b[0], a[0]) and b[0].flags.c_contiguous and b[0].flags.writeable
    assert b[1][0].shape == (0,) and b[1][1].shape == (0, 1) and b[3] == 5
    assert b[2].dtype == np.int64 and b[2].shape == (1, 7)
    for x in (b[0], b[2]):
        assert x.ctypes.data % LINE == 0 and x.ctypes.data != a[0].ctypes.data
        end = x.ctypes.data + -(-x.nbytes // LINE) * LINE      # its last line is its own too
        assert x.base.ctypes.data <= x.ctypes.data and x.base.ctypes.data + x.base.nbytes >= end
