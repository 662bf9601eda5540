"""Mitsuba 3 on the Cornell box: run time and samples per second of the ``mitsuba`` method.

* ``mitsuba``: ``cornell`` at 256x256, 64 spp (two passes of 32, box filter, path integrator with
  unbounded depth), ``--repeat`` renders; records the render time (Mitsuba's ``mi.render``
  calls only), the whole method's time (child process start, export, scene load), samples
  per second = spp x pixels / render time, samples per CPU-second (steadier than wall time
  on a shared host), the variant that ran and why, the noise estimate.
* ``pathtrace`` (``--with-pathtrace``, once the ``pathtrace`` method is registered): the same
  scene, size and spp in the same run, the two methods alternating, then
  :func:`validate_pathtrace` (per-pixel consistency with the combined noise, mean radiance).
* ``--rmse-study``: :func:`rmse_against_shared_reference`, error against run time of each
  method against one shared high-spp Mitsuba reference (cached on disk).

Usage: ``.venv/bin/python bench/mitsuba_cornell.py [--size 256] [--spp 64] [--repeat 2]
[--with-pathtrace]`` writes ``bench/results/mitsuba_cornell.json`` and
``docs/benchmarks/mitsuba_cornell.md`` and prints it.  Without Mitsuba the Mitsuba rows are skipped
(the path tracer's, with ``--with-pathtrace``, are still measured).  ``--smoke``: 16 x 16, 4 spp,
one repeat, with the path tracer; the RMSE study (only with ``--rmse-study``) at 16 x 16 against a
64-spp reference.
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

from workbench.compare.agreement import light_pixels  # noqa: E402  (re-exported for callers)
from _common import Page, first_paragraph, fmt, ratio, skip_note, table  # noqa: E402


def noise_image(result) -> np.ndarray | None:
    """The per-pixel standard error of a result: ``result.std_error`` (``pathtrace``), else the
    first (H, W[, 3]) array in its stats whose key names ``stderr`` or ``noise`` (``mitsuba``
    uses ``stderr``), broadcast to (H, W, 3)."""
    H, W = result.image.shape[:2]
    if getattr(result, "std_error", None) is not None:
        return np.asarray(result.std_error, dtype=np.float64)
    for k, v in result.stats.items():
        if isinstance(v, np.ndarray) and v.shape[:2] == (H, W) and ("stderr" in k or "noise" in k):
            v = np.asarray(v, dtype=np.float64)
            return np.broadcast_to(v if v.ndim == 3 else v[..., None], (H, W, 3))
    return None


def run_once(scene, method: str, size: int, spp: int, seed: int = 0) -> tuple[dict, object]:
    import workbench
    from workbench.renderers.base import get_renderer
    opts = {"seed": seed} if "seed" in get_renderer(method).options else {}
    r = workbench.render(scene, method, width=size, height=size, spp=spp, **opts)
    # the sampling phase: Mitsuba's mi.render calls, the path tracer's trace phase
    t_render = r.timings.get("render", r.timings.get("trace", r.timings["total"]))
    entry = {"total_s": round(r.timings["total"], 3), "render_s": round(t_render, 3),
             "samples_per_second": round(spp * size * size / t_render),
             "timings": {k: round(v, 4) for k, v in r.timings.items()},
             "noise_rms": None if noise_image(r) is None else float(np.sqrt(np.mean(noise_image(r) ** 2)))}
    cpu = r.stats.get("render_cpu_seconds") or r.timings.get("trace_cpu")
    if cpu:
        entry["samples_per_cpu_second"] = round(spp * size * size / cpu)
    for k in ("variant", "variant_reason", "mitsuba_version", "render_cpu_seconds", "child_peak_rss_bytes",
              "threads"):
        if k in r.stats:
            entry[k] = r.stats[k]
    return entry, r


def validate_pathtrace(pt, mi, exclude: np.ndarray | None = None) -> dict:
    """Agreement of two independent estimates of the same image.

    Statistic: ``noise_ratio = mean((a - b)^2) / mean(se_a^2 + se_b^2)`` over all pixels and
    channels, with each method's own per-pixel standard-error estimate: for two unbiased
    estimates of the same image whose noise estimates are right it is 1 (each se^2 is an
    unbiased but one-or-few-degree-of-freedom estimate, so the ratio of sums is used rather than
    a per-pixel z, whose tails are heavy); a bias between the two raises it.  Also the fraction
    of per-pixel ``|z| > 3``: with two-pass (one degree of freedom) noise estimates on both
    sides z follows roughly Student's t with 2 degrees of freedom, P(|z| > 3) = 0.095 (two
    Mitsuba images measured 0.099), and the mean radiance ratio (no clipping; both images are
    box-filtered pixel averages).
    ``exclude`` (H, W) bool leaves pixels out (e.g. :func:`light_pixels`: two independent
    32-spp Mitsuba images of ``cornell`` at 32x32 give a ratio of 1.3-1.7 over all pixels and
    0.8-1.1 off the light's pixels).
    """
    keep = np.ones(pt.image.shape[:2], bool) if exclude is None else ~exclude
    a, b = np.asarray(pt.image, np.float64)[keep], np.asarray(mi.image, np.float64)[keep]
    out = {"pixels": int(keep.sum()), "mean_radiance_pathtrace": a.mean(0).tolist(), "mean_radiance_mitsuba": b.mean(0).tolist(),
           "mean_ratio": float(a.mean() / b.mean()), "rmse": float(np.sqrt(np.mean((a - b) ** 2)))}
    se_a, se_b = noise_image(pt), noise_image(mi)
    if se_a is not None and se_b is not None:
        se_a, se_b = se_a[keep], se_b[keep]
    else:
        out["z"] = "no per-pixel noise estimate in one of the results"
        return out
    s = np.sqrt(se_a ** 2 + se_b ** 2)
    ok = s > 0
    z = (a - b)[ok] / s[ok]
    out.update(noise_ratio=float(np.mean((a - b) ** 2) / np.mean(s ** 2)), median_abs_z=float(np.median(np.abs(z))),
               frac_abs_z_gt_3=float(np.mean(np.abs(z) > 3)), values_with_zero_noise=int((~ok).sum()))
    return out


def pathtrace_vs_mitsuba(scene_name: str = "cornell", size: int = 256, spp: int = 64, repeat: int = 2,
                         have_mitsuba: bool = True) -> dict:
    """Both methods on the same scene, size and spp in the same run, alternating (best time of
    ``repeat`` each), plus :func:`validate_pathtrace` on the last images (the path tracer alone
    when Mitsuba is absent)."""
    import workbench
    from workbench.renderers.base import available
    if "pathtrace" not in available():
        return {"status": "pathtrace method not registered in this tree"}
    scene = workbench.load_scene(scene_name)
    runs = {"pathtrace": [], "mitsuba": []} if have_mitsuba else {"pathtrace": []}
    last = {}
    workbench.render(scene, "pathtrace", width=16, height=16, spp=2)  # JIT compile, apart
    for _ in range(repeat):
        for m in runs:
            e, last[m] = run_once(scene, m, size, spp)
            runs[m].append(e)
    best = {m: min(v, key=lambda e: e["render_s"]) for m, v in runs.items()}
    if not have_mitsuba:
        return {"scene": scene_name, "size": size, "spp": spp, "runs": runs, "best": best,
                "mitsuba": skip_note("mitsuba")}
    return {"scene": scene_name, "size": size, "spp": spp, "runs": runs, "best": best,
            "samples_per_second_ratio_pathtrace_over_mitsuba":
                best["pathtrace"]["samples_per_second"] / best["mitsuba"]["samples_per_second"],
            "validation_all_pixels": validate_pathtrace(last["pathtrace"], last["mitsuba"]),
            "validation_off_light": validate_pathtrace(last["pathtrace"], last["mitsuba"],
                                                       light_pixels(scene, size, size))}


def rmse_against_shared_reference(scene_name: str = "cornell", size: int = 128, reference_spp: int = 4096,
                                  spps: tuple = (4, 16, 64, 256), methods: tuple = ("pathtrace", "mitsuba")) -> dict:
    """Error against run time of each method against one shared high-spp Mitsuba reference (kept
    in the reference cache, so a second call does not re-render it): per method and spp the
    render time and the RMSE (linear, not clipped), from which the time each needs to reach an
    equal RMSE is read off.  Methods not registered are reported as such."""
    import workbench
    from workbench.compare.reference_cache import cached_render
    from workbench.renderers.base import available
    scene = workbench.load_scene(scene_name)
    ref = cached_render(scene, "mitsuba", size, size, spp=reference_spp, seed=1000)
    out = {"scene": scene_name, "size": size, "reference": {"method": "mitsuba", "spp": reference_spp,
           "stderr_rms": ref.stats.get("stderr_rms"), "cache": ref.stats.get("cache")}, "methods": {}}
    for m in methods:
        if m not in available():
            out["methods"][m] = "not registered in this tree"
            continue
        rows = []
        for spp in spps:
            e, r = run_once(scene, m, size, spp)
            e.update(spp=spp, rmse=float(np.sqrt(np.mean((r.image.astype(np.float64) - ref.image) ** 2))))
            rows.append(e)
        out["methods"][m] = rows
    return out


def tables(res: dict) -> str:
    out = [f"`cornell` at {res['size']} x {res['size']}, {res['spp']} spp; {res['image_definition']}.", ""]
    mits = res["mitsuba"]
    if isinstance(mits, str):
        out.append(mits + ".\n")
    else:
        out += ["## Mitsuba 3 (the anchor) alone", "",
                table(["run", "render (s)", "whole method (s)", "samples/s", "samples/CPU-s", "variant", "noise RMS"],
                      [[i + 1, e["render_s"], e["total_s"], e["samples_per_second"], e.get("samples_per_cpu_second"),
                        e.get("variant"), e.get("noise_rms")] for i, e in enumerate(mits)])]
        v = res.get("mitsuba_best", {}).get("variant_reason")
        if v:
            out += [f"Variant: {v}", ""]
    pv = res.get("pathtrace_vs_mitsuba")
    if pv and "best" in pv:
        b = pv["best"]
        out += ["## Path tracer (ours) and Mitsuba 3 (anchor), same run, alternating", ""]
        rows = [[m, e["render_s"], e["samples_per_second"], e.get("samples_per_cpu_second"), e.get("noise_rms")]
                for m, e in b.items()]
        out.append(table(["method (best run)", "sampling (s)", "samples/s", "samples/CPU-s", "noise RMS"], rows))
        if "mitsuba" in b:
            out += [f"Samples per second, pathtrace / Mitsuba: "
                    f"{ratio(b['pathtrace']['samples_per_second'], b['mitsuba']['samples_per_second'])}; per CPU second: "
                    f"{ratio(b['pathtrace'].get('samples_per_cpu_second'), b['mitsuba'].get('samples_per_cpu_second'))}.",
                    ""]
            for k in ("validation_all_pixels", "validation_off_light"):
                val = pv.get(k, {})
                out.append(f"* {k.replace('_', ' ')}: noise ratio {fmt(val.get('noise_ratio'))}, mean radiance ratio "
                           f"{fmt(val.get('mean_ratio'))}, |z| > 3 fraction {fmt(val.get('frac_abs_z_gt_3'))}")
            out.append("")
        else:
            out.append(pv.get("mitsuba", "") + "\n")
    elif pv:
        out.append(f"Path tracer comparison: {pv.get('status')}\n")
    st = res.get("rmse_against_shared_reference")
    if st and "skipped" in st:
        out.append(f"Error against time: {st['skipped']}.\n")
    elif st:
        out += [f"## Error against time, shared Mitsuba reference ({st['reference']['spp']} spp, {st['size']} px)", ""]
        rows = [[m, e["spp"], e["render_s"], e["rmse"]] for m, v in st["methods"].items() if isinstance(v, list)
                for e in v]
        out.append(table(["method", "spp", "render (s)", "RMSE"], rows))
    return "\n".join(out)


PAGE = Page("mitsuba_cornell", "Mitsuba 3 on the Cornell box", first_paragraph(__doc__),
            "python bench/mitsuba_cornell.py --with-pathtrace", tables, anchors=("mitsuba",),
            smoke_note="16 x 16, 4 spp, one repeat, with the path tracer")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--with-pathtrace", action="store_true")
    ap.add_argument("--rmse-study", action="store_true",
                    help="also error against time vs a shared 4096-spp Mitsuba reference at 128x128 (cached)")
    a = PAGE.parse(ap, argv)
    if a.smoke:
        a.size, a.spp, a.repeat, a.with_pathtrace = 16, 4, 1, True
    have = PAGE.anchor(a, "mitsuba") is not None
    import workbench
    scene = workbench.load_scene("cornell")
    res = {"date": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
           "load_average_1min_before": os.getloadavg()[0], "machine": f"{os.cpu_count()} CPUs (shared)",
           "scene": "cornell", "size": a.size, "spp": a.spp,
           "image_definition": "box-filtered pixel average, linear float32, not clipped",
           "mitsuba": []}
    if have:
        for i in range(a.repeat):
            e, r = run_once(scene, "mitsuba", a.size, a.spp, seed=i)
            res["mitsuba"].append(e)
        res["mitsuba_best"] = min(res["mitsuba"], key=lambda e: e["render_s"])
        res["mitsuba_mean_radiance"] = r.image.mean(axis=(0, 1)).tolist()
    else:
        res["mitsuba"] = skip_note("mitsuba")
    if a.with_pathtrace:
        res["pathtrace_vs_mitsuba"] = pathtrace_vs_mitsuba("cornell", a.size, a.spp, a.repeat, have)
    if a.rmse_study and not have:
        res["rmse_against_shared_reference"] = {"skipped": skip_note("mitsuba") + " (it makes the reference)"}
    elif a.rmse_study:
        res["rmse_against_shared_reference"] = (rmse_against_shared_reference(size=16, reference_spp=64, spps=(4, 16))
                                                if a.smoke else rmse_against_shared_reference())
    res["load_average_1min_after"] = os.getloadavg()[0]
    print(json.dumps(res, indent=1))
    PAGE.write(a, res)


if __name__ == "__main__":
    main()
