"""Error against run time on the default scene: the quick study the main job runs, plus the
wall time of the whole study (what "about a minute" means on this machine).

    .venv/bin/python bench/study_quick.py [--scene whitted] [--study-dir /tmp/study_quick]

Writes ``bench/results/study_quick.json`` (per point: method, knob value, warm median time,
compile time, RMSE, FLIP, Pareto flag; the study's total wall time, the reference's compile time
apart, the machine load) and ``docs/benchmarks/study_quick.md`` and prints it.  The study's own
files go to ``--study-dir`` (``--out`` is the results folder, as in every bench script).
``--smoke``: the quick study at 32 x 24, one warm run per point, of flat, Phong, ray casting and the
Whitted ray tracer (the others' child processes and converged references take most of a study's
time; the study's code path is the same).
"""
from __future__ import annotations

import argparse
import json
import time

import workbench
from _common import Page, first_paragraph, table
from workbench.compare.study import study


SMOKE_METHODS = ["flat", "phong", "raycast", "raytrace"]


def tables(res: dict) -> str:
    ref = res["reference"]
    w, h = res["size"]
    rows = [[p["method"], p["knob"], p["value"], p["status"], p["time_s"], p["compile_s"], p["rmse"], p["flip"],
             p["pareto"]] for p in res["points"]]
    return (f"`{res['scene']}` at {w} x {h}, warm runs per point: {res['repeat']} (their median).  The anchor is the "
            f"study's reference, `{ref['method']}` {ref.get('options', {})} ({ref.get('reason', '')}), "
            f"{ref.get('time_s', 0):.3f} s.  Whole study: **{res['study_wall_s']:.1f} s** of wall time.\n\n"
            + table(["method", "knob", "value", "status", "time (s)", "compile (s)", "RMSE", "FLIP", "Pareto"], rows))


PAGE = Page("study_quick", "The quick study: error against run time on the default scene", first_paragraph(__doc__),
            "python bench/study_quick.py", tables, smoke_note="32 x 24, one warm run per point, " + ", ".join(SMOKE_METHODS))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="whitted")
    ap.add_argument("--study-dir", default="/tmp/study_quick", help="the study's own files")
    a = PAGE.parse(ap, argv)
    size, repeat, methods = ((32, 24), 1, SMOKE_METHODS) if a.smoke else (None, None, None)
    if a.smoke and a.study_dir == ap.get_default("study_dir"):
        a.study_dir = str(a.out / "study")
    t0 = time.perf_counter()
    res = study(workbench.load_scene(a.scene), a.study_dir, quick=True, progress=False, size=size, repeat=repeat,
                methods=methods)
    wall = time.perf_counter() - t0
    keep = ("method", "knob", "value", "status", "time_s", "compile_s", "rmse", "flip", "pareto")
    out = {"scene": a.scene, "size": res["size"], "repeat": res["repeat"], "study_wall_s": wall,
           "reference": res["reference"], "machine": res["machine"],
           "points": [{k: p.get(k) for k in keep} for p in res["points"]]}
    print(json.dumps(out, indent=2, default=str))
    PAGE.write(a, json.loads(json.dumps(out, default=str)))


if __name__ == "__main__":
    main()
