"""The path tracer against Mitsuba 3 on the Cornell box and on ``cornell_spheres``, same run,
same host: Mitsuba's vectorised ``llvm_ad_rgb`` variant (the anchor: the variant a user would
pick for speed on a CPU) and its ``scalar_rgb`` variant.

* ``throughput``: each scene at 256x256, 64 spp, the methods alternating ``--repeat`` times
  (default 5; numba on 2 threads; Mitsuba's own thread pool, one thread per core: 2 here); per
  render the wall time of the sampling phase (pathtrace ``timings["trace"]``, Mitsuba
  ``timings["render"]``, the ``mi.render`` calls), the CPU seconds of that phase, the whole
  call's wall time, and the 1-minute load average before and after.  Samples per second and
  per CPU second (medians of the repeats) and their ratios pathtrace / Mitsuba (> 1: the path
  tracer is faster), against each variant.
* ``equal_rmse``: every method at 16, 64 and 256 spp, three seeds each, at ``--rmse-size``
  (default 64) against one shared Mitsuba reference of ``--ref-spp`` (default 4096) spp, kept in
  the reference cache (``workbench.compare.reference_cache``: a second run does not re-render
  it).  Per render the RMSE and the *excess* MSE ``RMSE^2 - noise_ref^2`` (the reference's own
  noise, from its per-pixel standard error, removed: what is left is the method's error); per
  method the constant ``c^2 = mean(excess MSE x spp)`` (unbiased Monte Carlo: MSE = c^2 / spp;
  pooled over the runs, since one image's error is dominated by a few light-edge pixels and
  varies from seed to seed), and from ``c`` and the measured sampling time per spp the time
  each method needs to reach the excess RMSE ``c_pathtrace / 8`` (pathtrace at 64 spp), and
  their ratio; the same off the light's own pixels.
* Methods: ``pathtrace`` (default: Russian roulette from the 3rd bounce), ``mitsuba_llvm``
  (``llvm_ad_rgb``) and ``mitsuba`` (``scalar_rgb``), both with Russian roulette from depth 5,
  and ``pathtrace_rr5`` (``rr_start = 5``).  ``llvm_ad_rgb`` is probed first (a tiny render in
  a child process, ``renderers.mitsuba_method.probe_variant``); where it cannot load (Drjit
  finds no usable ``libLLVM``: set ``DRJIT_LIBLLVM_PATH`` to Debian's ``libLLVM.so.19.1``), the
  page says why and compares with ``scalar_rgb`` alone.
* ``reference``: the pathtrace image of ``cornell`` at 256x256 run to the noise level
  ``--target`` (RMS of the per-pixel standard error), timed (wall and CPU), load average.

Usage: ``PYTHONPATH=. .venv/bin/python bench/pathtrace_vs_mitsuba.py [--repeat 5] [--quick]``
writes ``bench/results/pathtrace_vs_mitsuba.json`` and ``docs/benchmarks/pathtrace_vs_mitsuba.md`` and
prints it (``--quick``: small sizes, printed only unless ``--out`` is given).  Without Mitsuba its
rows, the shared reference and the equal-RMSE part are skipped.  ``--smoke``: 16 x 16 at 4 spp, one
repeat; equal RMSE at 8 x 8, 2 and 4 spp, one seed, against a 16-spp reference; a 0.2-noise reference.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))
THREADS = 2

from _common import Page, first_paragraph, fmt, ratio, skip_note, table  # noqa: E402
SCENES = ("cornell", "cornell_spheres")
#: What is compared: label -> (method, options).  ``pathtrace_rr5`` starts Russian roulette at
#: the 5th bounce, as Mitsuba's path integrator does (the method's default is the 3rd).
VARIANTS = {"pathtrace": ("pathtrace", {}), "mitsuba_llvm": ("mitsuba", {"variant": "llvm_ad_rgb"}),
            "mitsuba": ("mitsuba", {"variant": "scalar_rgb"}), "pathtrace_rr5": ("pathtrace", {"rr_start": 5})}
ANCHOR_LABELS = ("mitsuba_llvm", "mitsuba")


def load() -> float:
    return round(os.getloadavg()[0], 2)


def sample_time(r) -> tuple[float, float]:
    """(wall, CPU) seconds of a result's sampling phase."""
    if r.method == "pathtrace":
        return r.timings["trace"], r.timings["trace_cpu"]
    return r.timings["render"], r.stats["render_cpu_seconds"]


