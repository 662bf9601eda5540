"""Where a path-traced sample's time goes, on the Cornell box, one thread (CPU seconds; the
best of ``--repeat`` runs, so other work on the host inflates it least).

* ``sample``: CPU time per sample of :func:`workbench.renderers.pathtrace.kernels.render_samples`
  (``--size`` squared pixels, ``--spp`` samples each), its rays per sample (camera, extension,
  shadow: the kernel's counts) and mean path length;
* ``rays``: CPU time per ray of the path tracer's ``cast`` (the BVH alone when every primitive is
  a triangle, as here) and of ``cast_all`` (the ray tracer's general ``closest``: the loop over
  analytic primitives, the scene box test, then the same BVH), on a recorded set of rays like
  the path tracer's: camera rays, three cosine-sampled bounces and a shadow ray from each hit
  to a point of the light (closest-hit and any-hit apart);
* ``rng``: CPU time of one random number (:func:`..kernels.rand`) and of a path's key;
* ``accumulate``: CPU time per sample of the running sums (sum, sum of squares, finite check);
* ``pass_overhead``: wall time of a whole ``PathTraceSession.add_samples`` call on a 1x1 image
  with 1 sample (thread start, argument boxing, the dynamic-scheduling switch), per pass;
* ``shares``: the sample's time split into intersection (rays per sample x time per ray),
  RNG (random numbers per sample x their time), accumulation, and the rest (surface records,
  BSDF and light sampling, MIS, Russian roulette: the shading arithmetic).

Usage: ``PYTHONPATH=. .venv/bin/python bench/pathtrace_profile.py`` writes
``bench/results/pathtrace_profile.json`` and ``docs/benchmarks/pathtrace_profile.md`` and prints it.
``--smoke``: 8 x 8 pixels, 1 spp, one repeat, 4,096 random-number paths.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from _common import Page, first_paragraph, fmt, kv_table  # noqa: E402


def best_cpu(f, *args, repeat: int):
    """Smallest CPU time of ``repeat`` calls of ``f(*args)``, and the last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        c0 = time.process_time()
        out = f(*args)
        best = min(best, time.process_time() - c0)
    return best, out


def tables(res: dict) -> str:
    sm, ra, rg, sh = res["sample"], res["rays"], res["rng"], res["shares"]
    return (f"`{res['scene']}`, {res['size']} x {res['size']} pixels, {res['spp']} spp, {res['threads']} thread, "
            f"CPU time, best of the repeats; load {res.get('load_before')} -> {res.get('load_after')}.  No outside "
            "anchor: the ray tracer's general `closest` (`cast_all`) is the baseline of the path tracer's `cast`.\n\n"
            + kv_table([
                ("CPU time per sample (ns)", sm["cpu_ns"]),
                ("rays per sample: camera / extension / shadow",
                 f"{fmt(sm['camera_rays'])} / {fmt(sm['extension_rays'])} / {fmt(sm['shadow_rays'])}"),
                ("mean path length", sm["mean_path_length"]),
                ("closest hit per ray (ns): cast / cast_all / ratio",
                 f"{fmt(ra['cast_closest_hit_ns'])} / {fmt(ra['cast_all_closest_hit_ns'])} / "
                 f"{ra['cast_all_closest_hit_ns'] / ra['cast_closest_hit_ns']:.2f}"),
                ("any hit per ray (ns): cast / cast_all / ratio",
                 f"{fmt(ra['cast_any_hit_ns'])} / {fmt(ra['cast_all_any_hit_ns'])} / "
                 f"{ra['cast_all_any_hit_ns'] / ra['cast_any_hit_ns']:.2f}"),
                ("one random number (ns) / a path's key (ns)", f"{fmt(rg['rand_ns'])} / {fmt(rg['path_key_ns'])}"),
                ("accumulation per sample (ns)", res["accumulate_ns_per_sample"]),
                ("Python per pass (ms, best / median)",
                 f"{fmt(res['pass_overhead_ms'])} / {fmt(res.get('pass_overhead_ms_median'))}"),
                ("share: intersection", sh["intersection"]), ("share: random numbers (at most)", sh["rng_at_most"]),
                ("share: accumulation", sh["accumulate"]), ("share: shading and sampling", sh["shading_and_sampling"]),
            ]))


