"""Writing report folders: strict JSON, machine facts, and all-or-nothing publication.

A report is first written into a hidden staging folder inside the output folder; only when
every file is complete are they moved into place (``os.replace``, atomic per file), the
summary files (``report.json`` / ``report.html`` ...) last.  An error on the way leaves the
previous report untouched and no half-written file behind.
"""
from __future__ import annotations

import json
import math
import os
import platform
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path


NONFINITE = {"inf": float("inf"), "-inf": float("-inf"), "nan": float("nan")}


def jsonable(x, strict: bool = True):
    """Recursively turn ``x`` into plain Python data: numpy scalars to Python numbers, unknown
    objects to ``str``.  Non-finite floats (a PSNR of an exact match is ``inf``) become the
    strings ``"inf"``, ``"-inf"``, ``"nan"`` when ``strict`` (what JSON files hold: strict JSON
    has no such tokens) and stay floats otherwise (what functions return, so callers format
    and compare numbers, never strings).  :func:`loads` is the inverse for files."""
    import numpy as np
    if isinstance(x, dict):
        return {str(k): jsonable(v, strict) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v, strict) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist(), strict)
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        x = float(x)
        if math.isfinite(x) or not strict:
            return x
        return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if x is None or isinstance(x, str):
        return x
    return str(x)


def dumps(data) -> str:
    """Strict JSON text of ``data`` (non-finite floats as strings, see :func:`jsonable`)."""
    return json.dumps(jsonable(data), indent=2, allow_nan=False)


def loads(text: str):
    """Data of a JSON file written by :func:`dumps`, with ``"inf"``, ``"-inf"`` and ``"nan"``
    read back as floats."""
    def back(x):
        if isinstance(x, dict):
            return {k: back(v) for k, v in x.items()}
        if isinstance(x, list):
            return [back(v) for v in x]
        return NONFINITE.get(x, x) if isinstance(x, str) else x
    return back(json.loads(text))


def machine_info(gl_renderer: str | None = None) -> dict:
    """Facts needed to read the timings: CPU, cores, OS, Python and key library versions."""
    import numpy
    info = {"platform": platform.platform(), "machine": platform.machine(),
            "processor": platform.processor() or cpu_model(), "cpu_count": os.cpu_count(),
            "python": platform.python_version(), "numpy": numpy.__version__}
    try:
        info["load_average_1min"] = os.getloadavg()[0]
    except OSError:
        pass
    info["GL_RENDERER"] = gl_renderer if gl_renderer else _gl_renderer()
    return info


def cpu_model() -> str:
    """The CPU's model name from ``/proc/cpuinfo``, ``"unknown"`` where there is none."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def _gl_renderer() -> str:
    try:
        from ..renderers import gl
        return gl.renderer_name()
    except Exception as e:  # noqa: BLE001 -- a missing GL stack is a fact to report
        return f"unavailable ({type(e).__name__}: {e})"


@contextmanager
def staged(out_dir: str | Path, last: tuple[str, ...] = ()):
    """Yield a staging folder; on success move its files into ``out_dir`` (``last`` ones last).

    Sub-folders are kept (``images/x.png`` lands in ``out_dir/images/x.png``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(dir=out, prefix=".staging-"))
    try:
        yield stage
        files = sorted(p for p in stage.rglob("*") if p.is_file())
        files.sort(key=lambda p: p.relative_to(stage).as_posix() in last)
        for p in files:
            dest = out / p.relative_to(stage)
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(p, dest)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