def render(scene, label: str, size: int, spp: int, seed: int):
    import workbench
    method, opts = VARIANTS[label]
    l0 = load()
    r = workbench.render(scene, method, width=size, height=size, spp=spp, seed=seed, **opts)
    wall, cpu = sample_time(r)
    n = spp * size * size
    return r, {"method": label, "spp": spp, "size": size, "sample_wall_s": round(wall, 3),
               "sample_cpu_s": round(cpu, 3), "call_wall_s": round(r.timings["total"], 3),
               "samples_per_s": round(n / wall), "samples_per_cpu_s": round(n / cpu),
               "load_before": l0, "load_after": load()}


def median_run(runs: list[dict]) -> dict:
    """The run of median samples per second (the lower middle one of an even count), with the
    medians of every figure over the runs."""
    order = sorted(runs, key=lambda e: e["samples_per_s"])
    mid = dict(order[(len(order) - 1) // 2])
    for k in ("sample_wall_s", "sample_cpu_s", "call_wall_s", "samples_per_s", "samples_per_cpu_s"):
        mid[k] = float(np.median([e[k] for e in runs]))
    mid["runs"] = len(runs)
    return mid


def throughput(scene, size: int, spp: int, repeat: int, labels: list[str]) -> dict:
    runs = []
    for k in range(repeat):
        for m in labels:
            runs.append(render(scene, m, size, spp, seed=k)[1])
    med = {m: median_run([e for e in runs if e["method"] == m]) for m in labels}
    ratios = {}
    for a in (x for x in ANCHOR_LABELS if x in labels):
        for m in ("pathtrace", "pathtrace_rr5"):
            ratios[f"{m}_over_{a}"] = {
                "samples_per_s": med[m]["samples_per_s"] / med[a]["samples_per_s"],
                "samples_per_cpu_s": med[m]["samples_per_cpu_s"] / med[a]["samples_per_cpu_s"]}
    return {"scene": scene.name, "size": size, "spp": spp, "threads": THREADS, "runs": runs, "median": med,
            "ratios": ratios}


def equal_rmse(scene, size: int, ref_spp: int, labels: list[str], spps=(16, 64, 256), seeds=(7, 8, 9)) -> dict:
    from workbench.compare.agreement import light_pixels
    from workbench.compare.reference_cache import cached_render
    l0 = load()
    ref = cached_render(scene, "mitsuba", size, size, spp=ref_spp, seed=1000, variant="scalar_rgb")
    se2 = ref.stats["stderr"].astype(np.float64) ** 2
    off = ~light_pixels(scene, size, size)
    ref_noise2, ref_noise2_off = float(np.mean(se2)), float(np.mean(se2[off]))
    out = {"size": size, "seeds": list(seeds),
           "reference": {"method": "mitsuba", "spp": ref_spp, "cache": ref.stats.get("cache"),
                         "noise_rms": ref_noise2 ** 0.5, "noise_rms_off_light": ref_noise2_off ** 0.5,
                         "load_before": l0, "load_after": load()},
           "runs": []}
    per: dict = {}
    for spp in spps:
        for seed in seeds:
            for m in labels:
                r, e = render(scene, m, size, spp, seed=seed)
                err2 = (r.image.astype(np.float64) - ref.image) ** 2
                mse, mse_off = float(np.mean(err2)), float(np.mean(err2[off]))
                e.update(seed=seed, rmse=mse ** 0.5, excess_mse=mse - ref_noise2, rmse_off_light=mse_off ** 0.5,
                         excess_mse_off_light=mse_off - ref_noise2_off)
                out["runs"].append(e)
                per.setdefault(m, []).append(e)
    fit = {}
    for m, rows in per.items():
        # unbiased Monte Carlo: excess MSE = c^2 / spp; c^2 pooled over every run
        c2 = float(np.mean([e["excess_mse"] * e["spp"] for e in rows]))
        c2_off = float(np.mean([e["excess_mse_off_light"] * e["spp"] for e in rows]))
        wall_per_spp = sum(e["sample_wall_s"] for e in rows) / sum(e["spp"] for e in rows)
        cpu_per_spp = sum(e["sample_cpu_s"] for e in rows) / sum(e["spp"] for e in rows)
        fit[m] = {"c": max(c2, 0.0) ** 0.5, "c_off_light": max(c2_off, 0.0) ** 0.5,
                  "wall_s_per_spp": wall_per_spp, "cpu_s_per_spp": cpu_per_spp}
    flat = [m for m, f in fit.items() if f["c"] == 0.0 or f["c_off_light"] == 0.0]
    if flat:  # (the pooled excess MSE at or below zero: small images and few samples, as --smoke)
        out.update(constants_measured=fit, skipped=(
            f"the error of {', '.join(flat)} is not above the reference's own noise at {size} px "
            f"(pooled over {len(spps) * len(seeds)} renders), so the constant c of excess MSE = c^2 / spp "
            "cannot be fitted: a larger --rmse-size or more reference samples"))
        return out
    target = fit["pathtrace"]["c"] / 64 ** 0.5  # the excess RMSE pathtrace reaches at 64 spp
    for m, f in fit.items():
        spp_needed = (f["c"] / target) ** 2
        f.update(spp_to_target=spp_needed, wall_s_to_target=spp_needed * f["wall_s_per_spp"],
                 cpu_s_to_target=spp_needed * f["cpu_s_per_spp"],
                 efficiency_per_cpu_s=1.0 / (f["c"] ** 2 * f["cpu_s_per_spp"]))
    ratios = {}
    for a in (x for x in ANCHOR_LABELS if x in fit):
        M = fit[a]
        for m in ("pathtrace", "pathtrace_rr5"):
            P = fit[m]
            ratios[f"{m}_over_{a}"] = {
                "wall_time_to_equal_rmse": P["wall_s_to_target"] / M["wall_s_to_target"],
                "cpu_time_to_equal_rmse": P["cpu_s_to_target"] / M["cpu_s_to_target"],
                "cpu_time_to_equal_rmse_off_light":
                    (P["c_off_light"] ** 2 * P["cpu_s_per_spp"]) / (M["c_off_light"] ** 2 * M["cpu_s_per_spp"])}
    out.update(target_excess_rmse=target, fit=fit, ratios=ratios)
    return out


def reference(scene, size: int, target: float) -> dict:
    from workbench.renderers.pathtrace.session import PathTraceSession, run_to_noise
    l0 = load()
    t0 = time.perf_counter()
    ses = run_to_noise(PathTraceSession(scene, size, size, seed=11), target, max_spp=1 << 14)
    wall = time.perf_counter() - t0
    return {"size": size, "target_noise_rms": target, "reached_noise_rms": ses.noise_rmse, "spp": ses.samples,
            "wall_s": round(wall, 2), "trace_wall_s": round(ses.timings["trace"], 2),
            "trace_cpu_s": round(ses.timings["trace_cpu"], 2), "load_before": l0, "load_after": load(),
            "mean_radiance": ses.image.mean(axis=(0, 1)).tolist()}


def tables(res: dict) -> str:
    out = [f"{res['image_definition']}.", ""]
    llvm = res.get("llvm")
    if llvm:
        out += [f"Mitsuba `llvm_ad_rgb`: {llvm['status']}" + (f" ({llvm['reason']})" if llvm.get("reason") else "")
                + f"; `DRJIT_LIBLLVM_PATH` = {llvm.get('drjit_libllvm_path') or 'unset'}.", ""]
    for t in res["throughput"]:
        med = t["median"]
        anchors = [a for a in ANCHOR_LABELS if a in med]
        head = ["method", "sampling wall (s)", "sampling CPU (s)", "samples/s", "samples/CPU-s"]
        for a in anchors:
            head += [f"samples/s over {a}", f"samples/CPU-s over {a}"]
        rows = []
        for k, e in med.items():
            row = [k, e["sample_wall_s"], e["sample_cpu_s"], e["samples_per_s"], e["samples_per_cpu_s"]]
            for a in anchors:
                row += [ratio(e["samples_per_s"], med[a]["samples_per_s"]),
                        ratio(e["samples_per_cpu_s"], med[a]["samples_per_cpu_s"])]
            rows.append(row)
        out += [f"## Throughput: `{t['scene']}` at {t['size']} x {t['size']}, {t['spp']} spp, {t['threads']} threads, "
                f"medians of {next(iter(med.values()))['runs']} alternating runs", "",
                "Ratios above 1: the row's method is faster than the anchor.", "", table(head, rows), ""]
        if not anchors:
            out.append(skip_note("mitsuba") + ".\n")
    for q in res.get("equal_rmse", []):
        if "fit" not in q:
            out.append(f"Equal-RMSE part: {q.get('skipped')}.\n")
            continue
        r = q["reference"]
        anchors = [a for a in ANCHOR_LABELS if a in q["fit"]]
        head = ["method", "c", "c off the light", "CPU s per spp", "spp to target", "CPU s to target"]
        for a in anchors:
            head += [f"CPU time to equal RMSE over {a}", "same, off the light"]
        rows = []
        for k, f in q["fit"].items():
            row = [k, f["c"], f["c_off_light"], f["cpu_s_per_spp"], f["spp_to_target"], f["cpu_s_to_target"]]
            for a in anchors:
                rr = q["ratios"].get(f"{k}_over_{a}")
                row += ["1 (anchor)" if k == a else ("–" if rr is None else fmt(rr["cpu_time_to_equal_rmse"])),
                        "–" if rr is None else fmt(rr["cpu_time_to_equal_rmse_off_light"])]
            rows.append(row)
        out += [f"## Time to equal error: `{q['scene']}` at {q['size']} x {q['size']}, seeds {q['seeds']}, against "
                f"Mitsuba (`scalar_rgb`) at {r['spp']} spp (noise {fmt(r['noise_rms'])})", "",
                f"Target excess RMSE {fmt(q['target_excess_rmse'])} (pathtrace's at 64 spp).  Ratios below 1: "
                "the row's method reaches it in less CPU time than the anchor.", "", table(head, rows), ""]
    ref = res["reference"]
    out += [f"## Path tracer to noise {ref['target_noise_rms']} at {ref['size']} x {ref['size']}", "",
            table(["spp", "noise reached", "wall (s)", "trace wall (s)", "trace CPU (s)"],
                  [[ref["spp"], ref["reached_noise_rms"], ref["wall_s"], ref["trace_wall_s"], ref["trace_cpu_s"]]])]
    return "\n".join(out)


def llvm_status() -> dict:
    """Whether Mitsuba's ``llvm_ad_rgb`` loads here (a tiny render in a child process)."""
    from workbench.renderers.mitsuba_method import probe_variant
    ok, why = probe_variant("llvm_ad_rgb")
    return {"status": "loaded" if ok else "could not load: compared with scalar_rgb only",
            "reason": None if ok else why, "drjit_libllvm_path": os.environ.get("DRJIT_LIBLLVM_PATH")}


PAGE = Page("pathtrace_vs_mitsuba", "The path tracer against Mitsuba 3 (llvm_ad_rgb and scalar_rgb)", first_paragraph(__doc__),
            "python bench/pathtrace_vs_mitsuba.py", tables, anchors=("mitsuba",),
            smoke_note="16 x 16 at 4 spp; equal RMSE at 8 x 8 against a 16-spp reference")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--rmse-size", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--target", type=float, default=0.01, help="noise level of the 256x256 pathtrace reference")
    ap.add_argument("--quick", action="store_true", help="small sizes (a smoke test)")
    out_given = "--out" in (sys.argv[1:] if argv is None else argv)
    a = PAGE.parse(ap, argv)
    spps, seeds = (16, 64, 256), (7, 8, 9)
    if a.quick:
        a.size, a.spp, a.rmse_size, a.ref_spp, a.repeat, a.target = 32, 8, 16, 256, 1, 0.05
    if a.smoke:
        a.size, a.spp, a.rmse_size, a.ref_spp, a.repeat, a.target = 16, 4, 8, 16, 1, 0.2
        spps, seeds = (2, 4), (7,)
    have = PAGE.anchor(a, "mitsuba") is not None
    import numba

    import workbench
    numba.set_num_threads(THREADS)
    res = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "machine": f"{os.cpu_count()} CPUs, shared",
           "image_definition": "box-filtered pixel average, linear RGB, not clipped (every method)",
           "load_before": load()}
    labels = ["pathtrace", "pathtrace_rr5"]
    if have:
        res["llvm"] = llvm_status()
        labels[1:1] = (["mitsuba_llvm"] if res["llvm"]["reason"] is None else []) + ["mitsuba"]
    res["throughput"], res["equal_rmse"] = [], []
    for name in SCENES:
        scene = workbench.load_scene(name)
        workbench.render(scene, "pathtrace", width=8, height=8, spp=2)  # JIT compile or cache load, apart
        res["throughput"].append(throughput(scene, a.size, a.spp, a.repeat, labels))
        res["equal_rmse"].append(dict(equal_rmse(scene, a.rmse_size, a.ref_spp, labels, spps, seeds), scene=name)
                                 if have else {"skipped": skip_note("mitsuba") + " (it makes the shared reference)"})
    res["reference"] = reference(workbench.load_scene("cornell"), a.size, a.target)
    res["load_after"] = load()
    print(json.dumps(res, indent=1))
    if not a.quick or out_given or a.smoke:
        PAGE.write(a, res)


if __name__ == "__main__":
    main()
