"""Intersection rate per new object kind (blob, isosurface, lathe, prism): first hits per second
of the numba kernels of :mod:`workbench.scene.kinds`, one thread (CPU time, so that other
processes on the machine do not count), rays aimed at the object's
bounds from a sphere around it (about half of them hit); and the raster path's cost: the
tessellation's triangles and time at a few resolutions.

Writes ``bench/results/kinds_rate.json`` and ``docs/benchmarks/kinds_rate.md`` and prints it.  Run:
``NUMBA_CACHE_DIR=.numba_cache .venv/bin/python bench/kinds_rate.py [rays]`` (default 50000).
``--smoke``: 500 rays per kind, tessellation at resolution 16 only.
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np
from _common import Page, first_paragraph, table

from workbench.scene.kinds import (blob, blob_kernels, isosurface, isosurface_kernels, lathe, lathe_kernels, prism,
                                   prism_kernels)
from workbench.scene.kinds.expression import MAX_STACK

ROOT = Path(__file__).resolve().parents[1]
NPAR = 20


@nb.njit(cache=True)
def _run(code, par, aux, O, D, t_out):
    """First hit of every ray (kind ``code``: 0 blob, 1 isosurface, 2 lathe, 3 prism)."""
    out_t = np.zeros(4)
    out_f = np.zeros(4, dtype=np.int64)
    stack = np.zeros((MAX_STACK, 4))
    for i in range(O.shape[0]):
        ox, oy, oz, dx, dy, dz = O[i, 0], O[i, 1], O[i, 2], D[i, 0], D[i, 1], D[i, 2]
        if code == 0:
            t, _ = blob_kernels.first(par, 0, aux, ox, oy, oz, dx, dy, dz, 0.0, np.inf, out_t, out_f, stack)
        elif code == 1:
            t, _ = isosurface_kernels.first(par, 0, aux, ox, oy, oz, dx, dy, dz, 0.0, np.inf, out_t, out_f, stack)
        elif code == 2:
            t, _ = lathe_kernels.first(par, 0, aux, ox, oy, oz, dx, dy, dz, 0.0, np.inf, out_t, out_f, stack)
        else:
            t, _ = prism_kernels.first(par, 0, aux, ox, oy, oz, dx, dy, dz, 0.0, np.inf, out_t, out_f, stack)
        t_out[i] = t


def _objects():
    common = {"material": "m"}
    rng = np.random.default_rng(0)
    many = [{"center": list(rng.uniform(-1.5, 1.5, 3)), "radius": 0.8, "strength": 1.0} for _ in range(16)]
    iso = {"bounds": {"min": [-3, -3, -3], "max": [3, 3, 3]}}
    star = [[math.cos(a) * (1.0 if i % 2 == 0 else 0.4), math.sin(a) * (1.0 if i % 2 == 0 else 0.4)]
            for i, a in enumerate(np.linspace(0, 2 * np.pi, 11)[:-1])]
    return [
        ("blob, 3 components", 0, blob, blob.read({"threshold": 0.3, "components": [
            {"center": [0, 0, 0], "radius": 1.0}, {"center": [1.2, 0, 0], "radius": 1.0},
            {"center": [0.6, 0.8, 0], "radius": 0.7, "strength": -0.5}]}, "b", common)),
        ("blob, 16 components", 0, blob, blob.read({"threshold": 0.3, "components": many}, "b", common)),
        ("isosurface sphere", 1, isosurface, isosurface.read(
            {"function": "x^2+y^2+z^2", "threshold": 4.0, "max_gradient": 10.4, **iso}, "i", common)),
        ("isosurface torus", 1, isosurface, isosurface.read(
            {"function": "(sqrt(x^2+z^2)-2)^2+y^2", "threshold": 0.25, "max_gradient": 8.0, **iso}, "i", common)),
        ("isosurface gyroid", 1, isosurface, isosurface.read(
            {"function": "sin(x)*cos(y)+sin(y)*cos(z)+sin(z)*cos(x)", "threshold": 0.0, "max_gradient": 2.5, **iso},
            "i", common)),
        ("lathe, 6-point cup", 2, lathe, lathe.read(
            {"points": [[0, 0], [1, 0], [1.5, 2], [1.2, 2], [0.8, 0.3], [0, 0.3]]}, "l", common)),
        ("lathe, cubic spline, 6 segments", 2, lathe, lathe.read(
            {"spline": "cubic", "points": [[0.0, 2.2], [0.0, 0.0], [0.8, 0.05], [1.0, 1.0], [1.3, 2.0], [1.1, 2.1],
                                           [0.7, 1.2], [0.0, 1.0], [0.0, -1.0]]}, "l", common)),
        ("lathe, bezier, 2 segments", 2, lathe, lathe.read(
            {"spline": "bezier", "points": [[0.0, 0.0], [0.6, 0.0], [0.9, 0.5], [0.9, 1.0], [0.9, 1.0], [0.9, 1.5],
                                            [0.5, 2.0], [0.0, 2.0]]}, "l", common)),
        ("prism, 10-vertex star", 3, prism, prism.read({"polygon": star, "heights": [0, 0.5]}, "p", common)),
    ]


def _tessellate(mod, obj, res):
    if mod is prism:
        return mod.mesh(obj)
    return mod.mesh(obj, res)


def tables(res: dict) -> str:
    rows = [[r["kind"], r["rays"], r["seconds"], r["mrays_per_s"], r["hit_fraction"],
             "; ".join(f"{t['resolution']}: {t['triangles']} in {t['seconds']} s" for t in r["tessellation"])]
            for r in res["results"]]
    return (f"{res.get('threads', 1)} thread, CPU seconds.  No outside anchor: the raster path's tessellation of "
            "the same object (triangles and time per resolution) stands beside the exact intersection.\n\n"
            + table(["kind", "rays", "CPU (s)", "Mrays/s (first hits)", "hit fraction",
                     "tessellation: resolution: triangles in seconds"], rows))


PAGE = Page("kinds_rate", "Intersection rate per new object kind", first_paragraph(__doc__),
            "python bench/kinds_rate.py", tables, smoke_note="500 rays, tessellation resolution 16 only")


def main(n_rays: int = 50_000, resolutions=(16, 32, 64)) -> dict:
    rng = np.random.default_rng(1)
    rows = []
    for name, code, mod, obj in _objects():
        head, aux = mod.params(obj, 0)
        par = np.zeros((1, NPAR))
        par[0, :len(head)] = head
        lo, hi = mod.bounds(obj)
        c, r = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))
        u = rng.normal(size=(n_rays, 3))
        O = c + 3 * r * u / np.linalg.norm(u, axis=1, keepdims=True)
        D = np.ascontiguousarray(rng.uniform(lo, hi, (n_rays, 3)) - O)
        t = np.zeros(n_rays)
        _run(code, par, aux, O[:8], D[:8], t[:8])          # compile or load, outside the timing
        t0 = time.process_time()
        _run(code, par, aux, O, D, t)
        dt = time.process_time() - t0
        tess = []
        for res in resolutions:
            t1 = time.process_time()
            _, _, F = _tessellate(mod, obj, res)
            tess.append(dict(resolution=res, triangles=int(len(F)), seconds=round(time.process_time() - t1, 4)))
            if mod is prism:
                break
        rows.append(dict(kind=name, rays=n_rays, seconds=round(dt, 4), mrays_per_s=round(n_rays / dt / 1e6, 3),
                         hit_fraction=round(float(np.isfinite(t).mean()), 3), tessellation=tess))
    out = dict(bench="kinds_rate", date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               load_average=[round(x, 2) for x in os.getloadavg()], python=platform.python_version(),
               numba=nb.__version__, machine=platform.machine(), threads=1, results=rows)
    return out


def cli(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("rays", nargs="?", type=int, default=50_000, help="rays per kind")
    args = PAGE.parse(ap, argv)
    out = main(500, (16,)) if args.smoke else main(args.rays)
    print(json.dumps(out, indent=2))
    return PAGE.write(args, out)


if __name__ == "__main__":
    cli(sys.argv[1:])