PAGE = Page("pathtrace_profile", "Where a path-traced sample's time goes", first_paragraph(__doc__),
            "python bench/pathtrace_profile.py", tables, smoke_note="8 x 8, 1 spp, one repeat")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--repeat", type=int, default=7)
    a = PAGE.parse(ap, argv)
    paths = 1 << 20
    if a.smoke:
        a.size, a.spp, a.repeat, paths = 8, 1, 1, 1 << 12
    nb.set_num_threads(1)
    import workbench
    from workbench.renderers.pathtrace import kernels as K
    from workbench.renderers.pathtrace.session import PathTraceSession
    from workbench.renderers.kernels.columns import PathCount
    from workbench.renderers.kernels.layout import marker_features
    from workbench.renderers.kernels.flags import NO_REFCOUNT
    # the module, not its functions: numba's cache key hashes a kernel's closure variables, and a
    # dispatcher pickles differently in every process (the cache would never hit)
    from workbench.renderers.kernels import intersect as KI

    @nb.njit(**NO_REFCOUNT)
    def record(geo, cam, em_tri, nsamp, scr, rows, O, D, TM, AH):
        """Rays like a path's: camera ray, then per hit a shadow ray to a point of emitter
        triangle 0 and a cosine-sampled bounce (three bounces at most)."""
        h_ng, h_ns, h_uv, h_po, h_ev, _ = rows
        width = int(cam[14])
        n = 0
        for p in range(width * int(cam[15])):
            i, j = p // width, p % width
            for s in range(nsamp):
                key = K.path_key(0, p, s)
                dx, dy, dz = K.camera_ray_at(cam, i, j, K.rand(key, 0), K.rand(key, 1))
                ox, oy, oz = cam[0], cam[1], cam[2]
                for b in range(3):
                    t, k, f, tri, b1, b2 = K.cast_all(geo, ox, oy, oz, dx, dy, dz, 0.0, np.inf, np.bool_(False),
                                                      1e-12, 1e-6, scr)
                    O[n, 0], O[n, 1], O[n, 2], D[n, 0], D[n, 1], D[n, 2] = ox, oy, oz, dx, dy, dz
                    TM[n], AH[n] = np.inf, 0
                    n += 1
                    if k < 0:
                        break
                    px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
                    KI.surface(geo, k, f, tri, b1, b2, px, py, pz, 1e-12, h_ng, h_ns, h_uv, h_po, h_ev, 0, scr[0])
                    nx, ny, nz = h_ng[0, 0], h_ng[0, 1], h_ng[0, 2]
                    if nx * dx + ny * dy + nz * dz > 0.0:
                        nx, ny, nz = -nx, -ny, -nz
                    ox, oy, oz = px + 1e-3 * nx, py + 1e-3 * ny, pz + 1e-3 * nz
                    su, u2 = math.sqrt(K.rand(key, 10 + 8 * b)), K.rand(key, 11 + 8 * b)
                    c0, c1, c2 = 1.0 - su, su * (1.0 - u2), su * u2
                    vx = c0 * em_tri[0, 0] + c1 * em_tri[0, 3] + c2 * em_tri[0, 6] - ox
                    vy = c0 * em_tri[0, 1] + c1 * em_tri[0, 4] + c2 * em_tri[0, 7] - oy
                    vz = c0 * em_tri[0, 2] + c1 * em_tri[0, 5] + c2 * em_tri[0, 8] - oz
                    dist = math.sqrt(vx * vx + vy * vy + vz * vz)
                    O[n, 0], O[n, 1], O[n, 2] = ox, oy, oz
                    D[n, 0], D[n, 1], D[n, 2] = vx / dist, vy / dist, vz / dist
                    TM[n], AH[n] = dist - 1e-3, 1
                    n += 1
                    dx, dy, dz = K._around(nx, ny, nz, math.sqrt(K.rand(key, 12 + 8 * b)),
                                           2.0 * math.pi * K.rand(key, 13 + 8 * b))
        return n

    @nb.njit(**NO_REFCOUNT)
    def cast_bvh(geo, O, D, TM, AH, n, any_hit, scr):
        """The path tracer's ``cast`` (every primitive a triangle: the BVH alone)."""
        bvh = (geo.bvh_node, geo.bvh_child, geo.bvh_leaf, geo.bvh_first, geo.bvh_tv4)
        hits = 0
        for q in range(n):
            if AH[q] == any_hit:
                t, k, f, tri, b1, b2 = K.cast(geo, bvh, geo.tri_prim, O[q, 0], O[q, 1], O[q, 2], D[q, 0],
                                              D[q, 1], D[q, 2], 1e-9, TM[q], np.bool_(any_hit == 1), 1e-12,
                                              1e-6, scr)
                hits += k >= 0
        return hits

    @nb.njit(**NO_REFCOUNT)
    def cast_closest(geo, O, D, TM, AH, n, any_hit, scr):
        """``cast_all``: the ray tracer's ``closest``, as every ray was cast before."""
        hits = 0
        for q in range(n):
            if AH[q] == any_hit:
                t, k, f, tri, b1, b2 = K.cast_all(geo, O[q, 0], O[q, 1], O[q, 2], D[q, 0], D[q, 1], D[q, 2],
                                                  1e-9, TM[q], np.bool_(any_hit == 1), 1e-12, 1e-6, scr)
                hits += k >= 0
        return hits

    @nb.njit(**NO_REFCOUNT)
    def rng(n, per):
        acc = 0.0
        for p in range(n):
            key = K.path_key(0, p, 3)
            acc += float(key >> np.uint64(40))
            for d in range(per):
                acc += K.rand(key, d)
        return acc

    @nb.njit(**NO_REFCOUNT)
    def accumulate(sums, sumsq, nsamp, counts):
        for p in range(sums.shape[0]):
            for s in range(nsamp):
                r, g, b = 0.25 + 1e-9 * s, 0.5, 0.125 + 1e-9 * p
                if not (math.isfinite(r) and math.isfinite(g) and math.isfinite(b)):
                    counts[PathCount.NONFINITE_SAMPLES] += 1
                    r, g, b = 0.0, 0.0, 0.0
                sums[p, 0] += r
                sums[p, 1] += g
                sums[p, 2] += b
                sumsq[p, 0] += r * r
                sumsq[p, 1] += g * g
                sumsq[p, 2] += b * b

    def work_arrays():
        return KI.scratch.py_func(), K.hit_rows()  # as render_samples makes them

    scene = workbench.load_scene("cornell")
    out = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "threads": 1, "scene": "cornell",
           "size": a.size, "spp": a.spp, "load_before": round(os.getloadavg()[0], 2)}
    PathTraceSession(scene, 8, 8).add_samples(1)  # JIT compile or cache load, apart

    def render():
        ses = PathTraceSession(scene, a.size, a.size, seed=3)
        ses.add_samples(a.spp)
        return ses
    t, ses = best_cpu(render, repeat=a.repeat)
    st = ses.stats()
    nsamp = st["samples"]
    per_sample = t / nsamp
    cam_r, ext_r, sh_r = st["camera_rays"] / nsamp, st["extension_rays"] / nsamp, st["shadow_rays"] / nsamp
    out["sample"] = {"cpu_ns": per_sample * 1e9, "camera_rays": cam_r, "extension_rays": ext_r, "shadow_rays": sh_r,
                     "mean_path_length": st["mean_path_length"], "only_bvh_triangles":
                         marker_features(ses.geo.kinds) == ("triangles",)}

    scr, rows = work_arrays()
    cap = a.size * a.size * 4 * 7
    O, D, TM, AH = np.zeros((cap, 3)), np.zeros((cap, 3)), np.zeros(cap), np.zeros(cap, np.int64)
    n = record(ses.geo, ses.cam, ses.emitters.tri, 4, scr, rows, O, D, TM, AH)
    rays = {}
    for f, label in ((cast_bvh, "cast"), (cast_closest, "cast_all")):
        f(ses.geo, O, D, TM, AH, 16, 0, scr)
        for any_hit, kind in ((0, "closest_hit"), (1, "any_hit")):
            m = int((AH[:n] == any_hit).sum())
            tr, hits = best_cpu(f, ses.geo, O, D, TM, AH, n, any_hit, scr, repeat=2 * a.repeat)
            rays[f"{label}_{kind}_ns"] = tr / m * 1e9
            rays[f"{kind}_rays"], rays[f"{kind}_hit_fraction"] = m, hits / m
    out["rays"] = rays

    rng(4, 4)
    tr, _ = best_cpu(rng, paths, 16, repeat=a.repeat)
    t_key, _ = best_cpu(rng, paths, 0, repeat=a.repeat)
    rand_ns = (tr - t_key) / (16 * paths) * 1e9
    key_ns = t_key / paths * 1e9
    # random numbers per sample: 2 (pixel) and, per surface hit, up to 8 (light choice and point,
    # roulette, lobe, direction): the kernel draws at most 8 per bounce
    bounces = ses.stats()["mean_path_length"]
    rand_per_sample = 2 + 8 * bounces
    out["rng"] = {"rand_ns": rand_ns, "path_key_ns": key_ns, "rands_per_sample_at_most": rand_per_sample}

    sums, sumsq, counts = np.zeros((a.size * a.size, 3)), np.zeros((a.size * a.size, 3)), np.zeros(8, np.int64)
    accumulate(sums[:1], sumsq[:1], 1, counts)
    ta, _ = best_cpu(accumulate, sums, sumsq, a.spp, counts, repeat=a.repeat)
    acc_ns = ta / (a.size * a.size * a.spp) * 1e9
    out["accumulate_ns_per_sample"] = acc_ns

    tiny = PathTraceSession(scene, 1, 1, seed=0)
    walls = []
    for _ in range(20 * a.repeat):
        w0 = time.perf_counter()
        tiny.add_samples(1)
        walls.append(time.perf_counter() - w0)
    out["pass_overhead_ms"] = float(np.min(walls) * 1e3)
    out["pass_overhead_ms_median"] = float(np.median(walls) * 1e3)

    isect = (cam_r + ext_r) * rays["cast_closest_hit_ns"] + sh_r * rays["cast_any_hit_ns"]
    isect_general = (cam_r + ext_r) * rays["cast_all_closest_hit_ns"] + sh_r * rays["cast_all_any_hit_ns"]
    rng_ns = key_ns + rand_per_sample * rand_ns
    total = per_sample * 1e9
    out["shares"] = {"intersection": isect / total, "rng_at_most": rng_ns / total, "accumulate": acc_ns / total,
                     "shading_and_sampling": (total - isect - rng_ns - acc_ns) / total,
                     "python_per_pass_at_256x256_16spp": out["pass_overhead_ms"] * 1e-3 / (per_sample * 256 * 256 * 16)}
    out["intersection_ns_per_sample"] = isect
    out["intersection_ns_per_sample_with_closest"] = isect_general
    out["load_after"] = round(os.getloadavg()[0], 2)
    print(json.dumps(out, indent=1))
    PAGE.write(a, out)


if __name__ == "__main__":
    main()
