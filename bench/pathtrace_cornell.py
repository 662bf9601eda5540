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
``bench/results/pathtrace_cornell.json`` and prints it.
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
OUT = ROOT / "bench" / "results" / "pathtrace_cornell.json"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="64 x 64, shorter runs (a smoke test)")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    import numba

    import workbench
    from workbench.renderers.pathtrace.session import PathTraceSession, run_to_noise
    numba.set_num_threads(args.threads)
    size = 64 if args.quick else 256
    scene = workbench.load_scene("cornell")
    out = {"date": time.strftime("%Y-%m-%d %H:%M"), "load_before": os.getloadavg(),
           "threads": args.threads, "size": [size, size], "scene": "cornell"}
    warm = PathTraceSession(scene, 8, 8)
    warm.add_samples(1)
    out["compile_s"] = warm.timings["compile"]
    spp = 16 if args.quick else 64
    r = workbench.render(scene, "pathtrace", width=size, height=size, spp=spp)
    st = r.stats
    rays = st["camera_rays"] + st["extension_rays"] + st["shadow_rays"]
    out["rate"] = {"spp": spp, "trace_s": r.timings["trace"], "samples_per_s": st["samples_per_s"],
                   "samples_per_cpu_s": st["samples_per_cpu_s"], "trace_cpu_s": r.timings["trace_cpu"],
                   "mrays_per_s": rays / r.timings["trace"] / 1e6, "rays_per_sample": rays / st["samples"],
                   "mean_path_length": st["mean_path_length"], "noise_rmse": st["noise_rmse"]}
    target = 0.01
    ses = run_to_noise(PathTraceSession(scene, size, size, seed=1), target, max_spp=1 << 14)
    out["to_noise"] = {"target_noise_rmse": target, "reached": ses.noise_rmse, "spp": ses.samples,
                       "trace_s": ses.timings["trace"],
                       "extrapolated_s_to_0.005": ses.timings["trace"] * (ses.noise_rmse / 0.005) ** 2}
    limit = 20.0 if args.quick else 110.0
    ref = run_to_noise(PathTraceSession(scene, size, size, seed=2), 1e-4, max_spp=1 << 16, time_limit=limit)
    out["reference"] = {"time_limit_s": limit, "spp": ref.samples, "trace_s": ref.timings["trace"],
                        "noise_rmse": ref.noise_rmse, "mean_radiance": [float(x) for x in ref.image.mean((0, 1))]}
    if not args.quick:
        np.save(OUT.with_name("pathtrace_cornell_reference.npy"), ref.image)
    out["load_after"] = os.getloadavg()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    tmp = OUT.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=2))
    tmp.replace(OUT)
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
