"""The ray tracer against POV-Ray 3.7 on the same scenes, same machine, same run.

1. Whitted scene (``scenes/whitted.toml``), 640 x 480, no antialiasing, maximum trace level
   5, adaptive depth control 1/255 (POV-Ray's default ``adc_bailout``; our ``threshold``), 2
   threads for both.
2. A mesh of 81,920 triangles (``scenes/mesh.toml``: the procedural blob, a ``mesh2`` with its
   vertex normals).

Both are written for POV-Ray by the ``povray`` method's exporter
(:mod:`workbench.renderers.povray_sdl`) into a temporary directory.  The ``povray`` method
itself (export + POV-Ray process + read-back, in this process) is timed on the Whitted scene,
and its image compared with the ray tracer's.

Rays per second, counted the same way for both: every ray each program actually traced, by
kind.  POV-Ray: its "Rays" (eye + reflected + refracted) plus its "Shadow Ray Tests", over its
"Trace Time" (which excludes its start-up and parsing) and over the CPU-seconds it reports
for the trace (a fairer measure on a shared, loaded machine).  Ours: primary + shadow feelers
+ reflected + refracted rays over our trace phase (``timings["trace"]``: camera rays, tracing,
shading; and its CPU seconds ``timings["trace_cpu"]``; warm JIT cache).  Each is the best of 7
runs, POV-Ray's and ours alternating (:func:`alternate`): the second thread of this shared
machine comes and goes, and its speed drifts over minutes, so that 2-thread trace times of
the same render vary by up to 50 % between runs taken minutes apart.
The two programs do not trace the same number of rays for the same picture (which shadow tests each skips and how each applies the
bail-out differ in detail: POV-Ray reports about 18 % more rays on the Whitted scene), so the JSON also gives the ratio
of the trace times for the same image (``trace_time_ratio``), which does not depend on how
rays are counted.  Whole commands: POV-Ray's process wall time against ``workbench render
...`` as a process (Python start-up, imports, scene loading, warm numba cache, PNG writing),
best of the same 7 alternating runs each.
Our commands run with Python's bytecode cache on, as for a user (``PYTHONDONTWRITEBYTECODE``
is removed from their environment).  Cold compile: the same render in a fresh process with an
empty numba cache directory (it
compiles the kernels this scene needs: the fused kernel of :mod:`workbench.renderers.raytrace`).
The load average is recorded before and after (the machine is shared).

Writes ``bench/results/povray_whitted.json`` and ``docs/benchmarks/povray_whitted.md`` and prints
it.  Run: ``.venv/bin/python bench/povray_whitted.py``.  Without POV-Ray our side is measured alone
(its columns skipped).  ``--smoke``: 64 x 48, one run each, no cold compile (minutes on an empty cache)
and no warm-up command.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import Page, first_paragraph, fmt, ratio, skip_note, table

ROOT = Path(__file__).resolve().parents[1]
W, H = 640, 480
THRESHOLD = 1.0 / 255.0
PY = sys.executable


def _povray_once(pov: Path, out: Path) -> dict:
    """Run POV-Ray once; parse its statistics."""
    cmd = ["povray", f"+W{W}", f"+H{H}", "-A", "+MV3.7", "Work_Threads=2", "-D", f"+O{out}", f"+I{pov}"]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=pov.parent)
    wall = time.perf_counter() - t0
    log = p.stdout + p.stderr
    if p.returncode != 0:
        raise RuntimeError(f"povray failed:\n{log[-2000:]}")

    def num(pattern):
        m = re.search(pattern, log)
        return float(m.group(1)) if m else 0.0
    rays = num(r"Rays:\s+(\d+)")
    shadow = num(r"Shadow Ray Tests:\s+(\d+)")
    trace = num(r"Trace Time:.*\(([\d.]+) seconds\)")
    cpu = num(r"Trace Time:.*\n.*with ([\d.]+) CPU-seconds")
    return dict(command=" ".join(cmd), wall_s=wall, trace_s=trace, trace_cpu_s=cpu, rays=rays, shadow_rays=shadow,
                reflected=num(r"Reflected Rays:\s+(\d+)"), refracted=num(r"Refracted Rays:\s+(\d+)"),
                total_rays=rays + shadow, mrays_per_s=(rays + shadow) / max(trace, 1e-9) / 1e6,
                mrays_per_cpu_s=(rays + shadow) / max(cpu, 1e-9) / 1e6)


def alternate(pov_file: Path | None, scene_name: str, tmp: Path, warm_cache: str | None = None,
              repeats: int = 7) -> tuple[dict | None, dict, dict | None]:
    """POV-Ray and ours run alternately ``repeats`` times each: a POV-Ray command, our render
    in this process (warm JIT cache) and, with ``warm_cache``, our whole command.  The shared
    machine's speed drifts over minutes (other guests on the host): alternating exposes both
    programs to the same drift.  Returns POV-Ray's statistics of its best trace (its ``wall_s``
    the best whole command), ours of our best trace, and our best whole command (or None).
    ``pov_file`` None: POV-Ray is absent, ours alone (its statistics None)."""
    import numba

    import workbench
    numba.set_num_threads(2)
    scene = workbench.load_scene(scene_name)
    workbench.render(scene, "raytrace", width=32, height=24)  # JIT (or cache load)
    povs, ours, cmds = [], [], []
    for i in range(repeats):
        if pov_file is not None:
            povs.append(_povray_once(pov_file, tmp / f"{scene_name}_pov.png"))
        ours.append(workbench.render(scene, "raytrace", width=W, height=H, threshold=THRESHOLD, max_depth=5))
        if warm_cache is not None:
            cmds.append(ours_command(scene_name, warm_cache, tmp / f"{scene_name}_{i}.png"))
    pov = dict(min(povs, key=lambda d: d["trace_s"]), wall_s=min(d["wall_s"] for d in povs)) if povs else None
    best = min(ours, key=lambda r: r.timings["trace"])
    st = best.stats
    mine = dict(trace_s=best.timings["trace"], trace_cpu_s=best.timings["trace_cpu"], total_s=best.timings["total"],
                bvh_build_s=best.timings.get("bvh_build", 0.0), total_rays=st["total_rays"],
                primary=st["primary_rays"], shadow_rays=st["shadow_rays"],
                reflected=st["reflected_rays"], refracted=st["refracted_rays"],
                mrays_per_s=st["total_rays"] / best.timings["trace"] / 1e6,
                mrays_per_cpu_s=st["total_rays"] / best.timings["trace_cpu"] / 1e6)
    return pov, mine, (min(cmds, key=lambda d: d["wall_s"]) if cmds else None)


def ours_command(scene: str, cache_dir: str, out: Path) -> dict:
    """``workbench render`` as a separate process; returns wall time and its timings."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir, NUMBA_NUM_THREADS="2")
    # as a user runs it: with Python's bytecode cache (a harness's PYTHONDONTWRITEBYTECODE
    # would recompile every workbench module at each start, ~0.05 s)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    js = out.with_suffix(".json")
    cmd = [str(Path(PY).parent / "workbench"), "render", scene, "-m", "raytrace", "-o", str(out),
           "--size", f"{W}x{H}", "--set", f"threshold={THRESHOLD}", "--set", "max_depth=5",
           "--set", "progress=false", "--json", str(js)]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"workbench render failed:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    t = json.loads(js.read_text())["timings"]
    return dict(command=" ".join(cmd[1:]), wall_s=wall, compile_s=t["compile"], trace_s=t["trace"])


