"""What the stand-ins cost the window's GL panels (issue 15 item 4): per camera-drag frame
(the main pass only: the maps do not depend on the camera), per light-colour frame (the
environment maps redrawn, the shadow maps kept) and per light-move frame (both redrawn), for
flat, Gouraud and Phong panels of ``whitted`` at 512 x 384 drawn as the window draws them
(``gl_sessions``-built sessions, ``draw_to`` their framebuffer, ``finish``), stand-ins on
(the default) and off.  Wall and CPU milliseconds per frame (the mean over the frames; the
machine is shared: the load average is recorded).

    .venv/bin/python bench/ui_standins.py   ->  bench/results/ui_standins.{json,md}
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import workbench
from workbench.app.ui import camera as cam
from workbench.renderers import gl
from workbench.renderers.base import get_renderer

OUT = Path(__file__).resolve().parent / "results"
METHODS = ("flat", "gouraud", "phong")
FRAMES = 30


def _frame(ctx, sessions, camera) -> None:
    for s in sessions.values():
        s.draw_to(s.framebuffer(camera.width, camera.height), camera)
    ctx.finish()


def _timed(ctx, sessions, cameras, before=None) -> dict:
    """Mean wall and CPU ms per frame over ``cameras`` (``before(k)`` runs first each frame)."""
    wall = cpu = 0.0
    for k, c in enumerate(cameras):
        t0, c0 = time.perf_counter(), time.process_time()
        if before is not None:
            before(k)
        _frame(ctx, sessions, c)
        wall += time.perf_counter() - t0
        cpu += time.process_time() - c0
    return {"wall_ms": 1e3 * wall / len(cameras), "cpu_ms": 1e3 * cpu / len(cameras)}


def run(standins: str) -> dict:
    ctx = gl.context()
    scene = workbench.load_scene("whitted")
    camera = scene.camera.with_resolution(512, 384)
    scene = scene.with_camera(camera)
    sessions = {m: get_renderer(m).session(scene, 512, 384, ctx=ctx, **({"standins": standins}
                                                                       if m != "flat" else {}))
                for m in METHODS}
    _frame(ctx, sessions, camera)  # first frame: llvmpipe's code generation
    drag = [cam.orbit(camera, 0.01 * k, 0.004 * k) for k in range(1, FRAMES + 1)]
    maps0 = {m: dict(s.maps_drawn) for m, s in sessions.items()}
    out = {"drag": _timed(ctx, sessions, drag)}
    out["maps_drawn_by_drag"] = {m: {k: s.maps_drawn[k] - maps0[m][k] for k in s.maps_drawn}
                                 for m, s in sessions.items()}
    light = scene.lights[0]

    def colour(k):
        edited = replace(scene, lights=(replace(light, color=(1.0, 1.0 - 0.01 * k, 1.0)), *scene.lights[1:]))
        assert all(s.update(edited) for s in sessions.values())

    def move(k):
        p = np.asarray(light.position) + [0.02 * k, 0.0, 0.0]
        edited = replace(scene, lights=(replace(light, position=tuple(p)), *scene.lights[1:]))
        assert all(s.update(edited) for s in sessions.values())

    colour(0)
    _frame(ctx, sessions, camera)  # the live programs' first frame
    out["light_colour"] = _timed(ctx, sessions, [camera] * FRAMES, colour)
    out["light_move"] = _timed(ctx, sessions, [camera] * FRAMES, move)
    out["maps_drawn"] = {m: dict(s.maps_drawn) for m, s in sessions.items()}
    for s in sessions.values():
        s.release()
    return out


def main() -> None:
    results = {"benchmark": "ui_standins", "scene": "whitted", "size": [512, 384], "methods": list(METHODS),
               "frames": FRAMES, "load_before": os.getloadavg()[0],
               "gl_renderer": gl.renderer_name(gl.context()),
               "runs": {s: run(s) for s in ("on", "off")}, "load_after": os.getloadavg()[0]}
    OUT.mkdir(exist_ok=True)
    (OUT / "ui_standins.json").write_text(json.dumps(results, indent=1))
    rows = ["| stand-ins | drag ms (CPU) | light colour ms (CPU) | light move ms (CPU) |", "|---|---|---|---|"]
    for s, r in results["runs"].items():
        rows.append(f"| {s} | " + " | ".join(f"{r[k]['wall_ms']:.1f} ({r[k]['cpu_ms']:.1f})"
                                           for k in ("drag", "light_colour", "light_move")) + " |")
    note = (f"\nflat + gouraud + phong panels, whitted 512x384, {FRAMES} frames each, "
            f"load {results['load_before']:.1f} -> {results['load_after']:.1f}, {results['gl_renderer']}; "
            f"maps drawn by the drag: {results['runs']['on']['maps_drawn_by_drag']}\n")
    (OUT / "ui_standins.md").write_text("\n".join(rows) + "\n" + note)
    print("\n".join(rows) + note)


if __name__ == "__main__":
    main()
