"""Where the Whitted ray tracer spends its trace phase: the Whitted scene's trace on 1 and 2
threads (the kernel traces whole ray trees per pixel), then the mesh scene (81,920 triangles)
on one thread: its whole trace phase against the intersection queries of the same rays alone
(``mesh``).

The Whitted scene at 640 x 480, depth 5, threshold 1/255 (as ``bench/povray_whitted.py``),
warm JIT cache, best of 3 renders per thread count.  CPU seconds over wall seconds is the
thread utilisation (2.0 = both threads busy; on a shared machine other processes lower it).

Writes ``bench/results/raytrace_profile.json`` and ``docs/benchmarks/raytrace_profile.md`` and prints
it.  Run: ``.venv/bin/python bench/raytrace_profile.py``.  ``--smoke``: 32 x 24, one render per case.
"""
from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

from _common import Page, first_paragraph, fmt, table

ROOT = Path(__file__).resolve().parents[1]
W, H = 640, 480
REPEATS = 3
def fused(threads: int, repeats: int | None = None) -> dict:
    """Best trace phase of the fused path."""
    import numba

    import workbench
    numba.set_num_threads(threads)
    repeats = repeats or REPEATS
    scene = workbench.load_scene("whitted")
    r = min((workbench.render(scene, "raytrace", width=W, height=H, threshold=1.0 / 255.0, max_depth=5)
             for _ in range(repeats)), key=lambda r: r.timings["trace"])
    return dict(threads=threads, trace_s=r.timings["trace"], trace_cpu_s=r.timings["trace_cpu"],
                total_rays=r.stats["total_rays"], mrays_per_s=r.stats["total_rays"] / r.timings["trace"] / 1e6)


def mesh_intersection(repeats: int | None = None) -> dict:
    """The mesh scene on one thread: the trace phase of a render against the intersection
    queries of its rays alone, through :func:`intersect.closest` (analytic primitives, the
    mesh's box, the 4-wide BVH) and through the BVH alone (box test + :func:`walks.bvh_hit`):
    the primary rays' closest hits, then the shadow feelers :func:`kernels.shade_hit` traces
    (:func:`_feelers`, any hit).  Best of ``repeats`` each."""
    import numba
    import numpy as np

    import workbench
    from workbench.core.tol import tol
    from workbench.renderers.kernels import intersect, walks
    from workbench.renderers.kernels.flags import NO_REFCOUNT
    from workbench.renderers.raytrace import kernels as K
    from workbench.renderers.raytrace.flatten import flatten
    from workbench.renderers.raytrace.whitted import _alloc, camera_rays
    numba.set_num_threads(1)
    repeats = repeats or REPEATS
    scene = workbench.load_scene("mesh")
    r = min((workbench.render(scene, "raytrace", width=W, height=H, threshold=1.0 / 255.0, max_depth=5)
             for _ in range(repeats)), key=lambda r: r.timings["trace"])
    sd = flatten(scene)
    geo = sd.kernel_args()
    O, D, _ = camera_rays(scene.camera, W, H, 1, 0)
    n = len(O)
    h = _alloc(n)
    K.trace_batch(geo, O, D, np.zeros(n), np.full(n, np.inf), tol.zero, tol.ray_offset, sd.extent,
                  tol.normal_cancel, False, h["t"], h["prim"], h["ng"], h["ns"], h["uv"], h["po"], h["ev"])
    fo, fd, ftmin, ftmax, want = _feelers(sd, O, D, h)
    sets = dict(primary=(O, D, np.zeros(n), np.full(n, np.inf), False),
                shadow=(fo[want], fd[want], ftmin[want], ftmax[want], True))

    @numba.njit(**NO_REFCOUNT)  # as the kernels: no reference counting (cached: a smoke run loads it)
    def queries(geo, O, D, tmin, tmax, shadow, bvh_only, extent, scr, rel_eps, zero):
        stack, st, sp_, sf, sn = scr
        node, child, leaf, first, tv4, bounds = (geo.bvh_node, geo.bvh_child, geo.bvh_leaf, geo.bvh_first,
                                                 geo.bvh_tv4, geo.bvh_bounds)
        hits = 0
        for i in range(O.shape[0]):
            ox, oy, oz, dx, dy, dz = O[i, 0], O[i, 1], O[i, 2], D[i, 0], D[i, 1], D[i, 2]
            if bvh_only:
                if walks._bounds_hit(bounds, ox, oy, oz, dx, dy, dz, tmin[i], tmax[i]):
                    t = walks.bvh_hit((node, child, leaf, first, tv4), ox, oy, oz, dx, dy, dz, tmin[i],
                                  tmax[i], shadow, stack)[0]
                    hits += t < np.inf
            else:
                eps = rel_eps * max(max(abs(ox), abs(oy), abs(oz)), extent)
                hits += intersect.closest(geo, ox, oy, oz, dx, dy, dz, tmin[i], tmax[i], shadow, shadow, True, zero,
                                  eps, stack, st, sp_, sf, sn)[1] >= 0
        return hits

    scr = numba.njit(lambda: intersect.scratch())()
    out = dict(triangles=int(len(sd.tri_v)), bvh_4wide_nodes=int(len(sd.bvh.node)),
               bvh_leaves=int(len(sd.bvh.leaf)), trace_s=r.timings["trace"], total_rays=r.stats["total_rays"])
    for name, (o, d, t0, t1, shadow) in sets.items():
        for what, bvh_only in (("closest", False), ("bvh", True)):
            queries(geo, o, d, t0, t1, shadow, bvh_only, sd.extent, scr, tol.ray_offset, tol.zero)  # compile
            best = np.inf
            for _ in range(repeats):
                c0 = time.perf_counter()
                queries(geo, o, d, t0, t1, shadow, bvh_only, sd.extent, scr, tol.ray_offset, tol.zero)
                best = min(best, time.perf_counter() - c0)
            out[f"{name}_rays"] = len(o)
            out[f"{name}_{what}_s"] = best
    inter = out["primary_closest_s"] + out["shadow_closest_s"]
    out["intersection_share_of_trace"] = inter / out["trace_s"]
    out["bvh_share_of_trace"] = (out["primary_bvh_s"] + out["shadow_bvh_s"]) / out["trace_s"]
    return out