def export_pov(scene_name: str, path: Path) -> None:
    """A bundled scene as POV-Ray SDL through the ``povray`` method's exporter
    (:mod:`workbench.renderers.povray_sdl`), with our depth and threshold."""
    import workbench
    from workbench.renderers.povray_sdl import export
    ex = export(workbench.load_scene(scene_name), W, H, max_trace_level=5, adc_bailout=THRESHOLD)
    assert not ex.files and not ex.left_out, ex.left_out  # both benchmark scenes export whole
    path.write_text(ex.sdl)


def povray_method(scene_name: str, repeats: int = 3) -> dict:
    """The ``povray`` method in this process (export, POV-Ray process, read-back), best of
    ``repeats``, and how far its image is from the ray tracer's (clipped at 1, as POV-Ray's
    output): the fraction of pixels beyond 1e-4 and the mean difference."""
    import workbench
    scene = workbench.load_scene(scene_name)
    runs = [workbench.render(scene, "povray", width=W, height=H, max_trace_level=5, adc_bailout=THRESHOLD,
                             threads=2) for _ in range(repeats)]
    best = min(runs, key=lambda r: r.timings["total"])
    ours = workbench.render(scene, "raytrace", width=W, height=H, threshold=THRESHOLD, max_depth=5,
                            transmissive_shadows=True).image
    d = np.abs(best.image - np.minimum(ours, 1.0)).max(-1)
    return dict(total_s=best.timings["total"], export_s=best.timings["export"],
                povray_process_s=best.timings["povray_process"], trace_s=best.timings["trace"],
                image_vs_raytrace=dict(fraction_beyond_1em4=float((d > 1e-4).mean()),
                                       mean_abs=float(d.mean()), max_abs=float(d.max())))


