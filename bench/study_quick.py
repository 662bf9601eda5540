"""Error against run time on the default scene: the quick study the main job runs, plus the
wall time of the whole study (what "about a minute" means on this machine).

    .venv/bin/python bench/study_quick.py [--scene whitted] [--out /tmp/study_quick]

Writes ``bench/results/study_quick.json`` (per point: method, knob value, warm median time,
compile time, RMSE, FLIP, Pareto flag; the study's total wall time, the reference's compile time
apart, the machine load) and prints it.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import workbench
from workbench.compare.study import study

OUT = Path(__file__).resolve().parent / "results" / "study_quick.json"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="whitted")
    ap.add_argument("--out", default="/tmp/study_quick")
    a = ap.parse_args()
    t0 = time.perf_counter()
    res = study(workbench.load_scene(a.scene), a.out, quick=True, progress=False)
    wall = time.perf_counter() - t0
    keep = ("method", "knob", "value", "status", "time_s", "compile_s", "rmse", "flip", "pareto")
    out = {"scene": a.scene, "size": res["size"], "repeat": res["repeat"], "study_wall_s": wall,
           "reference": res["reference"], "machine": res["machine"],
           "points": [{k: p.get(k) for k in keep} for p in res["points"]]}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(out, indent=2, default=str))
    print(json.dumps(out, indent=2, default=str))


if __name__ == "__main__":
    main()
