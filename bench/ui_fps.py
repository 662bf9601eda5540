"""Frames per second of the UI with three GL panels (flat, Gouraud, Phong) at 512 x 512 on a
bundled scene while a ray trace runs in the background, under Xvfb (llvmpipe).

Runs ``python -m workbench.app.ui.main --test-script fps`` in a subprocess on a fresh Xvfb
display and writes ``bench/results/ui_fps.json``.  ``gui_ms_mean`` is the time spent in the
frame's Python callback (raster draws + read-back + texture uploads + widgets); the rest of a
frame is imgui's own rendering of the window and the buffer swap.

Each run counts frames for 10 s after 10 warm-up frames (``scripts.Fps``): with a static camera
while a 16 spp ray trace runs (the issue's case), during a steady drag (every panel changes each
frame, the ray trace restarts) and during a drag with the GL panels only (baseline).

Usage: python bench/ui_fps.py [--scene whitted] [--size 512]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def free_display() -> int:
    for n in range(120, 250):
        if not Path(f"/tmp/.X11-unix/X{n}").exists() and not Path(f"/tmp/.X{n}-lock").exists():
            return n
    raise RuntimeError("no free X display number")


def measure(scene: str, size: int, cpu: bool, script: str = "fps") -> dict:
    n = free_display()
    xvfb = subprocess.Popen(["Xvfb", f":{n}", "-screen", "0", "1920x1200x24", "-nolisten", "tcp"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while not Path(f"/tmp/.X11-unix/X{n}").exists():
            time.sleep(0.05)
        methods = "flat,gouraud,phong" + (",raytrace" if cpu else "")
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([sys.executable, "-m", "workbench.app.ui.main", scene, "--methods",
                            methods, "--size", str(size), "--test-script", script, "--out", out],
                           cwd=ROOT, env={**os.environ, "DISPLAY": f":{n}"}, check=True,
                           timeout=600)
            summary = json.loads(Path(out, "summary.json").read_text())
    finally:
        xvfb.terminate()
        xvfb.wait(10)
    return {"scene": scene, "panel_size": size, "methods": methods.split(","),
            "gl_renderer": summary["gl_renderer"], **summary["script"]}


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--scene", default="whitted")
    p.add_argument("--size", type=int, default=512)
    a = p.parse_args()
    load = os.getloadavg()
    res = {"static_camera_raytrace_spp16_running": measure(a.scene, a.size, True, "fps_static"),
           "drag_with_raytrace_restarting": measure(a.scene, a.size, True),
           "drag_gl_only": measure(a.scene, a.size, False),
           "cpu_count": os.cpu_count(), "load_average_1_5_15_before": load}
    out = ROOT / "bench" / "results" / "ui_fps.json"
    out.write_text(json.dumps(res, indent=1))
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
