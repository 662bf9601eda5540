"""Outside programs run with an eye on them (the ``povray`` program, the ``mitsuba`` method's
child process): :func:`run_watched` starts the program with its output going to files and,
while it runs, calls the caller's ``poll`` every :data:`POLL_SECONDS`, which reads what the
program has said so far (POV-Ray's "Rendered N of M pixels" lines, the Mitsuba child's
progress file) and passes it on to a progress callback (the window's progress bars,
:mod:`workbench.app.ui.jobs`).  An exception from ``poll`` (the window cancelled the job) ends
the program before it propagates, so a cancelled outside render stops at once instead of
running on unseen.
"""
from __future__ import annotations

import re
import subprocess
import time
from pathlib import Path

POLL_SECONDS = 0.1
"""How often a running program's output is read."""


def run_watched(cmd: list[str], folder, env: dict, timeout: float, poll=None,
                cwd=None) -> tuple[int, str, str]:
    """Run ``cmd`` (in ``cwd``, default ``folder``) with its standard output and error written
    to ``folder/stdout.log`` and ``folder/stderr.log``, calling ``poll()`` every
    :data:`POLL_SECONDS` while it runs and once after it ended; returns (exit status, output,
    error output).  Past ``timeout`` seconds the program is killed and
    :class:`subprocess.TimeoutExpired` raised; an exception from ``poll`` kills it too and
    propagates."""
    folder = Path(folder)
    out_path, err_path = folder / "stdout.log", folder / "stderr.log"
    with open(out_path, "wb") as out, open(err_path, "wb") as err:
        proc = subprocess.Popen(cmd, cwd=cwd or folder, env=env, stdout=out, stderr=err,
                                stdin=subprocess.DEVNULL)
        t0 = time.monotonic()
        try:
            while True:
                try:
                    proc.wait(POLL_SECONDS)
                    break
                except subprocess.TimeoutExpired:
                    if time.monotonic() - t0 > timeout:
                        raise subprocess.TimeoutExpired(cmd, timeout) from None
                if poll is not None:
                    poll()
            if poll is not None:
                poll()
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    return (proc.returncode, out_path.read_text(errors="replace"),
            err_path.read_text(errors="replace"))


def relay(read, on_progress, first: tuple | None = None):
    """A ``poll`` for :func:`run_watched` that passes what ``read(last)`` tells, a (phase, done,
    total, unit) given the last one told (first ``first``, told at once when given), on to
    ``on_progress`` whenever it changes; None without ``on_progress``."""
    if on_progress is None:
        return None
    told = [first]
    if first is not None:
        on_progress(*first)

    def poll():
        now = read(told[0])
        if now != told[0]:
            told[0] = now
            on_progress(*now)
    return poll


class Tail:
    """The lines a program has added to a file since the last :meth:`lines` (a line ends at
    ``\\n`` or ``\\r``: progress lines overwrite each other with ``\\r``)."""

    def __init__(self, path):
        self.path, self.offset, self.rest = Path(path), 0, ""

    def lines(self) -> list[str]:
        try:
            with open(self.path, "rb") as f:
                f.seek(self.offset)
                data = f.read()
        except OSError:
            return []
        self.offset += len(data)
        *done, self.rest = re.split(r"[\r\n]", self.rest + data.decode(errors="replace"))
        return done
