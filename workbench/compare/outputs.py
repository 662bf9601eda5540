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


def jsonable(x):
    """Recursively turn ``x`` into strict JSON data: numpy scalars to Python numbers, non-finite
    floats to the strings ``"inf"``, ``"-inf"``, ``"nan"``, unknown objects to ``str``."""
    import numpy as np
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        x = float(x)
        return x if math.isfinite(x) else ("nan" if math.isnan(x) else ("inf" if x > 0 else "-inf"))
    if x is None or isinstance(x, str):
        return x
    return str(x)


def dumps(data) -> str:
    return json.dumps(jsonable(data), indent=2, allow_nan=False)


def machine_info(gl_renderer: str | None = None) -> dict:
    """Facts needed to read the timings: CPU, cores, OS, Python and key library versions."""
    import numpy
    info = {"platform": platform.platform(), "machine": platform.machine(),
            "processor": platform.processor() or _cpu_model(), "cpu_count": os.cpu_count(),
            "python": platform.python_version(), "numpy": numpy.__version__}
    try:
        info["load_average_1min"] = os.getloadavg()[0]
    except OSError:
        pass
    info["GL_RENDERER"] = gl_renderer if gl_renderer else _gl_renderer()
    return info


def _cpu_model() -> str:
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