def _feelers(sd, O, D, h):
    """The shadow feelers :func:`kernels.shade_hit` traces from the hits ``h`` (point lights
    only, as in the mesh scene): a row per (hit, light), origin pushed off the surface on the
    light's side (:func:`..kernels.optics._feeler`), ``want`` where the light faces the
    shading normal."""
    import numpy as np

    from workbench.core.tol import tol
    from workbench.renderers.kernels.columns import Light
    nl = len(sd.lights)
    P = O + h["t"][:, None] * D
    ns = np.where((np.einsum("ij,ij->i", h["ns"], D) > 0)[:, None], -h["ns"], h["ns"])
    off = tol.ray_offset * np.maximum(np.abs(P).max(1), sd.extent)
    fo, fd = np.empty((len(O), nl, 3)), np.empty((len(O), nl, 3))
    ftmin, ftmax, want = np.empty((len(O), nl)), np.empty((len(O), nl)), np.empty((len(O), nl), np.bool_)
    for li in range(nl):
        V = sd.lights[li, Light.POSITION:Light.POSITION + 3] - P
        dist = np.linalg.norm(V, axis=1)
        L = V / dist[:, None]
        side = np.where(np.einsum("ij,ij->i", h["ng"], L) >= 0, 1.0, -1.0)
        fo[:, li] = P + (side * off)[:, None] * h["ng"]
        fd[:, li], ftmax[:, li] = L, dist - 2 * off
        ftmin[:, li] = tol.t_min * np.maximum(np.abs(P).max(1), sd.extent)
        want[:, li] = (h["prim"] >= 0) & (np.einsum("ij,ij->i", ns, L) > 0)
    return fo.reshape(-1, 3), fd.reshape(-1, 3), ftmin.reshape(-1), ftmax.reshape(-1), want.reshape(-1)




def tables(res: dict) -> str:
    fu, me = res["fused"], res["mesh"]
    out = [f"Whitted scene at {res['size']}, depth 5, threshold 1/255, warm; {res['machine']}; the kernel's tasks on "
           f"{res.get('numba_threads')} Python threads at most.  No outside anchor (POV-Ray on the same scene: "
           "[povray_whitted](povray_whitted.md)).", "",
           "## Whitted scene", "",
           table(["threads", "trace (s)", "trace CPU (s)", "Mrays/s"],
                 [[f["threads"], f["trace_s"], f["trace_cpu_s"], f["mrays_per_s"]] for f in fu]),
           f"## Mesh scene ({me['triangles']} triangles), one thread", "",
           table(["rays", "count", "closest (s)", "BVH alone (s)"],
                 [[k, me[f"{k}_rays"], me[f"{k}_closest_s"], me[f"{k}_bvh_s"]] for k in ("primary", "shadow")]),
           f"Trace phase {fmt(me['trace_s'])} s; intersection share {fmt(me['intersection_share_of_trace'])}, BVH share "
           f"{fmt(me['bvh_share_of_trace'])}.", ""]
    return "\n".join(out)


PAGE = Page("raytrace_profile", "Where the Whitted ray tracer spends its trace phase", first_paragraph(__doc__),
            "python bench/raytrace_profile.py", tables, smoke_note="32 x 24, one render per case")


def main(argv=None) -> dict:
    global W, H, REPEATS
    import numba

    import workbench
    args = PAGE.parse(argparse.ArgumentParser(description=__doc__.splitlines()[0]), argv)
    if args.smoke:
        W, H, REPEATS = 32, 24, 1
    workbench.render(workbench.load_scene("whitted"), "raytrace", width=32, height=24)  # JIT / cache
    res = dict(machine=f"{os.cpu_count()} CPUs (shared); load average {os.getloadavg()[0]:.2f} at start",
               numba_threads=numba.get_num_threads(), size=f"{W}x{H}",
               fused=[fused(t) for t in (1, 2)])
    res["mesh"] = mesh_intersection()
    print(json.dumps(res, indent=2))
    return PAGE.write(args, res)


if __name__ == "__main__":
    main()
