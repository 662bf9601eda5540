"""Path tracer benchmark on the Cornell box (published geometry), 256 x 256, 2 threads.

* ``rate``: samples per second of a warm 64-spp render (the JIT compile apart), rays per second,
  and samples per CPU second (all threads; on a shared host the wall rate depends on the load);
* ``to_noise``: how long, and how many samples per pixel, until the image's own noise estimate
  (RMS of the per-pixel standard error, ``stats["noise_rmse"]``) reaches 0.01
  (:func:`workbench.renderers.pathtrace.session.run_to_noise`), and the time 0.005 would take
  by the ``1 / sqrt(N)`` law (four times as long: an extrapolation, labelled so);
* ``reference``: the most converged image reached in 110 s (the target: the reference at
  256 x 256 in under 2 minutes), with its noise; the image is saved as
  ``bench/results/pathtrace_cornell_reference.npy`` beside the JSON (linear float32).

Usage: ``.venv/bin/python bench/pathtrace_cornell.py [--quick]`` writes
``bench/results/pathtrace_cornell.json`` and ``docs/benchmarks/pathtrace_cornell.md`` and prints it.
``--smoke``: 16 x 16, 2 spp, noise target 0.05 (at most 256 spp), a 1-second reference.
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

from _common import Page, first_paragraph, fmt, kv_table  # noqa: E402


def tables(res: dict) -> str:
    r, n, ref = res["rate"], res["to_noise"], res["reference"]
    w, h = res["size"]
    return (f"`{res['scene']}` at {w} x {h}, {res['threads']} threads; numba compile (cold or cache load) "
            f"{fmt(res.get('compile_s'))} s, apart.  No outside anchor here (Mitsuba 3 on the same scene: "
            "[pathtrace_vs_mitsuba](pathtrace_vs_mitsuba.md)).\n\n"
            + kv_table([
                (f"rate: {r['spp']} spp, trace (s)", r["trace_s"]), ("samples/s", r["samples_per_s"]),
                ("samples per CPU second", r["samples_per_cpu_s"]), ("Mrays/s", r["mrays_per_s"]),
                ("rays per sample", r["rays_per_sample"]), ("mean path length", r["mean_path_length"]),
                ("noise RMS at that spp", r["noise_rmse"]),
                (f"to noise {n['target_noise_rmse']}: spp", n["spp"]), ("... trace (s)", n["trace_s"]),
                ("... extrapolated to 0.005 (s, 1/sqrt(N) law)", n["extrapolated_s_to_0.005"]),
                (f"reference within {ref['time_limit_s']} s: spp", ref["spp"]), ("... noise RMS", ref["noise_rmse"]),
                ("... mean radiance (RGB)", " ".join(fmt(x) for x in ref["mean_radiance"]))]))


PAGE = Page("pathtrace_cornell", "Path tracer on the Cornell box", first_paragraph(__doc__),
            "python bench/pathtrace_cornell.py", tables,
            smoke_note="16 x 16, 2 spp, noise target 0.05, a 1-second reference")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="64 x 64, shorter runs")
    ap.add_argument("--threads", type=int, default=2)
    args = PAGE.parse(ap, argv)
    import numba

    import workbench
    from workbench.renderers.pathtrace.session import PathTraceSession, run_to_noise
    numba.set_num_threads(args.threads)
    size = 16 if args.smoke else 64 if args.quick else 256
    scene = workbench.load_scene("cornell")
    out = {"date": time.strftime("%Y-%m-%d %H:%M"), "load_before": os.getloadavg(),
           "threads": args.threads, "size": [size, size], "scene": "cornell"}
    warm = PathTraceSession(scene, 8, 8)
    warm.add_samples(1)
    out["compile_s"] = warm.timings["compile"]
    spp = 2 if args.smoke else 16 if args.quick else 64
    r = workbench.render(scene, "pathtrace", width=size, height=size, spp=spp)
    st = r.stats
    rays = st["camera_rays"] + st["extension_rays"] + st["shadow_rays"]
    out["rate"] = {"spp": spp, "trace_s": r.timings["trace"], "samples_per_s": st["samples_per_s"],
                   "samples_per_cpu_s": st["samples_per_cpu_s"], "trace_cpu_s": r.timings["trace_cpu"],
                   "mrays_per_s": rays / r.timings["trace"] / 1e6, "rays_per_sample": rays / st["samples"],
                   "mean_path_length": st["mean_path_length"], "noise_rmse": st["noise_rmse"]}
    target, max_spp = (0.05, 256) if args.smoke else (0.01, 1 << 14)
    ses = run_to_noise(PathTraceSession(scene, size, size, seed=1), target, max_spp=max_spp)
    out["to_noise"] = {"target_noise_rmse": target, "reached": ses.noise_rmse, "spp": ses.samples,
                       "trace_s": ses.timings["trace"],
                       "extrapolated_s_to_0.005": ses.timings["trace"] * (ses.noise_rmse / 0.005) ** 2}
    limit = 1.0 if args.smoke else 20.0 if args.quick else 110.0
    ref = run_to_noise(PathTraceSession(scene, size, size, seed=2), 1e-4, max_spp=1 << 16, time_limit=limit)
    out["reference"] = {"time_limit_s": limit, "spp": ref.samples, "trace_s": ref.timings["trace"],
                        "noise_rmse": ref.noise_rmse, "mean_radiance": [float(x) for x in ref.image.mean((0, 1))]}
    if not args.quick:
        np.save(args.out / "pathtrace_cornell_reference.npy", ref.image)
    out["load_after"] = os.getloadavg()
    print(json.dumps(out, indent=2))
    PAGE.write(args, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
