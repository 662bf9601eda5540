"""Radiosity benchmark on the Cornell box (published geometry).

Parts (each in its own process, so that peak memory is its own):

* ``full``: ~2,000 patches: hemicube form factors for every patch + direct LU solve (target
  <= 15 s); then progressive refinement timed until it is within 1 % (area-weighted RMS over
  the reflecting patches) of the converged solution (target <= 3 s): on the stored matrix
  (solver time only); with one hemicube per shot and no matrix (hemicubes included;
  overshooting 1.2, the method's default, with and without the ambient term, and plain
  shooting; the reference is the exact solution of the system shooting solves,
  F_ji = F_ij A_i / A_j, whose distance to the gathering solution is reported too); and with
  ray-cast rows (no GL; the reference is the direct solution of their own gathering system).
  Each run also reports its error against the hemicube matrix's direct solution when it
  reaches 1 %.
* ``pvf``: pyviewfactor (exact, unoccluded) on a sample of the same patch pairs, as the
  outside reference: its cost per pair and the hemicube's (and the analytic method's) error
  against it.  Pairs are taken in the empty room (walls, floor, ceiling: a convex enclosure,
  where unoccluded = exact) at the same patch size.
* ``big``: ~10,000 patches, progressive refinement without the matrix (peak memory).

Matrix-free progressive refinement keeps at most 128 MB of rows (float32) of patches that
shoot again (:class:`~workbench.renderers.radiosity.solvers.RowCache`, least recently used
dropped first): 18 MB holds all 2,120 rows of the Cornell box, 3,200 of the 10,341 rows of
the big case.

Usage: ``.venv/bin/python bench/radiosity_cornell.py [--quick]`` writes
``bench/results/radiosity_cornell.json`` and ``docs/benchmarks/radiosity_cornell.md`` and prints it.
Without pyviewfactor the ``pvf`` part is skipped.  ``--smoke``: about 100 patches (200 for ``big``),
16-pixel hemicubes, 20 pairs, a 2-second limit.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from _common import Page, first_paragraph, fmt, kv_table, ratio, skip_note, table  # noqa: E402


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def rel_errors(B, ref, areas, reflecting):
    """Errors on the reflecting (non-emitting) patches, all channels: (area-weighted RMS
    error / area-weighted RMS of ref, max |error| / max |ref|).  Emitters are left out: they
    are exact from the first shot and would swamp both norms."""
    d, r, a = (B - ref)[reflecting], ref[reflecting], areas[reflecting, None]
    rms = np.sqrt((a * d * d).sum() / (a * r * r).sum())
    return float(rms), float(np.abs(d).max() / np.abs(r).max())


#: overrelaxation of matrix-free progressive refinement: the radiosity method's default
RELAX = 1.2


def _progressive(make_rows, A, E, R, ambient, relax, conv, direct, refl, trace=None) -> dict:
    """Matrix-free progressive refinement timed until the shown radiosity (with the ambient
    term if ``ambient``) is within 1 % (area-weighted RMS, then max) of ``conv``; the time
    spent measuring the error is left out, the time ``make_rows()`` takes to set up the row
    provider (hemicube buffers, BVH) is in.  ``make_rows() -> (row, source)``.

    Also the process's CPU time (all threads: ours, llvmpipe's, numba's) to the same point:
    on a shared machine the wall time swings with the load; the CPU time much less."""
    from workbench.renderers.radiosity import solvers
    state = {"spent": 0.0, "cpu_spent": 0.0, "t_hit": None, "cpu_hit": None, "shots_hit": None,
             "t_hit_max": None, "direct": None}
    cpu_start = time.process_time()
    t_start = time.perf_counter()
    row, source = make_rows()
    setup = time.perf_counter() - t_start

    def on_batch(B, dB, shots):
        tc = time.perf_counter()
        cc = time.process_time()
        shown = B + R * solvers._ambient(dB, R, A) if ambient else B
        rms, mx = rel_errors(shown, conv, A, refl)
        el = tc - t_start - state["spent"]
        if trace is not None:
            trace.append((el, shots, rms, mx))
        if state["t_hit"] is None and rms <= 0.01:
            state["t_hit"], state["shots_hit"] = el, shots
            state["cpu_hit"] = cc - cpu_start - state["cpu_spent"]
            state["direct"] = rel_errors(shown, direct, A, refl)
        if state["t_hit_max"] is None and mx <= 0.01:
            state["t_hit_max"] = el
        state["spent"] += time.perf_counter() - tc
        state["cpu_spent"] += time.process_time() - cc
        if state["t_hit_max"] is not None and state["t_hit"] is not None:
            raise StopIteration

    cache = solvers.RowCache(row, 128.0)
    try:
        solvers.progressive_rows(cache, A, E, R, tol=1e-6, q=float(R.max()), ambient=ambient,
                                 on_batch=on_batch, time_limit=60.0, relax=relax)
    except StopIteration:
        pass
    d = state["direct"] or (None, None)
    return {"relax": relax, "source": source, "setup_seconds": setup,
            "seconds_to_1pct_rms": state["t_hit"], "cpu_seconds_to_1pct_rms": state["cpu_hit"],
            "shots_to_1pct_rms": state["shots_hit"], "seconds_to_1pct_max": state["t_hit_max"],
            "rows_computed": cache.computed, "row_cache_hits": cache.hits,
            "at_1pct_rms_error_vs_gathering_direct": {"rms_rel": d[0], "max_rel": d[1]},
            "target_seconds": 3.0}


def _setup(count):
    import workbench
    from workbench.renderers.radiosity.patches import patch_size_for_count, patches_from_scene
    from workbench.renderers import gl
    scene = workbench.load_scene("cornell")
    h = patch_size_for_count(scene, count)
    patches, _ = patches_from_scene(scene, h)
    gl.context()
    return scene, patches, h


def part_full(count: int, res: int) -> dict:
    from workbench.renderers.radiosity.formfactors import compute
    from workbench.renderers.radiosity.hemicube import Hemicube
    from workbench.renderers.radiosity import solvers
    from workbench.renderers import gl
    scene, p, h = _setup(count)
    base_mb = peak_mb()
    g = p.geometry()
    E, R, A = p.emission, p.reflectance, g.areas
    refl = E.max(1) == 0
    # shader compile, first draw and the numba kernels' (cached) loading, apart
    warm = Hemicube(g, 8)
    warm.rows([0])
    warm.release()
    solvers.progressive_rows(lambda i: np.zeros((len(i), len(A))), A, E, R, max_shots=1)
    t0 = time.perf_counter()
    ff = compute(g, "hemicube", res)
    t_ff = time.perf_counter() - t0
    t1 = time.perf_counter()
    direct = solvers.solve(ff.F, E, R, "direct")
    t_solve = time.perf_counter() - t1
    out = {"patches": len(p), "patch_size_mm": h, "hemicube_resolution": res,
           "gl_renderer": gl.renderer_name(), "form_factor_seconds": t_ff,
           "direct_solve_seconds": t_solve, "hemicube_plus_direct_seconds": t_ff + t_solve,
           "target_seconds": 15.0, "form_factors": ff.report(),
           "direct_message": direct.message, "peak_rss_mb_full_matrix": peak_mb(),
           "rss_mb_before_matrix": base_mb}
    # progressive: the converged solution of the system shooting solves (F'_ji = F_ij A_i/A_j)
    Fs = (A[:, None] * ff.F).T / np.where(A > 0, A, 1.0)[:, None]
    conv = solvers.solve(Fs, E, R, "direct").radiosity
    del Fs
    trace = []
    runs = (("with_ambient", True, RELAX), ("without_ambient", False, RELAX),
            ("plain_shooting_with_ambient", True, 1.0))
    for key, ambient, relax in runs:
        made = []

        def make_rows():
            made.append(Hemicube(g, res))
            return made[0].rows, "hemicube"

        out[f"progressive_{key}"] = _progressive(
            make_rows, A, E, R, ambient, relax, conv, direct.radiosity, refl,
            trace if key == "with_ambient" else None)
        out[f"progressive_{key}"]["hemicubes_drawn"] = made[0].drawn
        made[0].release()
    # ray-cast rows (receivers' exact factors x visibility): the gathering system, no GL
    from workbench.renderers.radiosity.raycast import RayRows
    rr = RayRows(g)
    rr.rows([0])                                   # numba (cached) loading, apart
    t0 = time.perf_counter()
    rows_all = rr.rows(np.arange(len(A)))
    t_rows = time.perf_counter() - t0
    Fg = (rows_all * A[:, None]).T / np.where(A > 0, A, 1.0)[:, None]
    del rows_all
    conv_ray = solvers.solve(Fg, E, R, "direct").radiosity
    del Fg
    out["progressive_raycast_rows_with_ambient"] = dict(
        _progressive(lambda: (RayRows(g).rows, "raycast"), A, E, R, True, RELAX, conv_ray,
                     direct.radiosity, refl),
        rays_per_patch_triangle=4 ** rr.level, all_rows_seconds=t_rows,
        converged_solution_vs_gathering_direct=dict(zip(("rms_rel", "max_rel"),
                                                        rel_errors(conv_ray, direct.radiosity, A, refl))),
        note="reference: the direct solution of the ray-cast rows' own (gathering) system; "
             "'at_1pct_rms_error_vs_gathering_direct' is against the hemicube matrix's direct "
             "solution")
    # progressive refinement on the stored matrix (numba shooting kernel), timed in chunks
    from workbench.renderers.radiosity.kernels import shoot
    Fc = np.ascontiguousarray(ff.F)
    B, dB = E.copy(), E.copy()
    hist = np.zeros(100)
    shoot(Fc, A, R, B.copy(), dB.copy(), 1, 0.0, hist)          # JIT (cached) warm-up
    spent, shots, t_hit = 0.0, 0, None
    t_start = time.perf_counter()
    while shots < 200 * len(A):
        shots += shoot(Fc, A, R, B, dB, 100, 0.0, hist)
        tc = time.perf_counter()
        if rel_errors(B, direct.radiosity, A, refl)[0] <= 0.01:
            t_hit = tc - t_start - spent
            break
        spent += time.perf_counter() - tc
    out["progressive_on_stored_matrix"] = {
        "seconds_to_1pct_rms": t_hit, "shots_to_1pct_rms": shots, "target_seconds": 3.0,
        "note": "shooting with the stored hemicube matrix (F_ji read directly), error against "
                "the direct solution; form-factor time not included"}
    del Fc
    out["progressive_trace_with_ambient"] = [
        {"seconds": t, "shots": s, "rms_rel": r, "max_rel": m} for t, s, r, m in trace[::max(1, len(trace) // 25)]]
    out["shooting_vs_gathering_solution"] = dict(zip(("rms_rel", "max_rel"),
                                                     rel_errors(conv, direct.radiosity, A, refl)))
    out["peak_rss_mb"] = peak_mb()
    return out


def part_pvf(count: int, res: int, pairs: int) -> dict:
    import pyvista as pv
    import pyviewfactor as pvf
    import workbench
    from workbench.renderers.radiosity.formfactors import analytic_pairs, compute, point_polygon
    from workbench.renderers.radiosity.patches import patches_from_scene, patch_size_for_count
    scene = workbench.load_scene("cornell")
    h = patch_size_for_count(scene, count)
    room = [o for o in scene.objects if "block" not in o.name]
    from dataclasses import replace
    empty = replace(scene, objects=tuple(room), lights=())
    p, _ = patches_from_scene(empty, h)
    g = p.geometry()
    t0 = time.perf_counter()
    ff = compute(g, "hemicube", res)
    t_hc = time.perf_counter() - t0
    rng = np.random.default_rng(0)
    # facing pairs (each centre in front of the other): visible in the convex room
    n = len(g)
    I = rng.integers(0, n, pairs * 4)
    J = rng.integers(0, n, pairs * 4)
    c, N = g.centres, g.normals
    ok = (I != J) & (((c[J] - c[I]) * N[I]).sum(1) > 0) & (((c[I] - c[J]) * N[J]).sum(1) > 0)
    I, J = I[ok][:pairs], J[ok][:pairs]
    cells = [pv.PolyData(np.asarray(poly[:3] if np.allclose(poly[3], poly[2]) else poly),
                         faces=[3, 0, 1, 2] if np.allclose(poly[3], poly[2]) else [4, 0, 1, 2, 3])
             for poly in g.polygons]
    pvf.compute_viewfactor(cells[J[0]], cells[I[0]])          # JIT warm-up, apart
    t0 = time.perf_counter()
    ref = np.array([pvf.compute_viewfactor(cells[j], cells[i]) for i, j in zip(I, J)])
    t_pvf = time.perf_counter() - t0
    analytic_pairs(g, I[:1], J[:1], order=8)                  # JIT warm-up, apart
    t0 = time.perf_counter()
    an = analytic_pairs(g, I, J, order=8)
    t_an = time.perf_counter() - t0
    hc = ff.F[I, J]
    # what the hemicube estimates: the exact factor from patch i's centre (no area average)
    centre = np.array([point_polygon(c[i:i + 1], N[i:i + 1], g.polygons[j])[0] for i, j in zip(I, J)])
    big = ref > 1e-4
    def stats(x, ref=ref):
        d = x - ref
        return {"mean_abs": float(np.abs(d).mean()), "max_abs": float(np.abs(d).max()),
                "mean_rel_signed_F>1e-4": float(np.mean(d[big] / ref[big])),
                "median_rel_F>1e-4": float(np.median(np.abs(d[big]) / ref[big])),
                "p95_rel_F>1e-4": float(np.percentile(np.abs(d[big]) / ref[big], 95))}
    return {"room_patches": n, "pairs": int(len(I)), "pyviewfactor_version": pvf.__version__,
            "pyviewfactor_seconds_per_pair": t_pvf / len(I),
            "pyviewfactor_seconds_full_matrix_estimate": t_pvf / len(I) * n * (n - 1),
            "analytic_seconds_per_pair": t_an / len(I),
            "hemicube_seconds_full_matrix": t_hc, "hemicube_seconds_per_pair": t_hc / (n * n),
            "hemicube_vs_pyviewfactor": stats(hc), "analytic_vs_pyviewfactor": stats(an),
            "centre_point_exact_vs_pyviewfactor": stats(centre),
            "hemicube_vs_centre_point_exact": stats(hc, centre),
            "hemicube_row_sum_range": [float(ff.row_sums.min()), float(ff.row_sums.max())],
            "note": "sampled pairs (all pairs would take the estimate above); pyviewfactor is "
                    "unoccluded, so pairs come from the empty room (convex, open at the front: "
                    "row sums < 1), same patch size.  The hemicube estimates the factor from "
                    "patch i's centre: 'hemicube_vs_centre_point_exact' is its aliasing error, "
                    "'centre_point_exact_vs_pyviewfactor' the proximity (point vs area) error"}


def part_big(count: int, res: int, limit: float) -> dict:
    from workbench.renderers.radiosity.hemicube import Hemicube
    from workbench.renderers.radiosity import solvers
    scene, p, h = _setup(count)
    g = p.geometry()
    base = peak_mb()
    hc = Hemicube(g, res)
    cache = solvers.RowCache(hc.rows, 128.0)
    res_ = solvers.progressive_rows(cache, g.areas, p.emission, p.reflectance, tol=1e-2,
                                    q=float(p.reflectance.max()), time_limit=limit, relax=RELAX)
    return {"patches": len(p), "patch_size_mm": h, "hemicube_resolution": res, "relax": RELAX,
            "shots": res_.iterations, "hemicubes_drawn": hc.drawn, "row_cache_mb": 128.0,
            "rows_cached": len(cache.rows), "seconds": res_.seconds, "seconds_per_shot": res_.seconds / max(res_.iterations, 1),
            "converged_to_tol_1e-2": res_.converged, "message": res_.message,
            "error_bound": res_.error_bound, "time_limit_seconds": limit,
            "rss_mb_before_hemicubes": base, "peak_rss_mb": peak_mb(),
            "full_matrix_would_need_mb": len(p) ** 2 * 8 / 2 ** 20}


def tables(res: dict) -> str:
    out = [f"{res.get('machine')}{'; quick sizes' if res.get('quick') else ''}.", ""]
    f = res.get("full")
    if f and "error" not in f:
        out += [f"## full: {f['patches']} patches, hemicube {f['hemicube_resolution']} px ({f['gl_renderer']})", "",
                kv_table([("form factors (s)", f["form_factor_seconds"]), ("direct LU solve (s)", f["direct_solve_seconds"]),
                          (f"hemicube + direct (s; target {f['target_seconds']})", f["hemicube_plus_direct_seconds"]),
                          ("peak RSS with the full matrix (MB)", f["peak_rss_mb_full_matrix"]),
                          ("progressive on the stored matrix, to 1 % RMS (s)",
                           f["progressive_on_stored_matrix"]["seconds_to_1pct_rms"])]),
                "Matrix-free progressive refinement to within 1 % (area-weighted RMS) of the converged solution:", "",
                table(["run", "rows from", "relax", "wall s to 1 %", "CPU s to 1 %", "shots", "rows computed",
                       "target (s)"],
                      [[k.replace("progressive_", ""), r["source"], r["relax"], r["seconds_to_1pct_rms"],
                        r["cpu_seconds_to_1pct_rms"], r["shots_to_1pct_rms"], r["rows_computed"], r["target_seconds"]]
                       for k, r in f.items() if k.startswith("progressive_") and isinstance(r, dict) and "source" in r])]
    elif f:
        out += ["## full: failed", "", "```", f["error"], "```", ""]
    v = res.get("pvf")
    if v and "skipped" in v:
        out += ["## pvf", "", v["skipped"] + ".", ""]
    elif v and "error" not in v:
        hc, an = v["hemicube_vs_pyviewfactor"], v["analytic_vs_pyviewfactor"]
        out += [f"## pvf: against pyviewfactor {v['pyviewfactor_version']} (the anchor), {v['pairs']} pairs of "
                f"{v['room_patches']} room patches", "",
                table(["", "pyviewfactor (anchor)", "hemicube (ours)", "analytic (ours)"],
                      [["seconds per pair", v["pyviewfactor_seconds_per_pair"], v["hemicube_seconds_per_pair"],
                        v["analytic_seconds_per_pair"]],
                       ["pyviewfactor / ours, per pair", "1", ratio(v["pyviewfactor_seconds_per_pair"], v["hemicube_seconds_per_pair"]),
                        ratio(v["pyviewfactor_seconds_per_pair"], v["analytic_seconds_per_pair"])],
                       ["mean abs error vs pyviewfactor", 0.0, hc["mean_abs"], an["mean_abs"]],
                       ["median rel. error (F > 1e-4)", 0.0, hc["median_rel_F>1e-4"], an["median_rel_F>1e-4"]],
                       ["95th percentile rel. error", 0.0, hc["p95_rel_F>1e-4"], an["p95_rel_F>1e-4"]]]),
                f"pyviewfactor for the full matrix would take about {fmt(v['pyviewfactor_seconds_full_matrix_estimate'])} s; "
                f"the hemicube took {fmt(v['hemicube_seconds_full_matrix'])} s.", ""]
    elif v:
        out += ["## pvf: failed", "", "```", v["error"], "```", ""]
    b = res.get("big")
    if b and "error" not in b:
        out += [f"## big: {b['patches']} patches, matrix-free progressive refinement", "",
                kv_table([("shots", b["shots"]), ("seconds", b["seconds"]), ("converged to 1e-2", b["converged_to_tol_1e-2"]),
                          ("peak RSS (MB)", b["peak_rss_mb"]), ("a full matrix would need (MB)", b["full_matrix_would_need_mb"])])]
    elif b:
        out += ["## big: failed", "", "```", b["error"], "```", ""]
    return "\n".join(out)


PAGE = Page("radiosity_cornell", "Radiosity on the Cornell box", first_paragraph(__doc__),
            "python bench/radiosity_cornell.py", tables, anchors=("pyviewfactor",),
            smoke_note="about 100 patches, 16-pixel hemicubes, 20 pairs")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--part", choices=("full", "pvf", "big"))
    ap.add_argument("--quick", action="store_true", help="small sizes")
    ap.add_argument("--parts", default="full,pvf,big",
                    help="comma-separated parts to run; others are kept from the last results file")
    a = PAGE.parse(ap, argv)
    q = a.quick
    if a.part:
        size = ("smoke" if a.smoke else "quick" if q else "full")
        fn = {"full": lambda: part_full(*{"smoke": (100, 16), "quick": (300, 64), "full": (2000, 128)}[size]),
              "pvf": lambda: part_pvf(*{"smoke": (100, 16, 20), "quick": (300, 64, 200), "full": (2000, 128, 2000)}[size]),
              "big": lambda: part_big(*{"smoke": (200, 16, 2.0), "quick": (1000, 64, 10.0),
                                        "full": (10000, 128, 120.0)}[size])}[a.part]
        print(json.dumps(fn()))
        return
    parts = a.parts.split(",")
    out = a.out / "radiosity_cornell.json"
    results = json.loads(out.read_text()) if out.exists() and len(parts) < 3 else {}
    results.pop("environment", None)
    results.update({"machine": f"{os.cpu_count()} CPUs (shared), llvmpipe", "quick": q})
    for part in parts:
        results[f"{part}_date"] = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
        results[f"{part}_load_average_1min_before"] = os.getloadavg()[0]
        if part == "pvf" and PAGE.anchor(a, "pyviewfactor") is None:
            results[part] = {"skipped": skip_note("pyviewfactor")}
            continue
        cmd = ([sys.executable, __file__, "--part", part, "--out", str(a.out)] + (["--quick"] if q else [])
               + (["--smoke"] if a.smoke else []))
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
        if r.returncode:
            results[part] = {"error": r.stderr[-2000:]}
        else:
            results[part] = json.loads(r.stdout.strip().splitlines()[-1])
    print(json.dumps(results, indent=1))
    PAGE.write(a, results)
    if any("error" in results[p] for p in parts):
        sys.exit(f"radiosity_cornell: part(s) failed: {[p for p in parts if 'error' in results[p]]}")


if __name__ == "__main__":
    main()
