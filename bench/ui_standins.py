"""What the stand-ins cost the window's GL panels (issue 15 item 4): per camera-drag frame
(the main pass only: the maps do not depend on the camera), per light-colour frame (the
environment maps redrawn, the shadow maps kept) and per light-move frame (both redrawn), for
flat, Gouraud and Phong panels of ``whitted`` at 512 x 384 drawn as the window draws them
(``gl_sessions``-built sessions, ``draw_to`` their framebuffer, ``finish``), stand-ins on
(the default) and off.  Wall and CPU milliseconds per frame (the mean over the frames; the
machine is shared: the load average is recorded).

    .venv/bin/python bench/ui_standins.py   ->  bench/results/ui_standins.json, docs/benchmarks/ui_standins.md

``--smoke``: 64 x 48 panels, 2 frames per case.
"""
from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace

import numpy as np

import workbench
from _common import Page, first_paragraph, ratio, table
from workbench.app.ui import camera as cam
from workbench.renderers import gl
from workbench.renderers.base import get_renderer

METHODS = ("flat", "gouraud", "phong")
FRAMES = 30
SIZE = (512, 384)


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
    camera = scene.camera.with_resolution(*SIZE)
    scene = scene.with_camera(camera)
    sessions = {m: get_renderer(m).session(scene, *SIZE, ctx=ctx, **({"standins": standins}
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


def tables(results: dict) -> str:
    runs = results["runs"]
    off = runs.get("off", {})
    rows = [[s] + [f"{r[k]['wall_ms']:.1f} ({r[k]['cpu_ms']:.1f})" for k in ("drag", "light_colour", "light_move")]
            + [ratio(r["light_move"]["cpu_ms"], off.get("light_move", {}).get("cpu_ms"))] for s, r in runs.items()]
    w, h = results["size"]
    return (f"{' + '.join(results['methods'])} panels, {results['scene']} {w} x {h}, {results['frames']} frames each; "
            f"load {results['load_before']:.1f} -> {results['load_after']:.1f}; {results['gl_renderer']}.  "
            "No outside anchor: stand-ins off is the baseline.\n\n"
            + table(["stand-ins", "drag ms (CPU)", "light colour ms (CPU)", "light move ms (CPU)",
                     "light move CPU: this / off"], rows)
            + f"\nMaps drawn by the drag (stand-ins on): {runs.get('on', {}).get('maps_drawn_by_drag')}.\n")


PAGE = Page("ui_standins", "What the stand-ins cost the window's GL panels", first_paragraph(__doc__),
            "python bench/ui_standins.py", tables, smoke_note="64 x 48 panels, 2 frames per case")


def main(argv=None) -> None:
    global FRAMES, SIZE
    args = PAGE.parse(argparse.ArgumentParser(description=__doc__.splitlines()[0]), argv)
    if args.smoke:
        FRAMES, SIZE = 2, (64, 48)
    results = {"benchmark": "ui_standins", "scene": "whitted", "size": list(SIZE), "methods": list(METHODS),
               "frames": FRAMES, "load_before": os.getloadavg()[0],
               "gl_renderer": gl.renderer_name(gl.context()),
               "runs": {s: run(s) for s in ("on", "off")}, "load_after": os.getloadavg()[0]}
    print(tables(results))
    PAGE.write(args, results)


if __name__ == "__main__":
    main()
