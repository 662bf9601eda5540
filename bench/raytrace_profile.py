"""Where the Whitted ray tracer spends its trace phase, on 1 and 2 threads: the fused kernel
(whole ray trees per pixel, the path the Whitted scene takes) against the wavefront path
(the path of scenes with numpy textures), whose numba kernels are timed against the numpy glue
between ray generations, per generation.

The Whitted scene at 640 x 480, depth 5, threshold 1/255 (as ``bench/povray_whitted.py``),
warm JIT cache, best of 3 renders per thread count and path.  For the wavefront runs the
Whitted scene is sent down the wavefront path (``whitted.fused_textures`` answers None) and
the kernels of :mod:`workbench.renderers.raytrace.kernels` are wrapped (in this process only)
by timers that record wall and CPU seconds of each call; ``glue`` is the trace phase minus
the kernels.
CPU seconds over wall seconds of a kernel is its thread utilisation (2.0 = both threads busy;
on a shared machine other processes lower it).

Writes ``bench/results/raytrace_profile.json`` and prints it.  Run:
``.venv/bin/python bench/raytrace_profile.py``.
"""
from __future__ import annotations

import json
import os
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
W, H = 640, 480
KERNELS = ("trace_batch", "shade_batch", "compact", "accumulate", "column_sums")


def _instrument(kernels, whitted, log):
    """Wrap the kernels and the band tracer so that each kernel call is logged as
    ``(kernel, generation, rays, wall_s, cpu_s)``."""
    state = {"gen": -1}
    for name in KERNELS:
        f = getattr(kernels, name)

        def timed(*a, _f=f, _n=name):
            if _n == "trace_batch":
                state["gen"] += 1
            t0, c0 = time.perf_counter(), time.process_time()
            r = _f(*a)
            log.append((_n, state["gen"], len(a[1]) if _n != "column_sums" else len(a[0]),
                        time.perf_counter() - t0, time.process_time() - c0))
            return r
        timed.signatures = f.signatures
        setattr(kernels, name, timed)
    band = whitted._Tracer.trace

    def trace(self, *a, **k):
        state["gen"] = -1
        return band(self, *a, **k)
    whitted._Tracer.trace = trace


def fused(threads: int, repeats: int = 3) -> dict:
    """Best trace phase of the fused path."""
    import numba

    import workbench
    numba.set_num_threads(threads)
    scene = workbench.load_scene("whitted")
    r = min((workbench.render(scene, "raytrace", width=W, height=H, threshold=1.0 / 255.0, max_depth=5)
             for _ in range(repeats)), key=lambda r: r.timings["trace"])
    return dict(threads=threads, trace_s=r.timings["trace"], trace_cpu_s=r.timings["trace_cpu"],
                total_rays=r.stats["total_rays"], mrays_per_s=r.stats["total_rays"] / r.timings["trace"] / 1e6)


def profile(threads: int, repeats: int = 3) -> dict:
    import numba

    import workbench
    numba.set_num_threads(threads)
    scene = workbench.load_scene("whitted")
    best = None
    for _ in range(repeats):
        r = workbench.render(scene, "raytrace", width=W, height=H, threshold=1.0 / 255.0, max_depth=5)
        log = LOG[:]
        LOG.clear()
        if best is None or r.timings["trace"] < best[0].timings["trace"]:
            best = (r, log)
    r, log = best
    kern = {n: dict(wall_s=sum(x[3] for x in log if x[0] == n), cpu_s=sum(x[4] for x in log if x[0] == n))
            for n in KERNELS}
    gens = sorted({x[1] for x in log})
    per_gen = [dict(generation=g + 1, rays=sum(x[2] for x in log if x[1] == g and x[0] == "trace_batch"),
                    trace_batch_s=sum(x[3] for x in log if x[1] == g and x[0] == "trace_batch"),
                    shade_batch_s=sum(x[3] for x in log if x[1] == g and x[0] == "shade_batch"))
               for g in gens]
    k_wall = sum(v["wall_s"] for v in kern.values())
    return dict(threads=threads, trace_s=r.timings["trace"], trace_cpu_s=r.timings["trace_cpu"],
                mrays_per_s=r.stats["total_rays"] / r.timings["trace"] / 1e6,
                kernels=kern, kernels_wall_s=k_wall, glue_wall_s=r.timings["trace"] - k_wall,
                glue_share=(r.timings["trace"] - k_wall) / r.timings["trace"],
                utilisation={n: v["cpu_s"] / max(v["wall_s"], 1e-9) for n, v in kern.items()
                             if n in ("trace_batch", "shade_batch")},
                per_generation=per_gen)


LOG: list = []


def main() -> dict:
    import numba

    import workbench
    from workbench.renderers.raytrace import kernels, whitted
    workbench.render(workbench.load_scene("whitted"), "raytrace", width=32, height=24)  # JIT / cache
    res = dict(machine=f"{os.cpu_count()} CPUs (shared); load average {os.getloadavg()[0]:.2f} at start",
               numba_threading_layer=numba.threading_layer(), size=f"{W}x{H}",
               fused=[fused(t) for t in (1, 2)])
    whitted.fused_textures = lambda scene, sd: None  # the wavefront path from here on
    workbench.render(workbench.load_scene("whitted"), "raytrace", width=32, height=24)
    _instrument(kernels, whitted, LOG)
    res["wavefront"] = [profile(t) for t in (1, 2)]
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "raytrace_profile.json").write_text(json.dumps(res, indent=2))
    print(json.dumps(res, indent=2))
    return res


if __name__ == "__main__":
    main()
