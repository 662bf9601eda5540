"""Raster throughput: flat, Gouraud and Phong at 512 x 512 on every bundled scene (llvmpipe).

For each scene and method: a :class:`RasterSession` is built (tessellation, upload and shader
compile, including llvmpipe's JIT at the first draw: ``setup_seconds`` and
``compile_seconds``, reported apart), 3 warm-up frames are drawn, then frames are timed for at
least ``--seconds`` (and at least 10 frames):

* ``fps`` / ``ms_per_frame``: a frame as a user sees it: ``draw_to`` into the FBO and
  ``ctx.finish()`` (the UI shows the FBO's texture; nothing is read back), over the whole
  window; ``fps_median`` and ``fps_best`` over batches of 5 frames (the best batch is the
  rate least disturbed by other processes on the shared cores);
* ``cpu_ms_per_frame``: CPU time of this process per frame, llvmpipe's threads included: on 2
  cores shared with other work, the wall-clock rate drops with the load average recorded in
  the file, the CPU time much less;
* ``readback_ms``: reading the finished float32 colour image back to numpy
  (``RasterSession.read_image``), for images only, timed alone (median batch);
* ``ms_with_readback``: ``draw(camera, with_depth=True)``, what ``render()`` does (colour and
  depth read back; median batch), the number to set beside pyrender's median frame.

pyrender's frame time (its offscreen render, which always reads colour and depth back) on the
same scene and camera is measured beside ours, in a child process
(``workbench.renderers.reference``).

    .venv/bin/python bench/raster_fps.py [--seconds 1.0] [--size 512] [--scenes a,b]

Writes ``bench/results/raster_fps.json`` and ``docs/benchmarks/raster_fps.md`` and prints it.  Without
pyrender its column is skipped.  ``--smoke``: ``whitted`` alone at 32 x 32, 0.05 s per rate, 2
pyrender frames.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time

import workbench
from workbench.renderers import gl
from workbench.renderers.raster import RasterSession
from workbench.scene.library import bundled
from _common import Page, first_paragraph, ratio, skip_note, table


def _rate(fn, seconds: float, batch: int = 5) -> dict:
    """Rates of ``fn`` after 3 warm-up calls, timed in batches of ``batch`` calls for at least
    ``seconds`` (and 4 batches): ``fps`` over the whole window, ``fps_median`` and
    ``fps_best`` over the batches (the best batch is the rate with the least interference
    from other processes on the shared cores), ``cpu_ms`` per call (all threads of this
    process, llvmpipe's rasteriser threads included: much less sensitive to the load)."""
    for _ in range(3):
        fn()
    rates, t0, c0 = [], time.perf_counter(), time.process_time()
    while len(rates) < 4 or time.perf_counter() - t0 < seconds:
        tb = time.perf_counter()
        for _ in range(batch):
            fn()
        rates.append(batch / (time.perf_counter() - tb))
    n = batch * len(rates)
    return {"fps": n / (time.perf_counter() - t0), "fps_median": statistics.median(rates),
            "fps_best": max(rates), "cpu_ms": 1e3 * (time.process_time() - c0) / n}


def bench_scene(name: str, size: int, seconds: float, pyrender_frames: int = 10, have_pyrender: bool = True) -> dict:
    scene = workbench.load_scene(name)
    cam = scene.camera.with_resolution(size, size)
    row = {"scene": name, "methods": {}}
    for mode in ("flat", "gouraud", "phong"):
        t0 = time.perf_counter()
        session = RasterSession(scene, mode)
        setup = time.perf_counter() - t0
        ctx = session.ctx
        fbo = session.framebuffer(size, size)

        def frame():
            session.draw_to(fbo, cam)
            ctx.finish()

        r = _rate(frame, seconds)
        read = _rate(lambda: session.read_image(fbo), seconds / 4)
        full = _rate(lambda: session.draw(cam, with_depth=True), seconds / 2)
        row["methods"][mode] = {
            "triangles": session.n_triangles,
            "culled_objects": len(session.cull_boxes),
            "setup_seconds": round(setup, 4),
            "compile_seconds": round(session.timings["compile"], 4),
            "tessellate_seconds": round(session.timings["tessellate"], 4),
            "fps": round(r["fps"], 1), "fps_median": round(r["fps_median"], 1), "fps_best": round(r["fps_best"], 1),
            "ms_per_frame": round(1e3 / r["fps"], 2), "cpu_ms_per_frame": round(r["cpu_ms"], 2),
            "readback_ms": round(1e3 / read["fps_median"], 2),
            "ms_with_readback": round(1e3 / full["fps_median"], 2),
        }
        session.release()
        print(name, mode, row["methods"][mode], flush=True)
    try:
        if not have_pyrender:
            raise RuntimeError(skip_note("pyrender"))
        from workbench.renderers.reference import frame_time_in_child
        row["pyrender"] = frame_time_in_child(name, size, size, frames=pyrender_frames)
    except Exception as e:  # reported, never fatal for the benchmark
        row["pyrender"] = {"error": str(e)}
    print(name, "pyrender", row["pyrender"], flush=True)
    return row


def tables(res: dict) -> str:
    w, h = res["size"]
    rows = []
    for sc in res["scenes"]:
        py = sc.get("pyrender", {})
        py_ms = 1e3 * py["frame_seconds_median"] if py.get("frame_seconds_median") else None
        for mode, m in sc["methods"].items():
            rows.append([sc["scene"], mode, m["triangles"], m["fps"], m["fps_best"], m["cpu_ms_per_frame"],
                         m["ms_with_readback"], py_ms if py_ms is not None else py.get("error", "–")[:60],
                         ratio(py_ms, m["ms_with_readback"])])
    return (f"{w} x {h}, {res['gl_renderer']}; load {res['load_average_1min']['before']} -> "
            f"{res['load_average_1min']['after']}.  {res['note']}.\n\n"
            + table(["scene", "method", "triangles", "fps", "fps (best batch)", "CPU ms/frame", "ms with read-back",
                     "pyrender ms/frame (anchor, median)", "pyrender / ours (with read-back)"], rows))


PAGE = Page("raster_fps", "Raster throughput: flat, Gouraud and Phong on llvmpipe", first_paragraph(__doc__),
            "python bench/raster_fps.py", tables, anchors=("pyrender",),
            smoke_note="whitted alone at 32 x 32, 0.05 s per rate")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=1.0)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--scenes", default="")
    args = PAGE.parse(ap, argv)
    frames = 10
    if args.smoke:
        args.seconds, args.size, args.scenes, frames = 0.05, 32, "whitted", 2
    names = args.scenes.split(",") if args.scenes else [p.stem for p in bundled()]
    load_before = os.getloadavg()
    have = PAGE.anchor(args, "pyrender") is not None
    rows = [bench_scene(n, args.size, args.seconds, frames, have) for n in names]
    result = {"benchmark": "raster_fps", "size": [args.size, args.size], "gl_renderer": gl.renderer_name(),
              "machine": platform.platform(), "cpu_count": os.cpu_count(),
              "load_average_1min": {"before": round(load_before[0], 2), "after": round(os.getloadavg()[0], 2)},
              "note": "2 shared cores: other processes' load (load_average) lowers these rates; "
                      "fps = draw + finish (no read-back); pyrender's frame includes its read-back: "
                      "compare it with ms_with_readback",
              "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "scenes": rows}
    print(json.dumps(result, indent=2))
    PAGE.write(args, result)


if __name__ == "__main__":
    main()