def tables(res: dict) -> str:
    out = [f"{res['size']}, trace level {res['max_depth']}, threshold / adc_bailout {res['threshold_adc_bailout']:.5f}; "
           f"{res['machine']}.  Rays counted: {res['ray_counting']}.", ""]
    if res.get("povray_absent"):
        out += [res["povray_absent"] + ".", ""]
    for name in ("whitted", "mesh"):
        r = res.get(name)
        if not r:
            continue
        pov, ours = r.get("povray") or {}, r["ours_trace"]
        warm = r.get("ours_command_warm") or {}
        title = "Whitted scene" if name == "whitted" else f"mesh, {r.get('triangles')} triangles"
        def row(label, key, theirs, mine, faster):
            a, b = theirs.get(key), mine.get(key)
            return [label, a, b, (ratio(a, b) if faster == "smaller" else ratio(b, a)) if faster else "–"]
        rows = [row("trace (s)", "trace_s", pov, ours, "smaller"),
                row("trace CPU (s)", "trace_cpu_s", pov, ours, "smaller"),
                row("rays traced", "total_rays", pov, ours, None),
                row("Mrays/s", "mrays_per_s", pov, ours, "larger"),
                row("Mrays per CPU-s", "mrays_per_cpu_s", pov, ours, "larger"),
                row("whole command, warm (s)", "wall_s", pov, warm, "smaller")]
        out += [f"## {title}", "", table(["", "POV-Ray 3.7 (anchor)", "ours", "ours faster by (x)"], rows)]
        cold = r.get("ours_command_cold")
        extra = []
        if cold:
            extra.append(f"our command on an empty numba cache: {fmt(cold['wall_s'])} s (compile {fmt(cold['compile_s'])} s)")
        pm = r.get("povray_method")
        if pm:
            iv = pm["image_vs_raytrace"]
            extra.append(f"the `povray` method (export, process, read-back): {fmt(pm['total_s'])} s; its image against "
                         f"the ray tracer's: {fmt(100 * iv['fraction_beyond_1em4'])} % of pixels beyond 1e-4, max "
                         f"{fmt(iv['max_abs'])}")
        if r.get("targets"):
            extra.append("targets: " + ", ".join(f"{k}: {'met' if v else 'not met'}" for k, v in r["targets"].items()))
        out += [f"* {e}" for e in extra] + [""]
    return "\n".join(out)


