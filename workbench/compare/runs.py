"""Timed runs of one method: a cold call (shader / JIT compilation happens there and is reported
apart) followed by ``repeat`` warm calls whose median wall time is *the* run time.

All timing runs happen sequentially in the calling process: on a shared 2-core machine a
parallel worker would steal a core from the run being timed.
"""
from __future__ import annotations

import statistics
import traceback
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.errors import NotApplicable, OverMemory, ShaderSourceError
from ..renderers.base import RenderResult, render
from ..scene.model import Scene


@dataclass
class MethodRun:
    """Outcome of timing one method at one setting.

    status : "ok", "not_applicable" (``reason`` says why), "over_memory" (refused before it
        allocated: its estimate is above the memory limit, ``reason`` says by how much) or
        "failed" (``reason`` holds the exception, ``trace`` the traceback).
    cold : wall time of the first call (s), includes ``compile``.
    compile : shader / JIT compile time reported by the first call (s).
    warm : wall times of the warm calls (s); ``time`` is their median (``cold - compile`` when
        ``repeat == 0``).
    """

    method: str
    options: dict[str, Any] = field(default_factory=dict)
    status: str = "ok"
    reason: str = ""
    trace: str = ""
    result: RenderResult | None = None
    cold: float = float("nan")
    compile: float = 0.0
    warm: list[float] = field(default_factory=list)

    @property
    def time(self) -> float:
        if self.warm:
            return float(statistics.median(self.warm))
        return self.cold - self.compile

    @property
    def image(self) -> np.ndarray | None:
        return None if self.result is None else self.result.image


def timed_run(scene: Scene, method: str, width: int, height: int, repeat: int = 1,
              options: dict | None = None) -> MethodRun:
    """Render ``repeat + 1`` times (first call = warm-up); never raises for a method's failure.

    A :class:`NotApplicable` gives ``status = "not_applicable"``, an :class:`OverMemory`
    ``status = "over_memory"``; a :class:`ShaderSourceError`
    (a user's GLSL does not compile) is raised: it is bad input.  Any other exception inside the
    method gives ``status = "failed"`` with its message (the report lists it instead of dying:
    a comparison of many methods must survive one broken method).
    """
    options = dict(options or {})
    run = MethodRun(method, options)
    try:
        res = render(scene, method, width=width, height=height, **options)
        run.cold, run.compile = res.timings["total"], float(res.timings.get("compile", 0.0))
        for _ in range(max(0, int(repeat))):
            res = render(scene, method, width=width, height=height, **options)
            run.warm.append(res.timings["total"])
        run.result = res
    except NotApplicable as e:
        run.status, run.reason = "not_applicable", str(e)
    except OverMemory as e:
        run.status, run.reason = "over_memory", str(e)
    except ShaderSourceError:  # the user's shader code: bad input, not a method's failure
        raise
    except Exception as e:  # noqa: BLE001 -- a method's bug is reported, not fatal
        run.status, run.reason = "failed", f"{type(e).__name__}: {e}"
        run.trace = traceback.format_exc()
    return run
