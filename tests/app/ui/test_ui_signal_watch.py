"""``workbench ui`` ends on SIGTERM even when its main thread never returns to the interpreter
(a long GL call or compile under load held it past the 5 s every-command-every-scene allows):
the watcher thread of :func:`workbench.app.ui.main.quit_on_signals`, woken through the signal
wake-up pipe, sets the quit flags and, when the loop has not ended SIGNAL_EXIT_SECONDS later,
terminates the child processes and ends the process with 128 + the signal.  The same when the
loop ended but the exit does not (a job thread inside a numba compile, which the interpreter
waits for at exit): SIGNAL_END_SECONDS after the signal."""
from __future__ import annotations

import signal
import subprocess
import sys
import time

from workbench.app.ui.main import SIGNAL_END_SECONDS, SIGNAL_EXIT_SECONDS

STUCK = r"""
import multiprocessing as mp, sys, threading, time, types
from workbench.app.ui.main import quit_on_signals

def idle():
    time.sleep(600)

if __name__ == "__main__":
    child = mp.get_context("spawn").Process(target=idle, name="ui-child")
    child.start()
    print(child.pid, flush=True)
    state = types.SimpleNamespace(quit=False, quit_signal=0)
    stuck = threading.Lock()
    stuck.acquire()
    with quit_on_signals(state):
        print("stuck", flush=True)
        stuck.acquire()   # never released: the loop never sees state.quit
"""


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except FileNotFoundError:
        return False


def _terminated_after(proc, seconds: float) -> None:
    """SIGTERM to ``proc``; it must end with 128 + SIGTERM, and not before ``seconds`` (its
    loop or its exit had that long first)."""
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=seconds + 20)
    assert proc.returncode == 128 + signal.SIGTERM
    assert time.monotonic() - t0 >= seconds - 0.5


def test_sigterm_ends_a_stuck_window_and_its_children(tmp_path):
    script = tmp_path / "stuck.py"
    script.write_text(STUCK)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        child = int(proc.stdout.readline())
        assert proc.stdout.readline().strip() == "stuck"
        _terminated_after(proc, SIGNAL_EXIT_SECONDS)
        deadline = time.monotonic() + 5
        while _alive(child) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _alive(child), "the child process was left running"
    finally:
        if proc.poll() is None:
            proc.kill()


LINGERING = r"""
import sys, threading, time, types
from workbench.app.ui.main import quit_on_signals

if __name__ == "__main__":
    state = types.SimpleNamespace(quit=False, quit_signal=0)
    job = threading.Thread(target=time.sleep, args=(600,), name="ui-job-compiling", daemon=False)
    job.start()   # cannot be cancelled, and the interpreter waits for it at exit
    with quit_on_signals(state) as closing:
        print("looping", flush=True)
        while not state.quit:
            time.sleep(0.05)
        closing.set()
"""


def test_sigterm_ends_the_process_when_a_job_thread_outlives_the_loop(tmp_path):
    script = tmp_path / "lingering.py"
    script.write_text(LINGERING)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "looping"
        _terminated_after(proc, SIGNAL_END_SECONDS)
    finally:
        if proc.poll() is None:
            proc.kill()