PAGE = Page("povray_whitted", "The ray tracer against POV-Ray 3.7", first_paragraph(__doc__),
            "python bench/povray_whitted.py", tables, anchors=("povray",), variants=True,
            smoke_note="64 x 48, one run each, no cold compile")


def main(argv=None) -> dict:
    global W, H
    import argparse
    args = PAGE.parse(argparse.ArgumentParser(description=__doc__.splitlines()[0]), argv)
    repeats, method_repeats = 7, 3
    if args.smoke:
        W, H, repeats, method_repeats = 64, 48, 1, 1
    have = PAGE.anchor(args, "povray") is not None
    res: dict = {"machine": f"{os.cpu_count()} CPUs (shared), both renderers on 2 threads",
                 "load_average_start": os.getloadavg(),
                 "size": f"{W}x{H}", "threshold_adc_bailout": THRESHOLD, "max_depth": 5,
                 "ray_counting": "every ray traced, by kind: POV-Ray's Rays (eye + reflected + refracted) "
                                 "+ Shadow Ray Tests; ours primary + shadow feelers + reflected + refracted"}
    if not have:
        res["povray_absent"] = skip_note("povray")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        # --- Whitted
        # (the smoke run skips the cold compile: minutes of kernel compiles on an empty cache)
        cold = None if args.smoke else ours_command("whitted", str(tmp / "cold_cache"), tmp / "cold.png")
        warm_cache = os.environ.get("NUMBA_CACHE_DIR") or str(ROOT / ".numba_cache")
        if not args.smoke:
            ours_command("whitted", warm_cache, tmp / "w0.png")  # make sure the cache is warm
        whitted_pov = tmp / "whitted.pov" if have else None
        if have:
            export_pov("whitted", whitted_pov)
        pov, inproc, warm = alternate(whitted_pov, "whitted", tmp, warm_cache, repeats)
        res["whitted"] = dict(
            povray=pov, ours_trace=inproc, ours_command_warm=warm, ours_command_cold=cold,
            numba_cold_compile_s=cold["compile_s"] if cold else None)
        if have:
            res["whitted"].update(
                rays_per_s_ratio=inproc["mrays_per_s"] / pov["mrays_per_s"],
                rays_per_cpu_s_ratio=inproc["mrays_per_cpu_s"] / pov["mrays_per_cpu_s"],
                trace_time_ratio=pov["trace_s"] / inproc["trace_s"],
                command_ratio_pov_over_ours=pov["wall_s"] / warm["wall_s"],
                povray_method=povray_method("whitted", method_repeats),
                targets={"rays_per_s_ratio >= 2": inproc["mrays_per_s"] / pov["mrays_per_s"] >= 2,
                         "warm command no slower than POV-Ray": warm["wall_s"] <= pov["wall_s"]})
        # --- mesh
        mesh_pov = tmp / "mesh_blob.pov" if have else None
        if have:
            export_pov("mesh", mesh_pov)
        povm, oursm, _ = alternate(mesh_pov, "mesh", tmp, None, repeats)
        warm_m = ours_command("mesh", warm_cache, tmp / "m.png")
        res["mesh"] = dict(triangles=81920, povray=povm, ours_trace=oursm, ours_command_warm=warm_m)
        if have:
            res["mesh"].update(
                rays_per_s_ratio=oursm["mrays_per_s"] / povm["mrays_per_s"],
                rays_per_cpu_s_ratio=oursm["mrays_per_cpu_s"] / povm["mrays_per_cpu_s"],
                trace_time_ratio=povm["trace_s"] / oursm["trace_s"],
                targets={"rays_per_s_ratio >= 3": oursm["mrays_per_s"] / povm["mrays_per_s"] >= 3})
    res["load_average_end"] = os.getloadavg()
    print(json.dumps(res, indent=2))
    return PAGE.write(args, res)


if __name__ == "__main__":
    main()
