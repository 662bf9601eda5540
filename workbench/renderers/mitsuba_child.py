"""The child process of the ``mitsuba`` method: ``python -m workbench.renderers.mitsuba_child FOLDER``.

Reads ``FOLDER/plan.json`` (``variant``, ``scene`` = the exporter's dictionary, ``passes`` =
a list of ``[spp, seed]``), renders each pass with ``mi.render`` and writes ``passes.npy``
((P, H, W, 3) float32, one image per pass) and ``result.json`` (timings).  Mitsuba is only
ever imported here: ``mi.set_variant`` is process-wide state, and an LLVM back end that
aborts takes only this process down.

While it runs it keeps ``FOLDER/progress.txt`` (replaced whole, never half written) saying
how far it is (:func:`report`): ``load`` while Mitsuba loads the scene, then ``render N``
with N the samples per pixel done over all passes.  Within a pass only the scalar variants
report (Mitsuba's progress reporter, block by block, heard at log level Info through
:class:`ProgressAppender`); a JIT variant (``llvm_*``) renders a pass as one kernel and
reports nothing until it ends.
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np


def to_mitsuba(value, mi):
    """The exporter's plain dictionary with every ``to_world`` 4x4 list made a
    ``mi.ScalarTransform4f`` (recursively)."""
    if isinstance(value, dict):
        return {k: (mi.ScalarTransform4f(v) if k == "to_world" else to_mitsuba(v, mi)) for k, v in value.items()}
    return value


def peak_rss_bytes() -> int | None:
    """This process's peak resident set (Linux ``VmHWM``; unlike ``getrusage``'s ``ru_maxrss`` it
    does not carry the parent's peak across ``exec``), or None where /proc is absent."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


REPORT_SECONDS = 0.1
"""Least time between two progress reports within a pass."""


def report(folder: str, text: str) -> None:
    """``FOLDER/progress.txt`` now says ``text`` (written beside it, then renamed over it)."""
    path = os.path.join(folder, "progress.txt")
    with open(path + ".new", "w", encoding="ascii") as f:
        f.write(text)
    os.replace(path + ".new", path)


def progress_appender(mi, folder: str, done: list):
    """A Mitsuba log appender that reports the render's progress (``render N``, ``done[0]``
    the samples per pixel of the passes before, ``done[1]`` this pass's) and passes warnings
    and errors on to standard error."""
    class ProgressAppender(mi.Appender):
        last = 0.0

        def append(self, level, text):
            if level >= mi.LogLevel.Warn:
                print(text, file=sys.stderr, flush=True)

        def log_progress(self, progress, name, formatted, eta, ptr=None):
            now = time.perf_counter()
            if now - self.last >= REPORT_SECONDS or progress >= 1.0:
                self.last = now
                report(folder, f"render {done[0] + float(progress) * done[1]:.6g}")
    return ProgressAppender()


def main(folder: str) -> None:
    with open(os.path.join(folder, "plan.json"), encoding="utf-8") as f:
        plan = json.load(f)
    t0 = time.perf_counter()
    import mitsuba as mi
    mi.set_variant(plan["variant"])
    t_import = time.perf_counter() - t0
    report(folder, "load")
    t0 = time.perf_counter()
    scene = mi.load_dict(to_mitsuba(plan["scene"], mi))
    t_load = time.perf_counter() - t0
    done = [0, 0]  # spp of the passes before, of this pass
    logger = mi.logger()
    logger.clear_appenders()
    logger.add_appender(progress_appender(mi, folder, done))
    logger.set_log_level(mi.LogLevel.Info)  # the progress reporter's level
    images, times = [], []
    cpu0 = time.process_time()
    report(folder, "render 0")
    for spp, seed in plan["passes"]:
        t0 = time.perf_counter()
        done[1] = int(spp)
        images.append(np.asarray(mi.render(scene, spp=int(spp), seed=int(seed)), dtype=np.float32))
        times.append(time.perf_counter() - t0)
        done[0] += int(spp)
        report(folder, f"render {done[0]}")
    cpu = time.process_time() - cpu0
    np.save(os.path.join(folder, "passes.npy"), np.stack(images))
    peak = peak_rss_bytes()
    with open(os.path.join(folder, "result.json"), "w", encoding="utf-8") as f:
        json.dump({"import": t_import, "load": t_load, "passes": times, "cpu": cpu, "peak_rss_bytes": peak,
                   "mitsuba_version": mi.__version__}, f)


if __name__ == "__main__":
    main(sys.argv[1])
