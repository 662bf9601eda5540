"""Frames per second of the UI with three GL panels (flat, Gouraud, Phong) at 512 x 512 on a
bundled scene while a ray trace runs in the background, under Xvfb (llvmpipe).

Each case runs ``workbench ui --script tests/app/ui/sessions.py:Fps`` (or another session of that
file; the console script) in a
subprocess on a fresh Xvfb display (``sessions.Fps`` counts frames for 10 s after 10 warm-up
frames) and the results go to ``bench/results/ui_fps.json``:

* ``static_camera_raytrace_running`` (the issue's case): nothing moves while a 16 spp ray trace
  runs; the count stops early if the ray trace ends first (the rate is the one *while* it
  runs), then the session waits for it and logs its run time with the window open
  (``raytrace_seconds``) and the number of GL panel draws and GPU read-backs during the count
  (both 0 when nothing changes);
* ``drag_with_raytrace_panel``: the camera turns every frame (a steady mouse drag: all three
  GL panels redraw each frame, the difference view follows); the ray trace is cancelled at the
  drag's first frame and restarts once the camera has rested for
  ``jobs.RESTART_SETTLE_SECONDS``, so during the drag its panel keeps its stale image
  (``cpu_jobs_started`` counts the restarts during the count: 0);
* ``drag_gl_only``: the same drag with the three GL panels only, at full resolution
  (``--drag-resolution full``, as every case but the next: their numbers compare with the
  runs before the adaptive resolution);
* ``drag_gl_adaptive``: the same drag with the GL panels' resolution adapted to hold 30 fps
  (``--drag-resolution adaptive``, the window's default, ``ui/drag_resolution.py``);
  ``drag_scale_median`` is the scale of the panels' sides the drag settled at (median over
  the counted frames; ``drag_panel_px_median`` in pixels) and ``full_resolution_after_s``
  the time from the drag's last move until the panels show it at full resolution (both
  cases log both);
* ``raytrace_without_window``: the same 512 x 512, 16 spp ray trace rendered by the library in
  a plain process (numba's default threads), for the completion-time comparison;
* ``material_drag``: the camera rests while the chosen material's ``kd`` slider moves every
  frame (``sessions.SliderFps``; three GL panels), ``slider_drag``: the same with light 0's
  position slider moving every frame too; ``programs_compiled`` counts the GL programs the
  panels' sessions compiled during the count.

* ``idle``: the three GL panels and the ray-trace panel, untouched: once nothing is in progress
  (the ray trace, the error plot's reference and evaluations), the frames drawn and the process
  CPU time (every thread) over 10 s (``sessions.Idle``; hello_imgui idles at ``main.IDLE_FPS``),
  then a knob change from the script whose job must still deliver its image;
* ``soak``: 24 rounds of a scene switch (whitted, csg, cornell, quadrics, each with its first
  view of methods plus Gouraud or the ray caster in turn), knob changes, a short camera drag,
  the difference view and the error plot shown, each round waiting for the jobs and the plot,
  then exporting (``sessions.Soak``, 256 px panels, a fresh reference cache): the process RSS,
  the C heap, the bytes the window holds, the jobs kept and the GL objects alive after each
  round; ``soak_10min`` and ``soak_30min`` (issue #29, item 3): the same rounds for 10 and 30
  minutes.  ``rss_mb_warmup_end`` is the highest RSS over the warm-up's last cycle of scenes
  (by then every scene was seen with each added method), ``rss_mb_last_cycle`` the highest over
  the last cycle, ``rss_ratio`` the second over the first; ``rss_mb_first_minute_end`` the RSS
  of the first round logged after 60 s and of the last round;
* ``drag_indexed``: the ``drag_gl_only`` drag with every GL panel shown through
  ``indexed16-kmeans-fs`` (``sessions.Fps`` with ``display``: during the drag the panels map to
  the CLUT of their last exact image on the GPU, the exact mode is computed once the camera
  rests, ``ui/display_modes.py``);
* ``drag_gl_bare``: the ``drag_gl_only`` drag with the panels' stand-ins off (``standins =
  off``: the bare local models, the panels as they were before they drew the stand-ins).

``--cases a,b`` runs only those cases and keeps the other entries of the results file.

``cpu_ms_per_frame`` is the process CPU time (every thread: Python, llvmpipe's rasterizer
threads, jobs) per frame counted: the work a frame costs, which the machine's load does not
inflate as it does the frame rate (on a machine shared with other work the rate measures the
share of the cores the window got).  ``gui_ms_mean`` is the time in the frame's Python callbacks (panel updates + widgets); the rest
of a frame is imgui's rendering of the window on llvmpipe and the buffer swap.  The window is
``--window`` (default 1600 x 900 (was 860): the docking layout's panels window, the full width above the
control row, then holds the three 512 px panels side by side, so all three are on screen;
``panels_window`` logs that window's size; a frame costs about in proportion to the window's
pixels on llvmpipe).

Usage: python bench/ui_fps.py [--scene whitted] [--size 512] [--window 1600x900]
writes ``bench/results/ui_fps.json`` and ``docs/benchmarks/ui_fps.md``.  Needs ``Xvfb``.  ``--smoke``:
the cases ``drag_gl_only`` (its script counts frames for 10 s: it cannot be shorter without changing
its session) and ``raytrace_without_window``, 64 px panels in an 800 x 500 window.
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

from _common import Page, first_paragraph, fmt, table

ROOT = Path(__file__).resolve().parents[1]
SESSIONS = ROOT / "tests" / "app" / "ui" / "sessions.py"
"""The project's scripted sessions of the window (``workbench ui --script FILE.py:NAME``)."""
SPP = 16
"""Samples per pixel of the background ray trace (the ``fps_static`` script sets it)."""


