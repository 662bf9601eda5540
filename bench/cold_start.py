"""Time to a first image on an empty numba cache ("cold"), and the same command again on the
cache it left ("warm"): the kernel-layer issue's targets.

Each case is the console script run as a new process (``workbench render SCENE -m METHOD``, a
64 x 48 image) with ``NUMBA_CACHE_DIR`` pointing at a new empty folder, so the run compiles
every kernel it needs; the warm run repeats it on that folder.  ``every kind`` renders the
``kinds`` and ``csg`` scenes (every object kind, CSG) with ray casting, Whitted and path tracing
in one cache folder, one after the other: the compile time of every kernel of every kind, summed.

Writes ``bench/results/cold_start.json`` and prints it.  Run: ``.venv/bin/python bench/cold_start.py``
(about 5 minutes on 2 cores).
"""
from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
WORKBENCH = str(Path(sys.executable).with_name("workbench"))
CASES = {"whitted raytrace": [("whitted", "raytrace")],
         "cornell pathtrace": [("cornell", "pathtrace")],
         "every kind": [(s, m) for s in ("kinds", "csg") for m in ("raycast", "raytrace", "pathtrace")]}
TARGETS = {"whitted raytrace": 15.0, "cornell pathtrace": 15.0, "every kind": 60.0}


def run(scene: str, method: str, cache: str, out: str) -> float:
    """Seconds of one ``workbench render`` process (raises if it fails)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    t0 = time.perf_counter()
    subprocess.run([WORKBENCH, "render", scene, "-m", method, "--size", "64x48", "-o", out],
                   env=env, check=True, capture_output=True, cwd=ROOT)
    return time.perf_counter() - t0


def main() -> int:
    rows = {}
    for name, runs in CASES.items():
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
            cold = sum(run(s, m, cache, f"{out}/{s}-{m}.png") for s, m in runs)
            warm = sum(run(s, m, cache, f"{out}/{s}-{m}.png") for s, m in runs)
        rows[name] = {"cold_s": round(cold, 2), "warm_s": round(warm, 2), "target_cold_s": TARGETS[name],
                      "renders": [f"{s} -m {m}" for s, m in runs]}
        print(name, rows[name], flush=True)
    report = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs",
              "load_average_at_end": [round(x, 2) for x in os.getloadavg()],
              "python": platform.python_version(), "size": "64x48", "cases": rows}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "cold_start.json").write_text(json.dumps(report, indent=1) + "\n")
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
