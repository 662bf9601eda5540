"""Time to a first image on an empty numba cache ("cold"), and the same command again on the
cache it left ("warm"): the kernel-layer issue's targets.

Each case is the console script run as a new process (``workbench render SCENE -m METHOD``, a
64 x 48 image) with ``NUMBA_CACHE_DIR`` pointing at a new empty folder, so the run compiles
every kernel it needs; the warm run repeats it on that folder.  ``every kind`` renders the
``kinds``, ``csg``, ``fire`` and ``fur`` scenes (every object kind, CSG, the two media) with ray
casting, Whitted and path tracing
in one cache folder, one after the other: the compile time of every kernel of every kind, summed.

Writes ``bench/results/cold_start.json`` and ``docs/benchmarks/cold_start.md`` and prints it.  Run:
``.venv/bin/python bench/cold_start.py`` (about 5 minutes on 2 cores).  ``--smoke``: one case, ``whitted``
with ``phong`` (the GL rasteriser: the same cold and warm commands without minutes of kernel compiles),
at 16 x 12.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import Page, first_paragraph, table

ROOT = Path(__file__).resolve().parents[1]
WORKBENCH = str(Path(sys.executable).with_name("workbench"))
CASES = {"whitted raytrace": [("whitted", "raytrace")],
         "cornell pathtrace": [("cornell", "pathtrace")],
         "every kind": [(s, m) for s in ("kinds", "csg", "fire", "fur") for m in ("raycast", "raytrace", "pathtrace")]}
TARGETS = {"whitted raytrace": 15.0, "cornell pathtrace": 15.0, "every kind": 60.0}
SMOKE_CASES = {"smoke: whitted phong": [("whitted", "phong")]}


def run(scene: str, method: str, cache: str, out: str, size: str = "64x48") -> float:
    """Seconds of one ``workbench render`` process (raises if it fails)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    t0 = time.perf_counter()
    subprocess.run([WORKBENCH, "render", scene, "-m", method, "--size", size, "-o", out],
                   env=env, check=True, capture_output=True, cwd=ROOT)
    return time.perf_counter() - t0


def tables(res: dict) -> str:
    rows = [[name, ", ".join(f"`{r}`" for r in c["renders"]), c["cold_s"], c["warm_s"], c.get("target_cold_s"),
             "–" if c.get("target_cold_s") is None else ("yes" if c["cold_s"] <= c["target_cold_s"] else "no"),
             f"{c['cold_s'] / c['warm_s']:.0f}"]
            for name, c in res["cases"].items()]
    return (f"Images {res['size']}; each case a new `workbench render` process per render.  No outside anchor: "
            "the warm run (same command, the cache the cold one left) is the baseline.\n\n"
            + table(["case", "renders", "cold (s)", "warm (s)", "target cold (s)", "meets target", "cold / warm"],
                    rows))


PAGE = Page("cold_start", "Time to a first image on an empty numba cache", first_paragraph(__doc__),
            "python bench/cold_start.py", tables, smoke_note="one GL case (whitted phong) at 16 x 12")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args = PAGE.parse(ap, argv)
    cases, size = (SMOKE_CASES, "16x12") if args.smoke else (CASES, "64x48")
    rows = {}
    for name, runs in cases.items():
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
            cold = sum(run(s, m, cache, f"{out}/{s}-{m}.png", size) for s, m in runs)
            warm = sum(run(s, m, cache, f"{out}/{s}-{m}.png", size) for s, m in runs)
        rows[name] = {"cold_s": round(cold, 2), "warm_s": round(warm, 2), "target_cold_s": TARGETS.get(name),
                      "renders": [f"{s} -m {m}" for s, m in runs]}
        print(name, rows[name], flush=True)
    report = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs",
              "load_average_at_end": [round(x, 2) for x in os.getloadavg()],
              "python": platform.python_version(), "size": size, "cases": rows}
    print(json.dumps(report, indent=1))
    PAGE.write(args, report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