def free_display() -> int:
    for n in range(120, 250):
        if not Path(f"/tmp/.X11-unix/X{n}").exists() and not Path(f"/tmp/.X{n}-lock").exists():
            return n
    raise RuntimeError("no free X display number")


def measure(scene: str, size: int, window: str, cpu: bool, script: str, drag: str = "full",
            methods: str | None = None) -> dict:
    """Run ``script`` in the window (three GL panels, plus the ray tracer with ``cpu``; or the
    ``methods`` given, "" for the scene's first view; ``drag``: the ``--drag-resolution``), with
    a reference cache of its own."""
    n = free_display()
    w, h = (int(x) for x in window.split("x"))
    xvfb = subprocess.Popen(["Xvfb", f":{n}", "-screen", "0", f"{w + 64}x{h + 64}x24",
                             "-nolisten", "tcp"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while not Path(f"/tmp/.X11-unix/X{n}").exists():
            time.sleep(0.05)
        if methods is None:
            methods = "flat,gouraud,phong" + (",raytrace" if cpu else "")
        with tempfile.TemporaryDirectory() as out:
            load = os.getloadavg()
            subprocess.run([str(Path(sys.executable).with_name("workbench")), "ui", scene,
                            *(["--methods", methods] if methods else []),
                            "--size", str(size), "--window", window, "--drag-resolution", drag,
                            "--script", f"{SESSIONS}:{script}", "--out", out],
                           cwd=ROOT, check=True, timeout=2400,
                           # folders of its own for the remembered window size and the
                           # references: not the user's
                           env={**os.environ, "DISPLAY": f":{n}", "WORKBENCH_CONFIG_DIR": out,
                                "WORKBENCH_REFERENCE_CACHE": str(Path(out, "references"))})
            summary = json.loads(Path(out, "summary.json").read_text())
    finally:
        xvfb.terminate()
        xvfb.wait(10)
    return {"scene": scene, "panel_size": size, "window": window,
            "methods": methods.split(",") if methods else summary["methods"],
            "gl_renderer": summary["gl_renderer"], "load_average_1_5_15_before": load,
            **summary["script"]}


def raytrace_without_window(scene: str, size: int) -> dict:
    """The ray trace of the static case in a plain process (warm kernels, default threads)."""
    code = f"""
import json, time, numba, workbench
sc = workbench.load_scene({scene!r})
workbench.render(sc, "raytrace", width=32, height=32, spp={SPP})  # load the compiled kernels
t0 = time.perf_counter()
workbench.render(sc, "raytrace", width={size}, height={size}, spp={SPP})
print(json.dumps({{"seconds": time.perf_counter() - t0, "numba_threads": numba.get_num_threads()}}))
"""
    load = os.getloadavg()
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True, timeout=900,
                         capture_output=True, text=True).stdout
    return {"scene": scene, "size": size, "spp": SPP, "load_average_1_5_15_before": load,
            **json.loads(out.strip().splitlines()[-1])}


def soak(result: dict) -> dict:
    """The soak session's rounds summed up (see the module docstring)."""
    rounds, warm = result["rounds"], result["warmup_rounds"]
    cycle = warm // 2  # the scenes' count
    result["rss_mb_warmup_end"] = max(r["rss_mb"] for r in rounds[warm - cycle + 1:warm + 1])
    result["rss_mb_last_cycle"] = max(r["rss_mb"] for r in rounds[-cycle:])
    result["rss_ratio"] = result["rss_mb_last_cycle"] / result["rss_mb_warmup_end"]
    minute = next((r for r in rounds if r["seconds"] >= 60.0), rounds[-1])
    result["rss_mb_first_minute_end"] = [minute["rss_mb"], rounds[-1]["rss_mb"]]
    result["rss_mb_peak"] = max(r["rss_mb"] for r in rounds)
    result["heap_free_mb_warmup_end_last"] = [rounds[warm].get("heap_free_mb"), rounds[-1].get("heap_free_mb")]
    result["window_mb_max"] = max(r["window_bytes"]["total"] for r in rounds) / 2**20
    result["session_seconds"] = rounds[-1].get("seconds")
    result["jobs_kept_max"] = max(r["jobs_kept"] for r in rounds)
    return result


def fmt_load(case: dict):
    """The 1-minute load average before the case ran, where recorded."""
    load = case.get("load_average_1_5_15_before")
    return None if not load else round(load[0], 2)


def tables(res: dict) -> str:
    cpu = f"{res.get('cpu_count')} CPUs, {res.get('processor') or res.get('machine')}"
    rows = []
    for name, c in res.items():
        if not isinstance(c, dict) or "fps" not in c:
            continue
        rows.append([name, c.get("window"), c.get("panel_size"), ", ".join(c.get("methods", [])), c["fps"],
                     c.get("cpu_ms_per_frame"), c.get("gui_ms_mean"), c.get("frames"), c.get("gl_panel_draws"),
                     c.get("drag_resolution"), c.get("drag_scale_median"), c.get("full_resolution_after_s"),
                     c.get("raytrace_seconds"), fmt_load(c), c.get("note", "")[:80]])
    out = [f"{cpu}; Xvfb + llvmpipe.  No outside anchor: the plain-process ray trace "
           "(`raytrace_without_window`) is the baseline of the window's background job.", "",
           table(["case", "window", "panel px", "methods", "fps", "CPU ms/frame", "GUI ms (mean)", "frames",
                  "GL panel draws", "drag resolution", "drag scale (median)", "full resolution after (s)",
                  "ray trace with the window open (s)", "load (1 min)", "note"], rows)]
    rw = res.get("raytrace_without_window")
    if rw:
        out.append(f"Ray trace without the window ({rw['size']} px, {rw['spp']} spp): {fmt(rw['seconds'])} s on "
                   f"{rw.get('numba_threads')} numba threads.\n")
    idle = res.get("idle")
    if idle and "idle" in idle:
        i = idle["idle"]
        out.append(f"Idle: {fmt(i['fps'])} fps, {fmt(i['cpu_percent_of_a_core'])} % of a core over {fmt(i['seconds'])} s.\n")
    for k in ("soak", "soak_10min", "soak_30min"):
        sk = res.get(k)
        if sk and "rss_ratio" in sk:
            a, b = sk["rss_mb_first_minute_end"]
            out.append(f"{k}: {len(sk['rounds'])} rounds in {fmt(sk['session_seconds'])} s; RSS (highest over a cycle of "
                       f"scenes) {fmt(sk['rss_mb_warmup_end'])} MB at the end of the warm-up -> "
                       f"{fmt(sk['rss_mb_last_cycle'])} MB over the last cycle (x{fmt(sk['rss_ratio'])}); "
                       f"{fmt(a)} MB after the first minute -> {fmt(b)} MB at the end; peak {fmt(sk['rss_mb_peak'])} MB; "
                       f"the window's caches at most {fmt(sk['window_mb_max'])} MB; jobs kept at most {sk.get('jobs_kept_max')}.\n")
        elif sk and "rss_mb_round4_last" in sk:  # a run before issue #29's soak rounds
            out.append(f"{k}: {len(sk['rounds'])} rounds, RSS {fmt(sk['rss_mb_round4_last'][0])} MB at round 4 -> "
                       f"{fmt(sk['rss_mb_round4_last'][1])} MB at the last; jobs kept at most {sk.get('jobs_kept_max')}.\n")
    return "\n".join(out)


PAGE = Page("ui_fps", "Frames per second of the UI window", first_paragraph(__doc__), "python bench/ui_fps.py",
            tables, smoke_note="drag_gl_only (10 s of counting) and raytrace_without_window, 64 px panels")


def main(argv=None) -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--scene", default="whitted")
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--window", default="1600x900", help="WIDTHxHEIGHT of the UI window (the "
                   "issue's 1600x900)")
    p.add_argument("--cases", default="", help="comma-separated cases to run (default: all); "
                   "the results file keeps the others' entries")
    a = PAGE.parse(p, argv)
    if a.smoke:
        a.size, a.window, a.cases = 64, "800x500", a.cases or "drag_gl_only,raytrace_without_window"
    cases = {"static_camera_raytrace_running": lambda: measure(a.scene, a.size, a.window, True, "fps_static"),
             "drag_with_raytrace_panel": lambda: measure(a.scene, a.size, a.window, True, "Fps"),
             "drag_gl_only": lambda: measure(a.scene, a.size, a.window, False, "Fps"),
             "drag_gl_adaptive": lambda: measure(a.scene, a.size, a.window, False, "Fps", "adaptive"),
             "drag_indexed": lambda: measure(a.scene, a.size, a.window, False, "fps_indexed"),
             "drag_gl_bare": lambda: measure(a.scene, a.size, a.window, False, "fps_bare"),
             "material_drag": lambda: measure(a.scene, a.size, a.window, False, "fps_material_drag"),
             "slider_drag": lambda: measure(a.scene, a.size, a.window, False, "fps_slider_drag"),
             "raytrace_without_window": lambda: raytrace_without_window(a.scene, a.size),
             "idle": lambda: measure(a.scene, a.size, a.window, True, "Idle"),
             "soak": lambda: soak(measure(a.scene, 256, a.window, True, "Soak", methods="")),
             "soak_10min": lambda: soak(measure(a.scene, 256, a.window, True, "soak_10min", methods="")),
             "soak_30min": lambda: soak(measure(a.scene, 256, a.window, True, "soak_30min", methods=""))}
    chosen = [c for c in a.cases.split(",") if c] or list(cases)
    bad = [c for c in chosen if c not in cases]
    if bad:
        p.error(f"unknown cases {bad}; known: {', '.join(cases)}")
    out = a.out / "ui_fps.json"
    res = json.loads(out.read_text()) if a.cases and out.exists() else {}
    res.pop("environment", None)
    for c in chosen:
        res[c] = cases[c]()
    res.update({"cpu_count": os.cpu_count(), "machine": platform.machine(),
                "processor": platform.processor() or platform.uname().processor})
    print(json.dumps(res, indent=1))
    PAGE.write(a, res)


if __name__ == "__main__":
    main()
