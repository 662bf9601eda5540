"""The GPU side of one camera-drag frame of the window, measured apart from the window: three
512 x 384 GL panels (flat, Gouraud, Phong on whitted) and the difference view drawn into a
1600 x 900 framebuffer standing for the window, in a headless EGL context (llvmpipe).

Sequences, run in turn frame after frame in one process (so that a load that varies over
the run weighs on each alike) and timed from the first call to ``glFinish``, wall and
process CPU time (every thread: llvmpipe's rasteriser threads included):

* ``draws``: the three panels' draws alone (no wait between them);
* ``window_passes``: what a drag frame does now (``ui/panel_refresh.py``,
  ``ui/panel_show.py``): the window cleared, the draws, the difference pass and its statistics
  reduced on the GPU, then each panel sRGB-encoded and the difference colour-mapped straight into the window;
* ``encode_blit``: the sequence it replaced: ``glFinish`` after each draw, each panel
  encoded into an RGBA8 display texture, the difference map read back for its maximum and
  mean and colour-mapped into a texture, then the four textures copied into the window by
  ``glBlitFramebuffer`` (scaled, nearest, scissored);
* ``encodes`` and ``window_encodes``: the three sRGB encodings alone, into textures or into the
  window.

Usage: python bench/ui_frame_gpu.py [--frames 40]  ->  bench/results/ui_frame_gpu.json and
docs/benchmarks/ui_frame_gpu.md.  ``--smoke``: 2 counted frames.
"""
from __future__ import annotations

import argparse
import ctypes
import os
import time
from dataclasses import replace

import numpy as np
from _common import Page, first_paragraph, ratio, table

WINDOW = (1600, 900)
PANEL = (512, 384)
RECTS = [(10 + k * 520, 400, 508, 381) for k in range(3)] + [(10, 10, 340, 255)]
"""Where the panels and the difference view sit in the window (x, y from the bottom, w, h)."""


class WindowStandIn:
    """The context seen by :class:`~workbench.app.ui.display_passes.DisplayPasses` with ``screen``, a
    1600 x 900 framebuffer, as the window's."""

    def __init__(self, ctx):
        self._ctx, self.screen = ctx, ctx.simple_framebuffer(WINDOW)

    def __getattr__(self, name):
        return getattr(self._ctx, name)


def tables(res: dict) -> str:
    ms = res["ms_per_frame"]
    base = ms.get("encode_blit", {}).get("wall_ms")
    return (f"{res['frames']} frames after 2 warm-up frames; window {res['window'][0]} x {res['window'][1]}, panels "
            f"{res['panel'][0]} x {res['panel'][1]}; {res['gl_renderer']}; load {[round(x, 2) for x in res.get('load_average_1_5_15_before', [])]} "
            f"-> {[round(x, 2) for x in res.get('load_average_after', [])]}.  No outside anchor: `encode_blit` (the sequence `window_passes` "
            "replaced) is the baseline.\n\n"
            + table(["sequence", "wall ms / frame", "CPU ms / frame", "wall: encode_blit / this"],
                    [[k, v["wall_ms"], v["cpu_ms"], ratio(base, v["wall_ms"])] for k, v in ms.items()]))


PAGE = Page("ui_frame_gpu", "The GPU side of one camera-drag frame", first_paragraph(__doc__),
            "python bench/ui_frame_gpu.py", tables, smoke_note="2 counted frames")


def main(argv=None) -> None:
    import workbench
    from workbench.app.ui import camera as cam
    from workbench.app.ui.display_passes import SCALE_FLOOR, DisplayPasses
    from workbench.renderers import gl
    from workbench.renderers.base import get_renderer
    p = argparse.ArgumentParser()
    p.add_argument("--frames", type=int, default=40)
    a = PAGE.parse(p, argv)
    if a.smoke:
        a.frames = 2
    ctx = gl.context()
    win = WindowStandIn(ctx)
    screen, passes = win.screen, DisplayPasses(win)
    scene = workbench.load_scene("whitted")
    camera = replace(scene.camera, width=PANEL[0], height=PANEL[1])
    sessions = [get_renderer(m).session(scene, ctx=ctx) for m in ("flat", "gouraud", "phong")]
    fbos = [s.framebuffer(*PANEL) for s in sessions]
    near_far = sessions[0].near_far(camera)
    textures = [ctx.texture(PANEL, 4) for _ in range(4)]
    values = ctx.texture(PANEL, 1, dtype="f4")
    table = ctx.texture((256, 1), 3, (np.arange(768) % 256).astype(np.uint8).tobytes(), alignment=1)
    egl = ctypes.CDLL("libEGL.so.1")
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    u, i = ctypes.c_uint, ctypes.c_int
    bind = ctypes.CFUNCTYPE(None, u, u)(egl.eglGetProcAddress(b"glBindFramebuffer"))
    blit = ctypes.CFUNCTYPE(None, i, i, i, i, i, i, i, i, u, u)(egl.eglGetProcAddress(b"glBlitFramebuffer"))
    turn = {"k": 0}
    sources = [f.color_attachments[0] for f in fbos]

    def draws(wait: bool) -> None:
        turn["k"] += 1
        c = cam.orbit(camera, 0.002 * turn["k"], 0.0)
        for s, f in zip(sessions, fbos):
            s.draw_to(f, c, *near_far)
            if wait:
                ctx.finish()

    def to_window(name, inputs, rect, **uniforms):
        x, y, w, h = rect
        ctx.scissor = rect
        passes.to_window(name, inputs, (0, 0, *PANEL), (x, y + h, x + w, y), **uniforms)

    def window_encodes() -> None:
        screen.use()
        for src, rect in zip(sources, RECTS):
            to_window("srgb", {"u_linear": src}, rect, u_flip=1)
        ctx.scissor = None

    def window_passes() -> None:
        screen.use()
        ctx.clear(0.1, 0.1, 0.1, 1.0)
        draws(False)
        passes.difference((sources[0], True), (sources[1], True), values)
        stats = passes.statistics(values)
        window_encodes()
        screen.use()
        to_window("colour_map", {"u_value": values, "u_table": table, "u_stats": stats}, RECTS[3],
                  u_floor=SCALE_FLOOR)
        ctx.scissor = None

    def encodes() -> None:
        for src, tex in zip(sources, textures):
            passes.encode(src, tex, True)

    def encode_blit() -> None:
        screen.use()
        ctx.clear(0.1, 0.1, 0.1, 1.0)
        draws(True)
        encodes()
        passes.difference((sources[0], True), (sources[1], True), values)
        err = np.frombuffer(values.read(), np.float32)
        float(err.max()), float(err.mean())
        passes.colour_map(values, table, passes.statistics(values), textures[3])
        screen.use()
        reads = [ctx.framebuffer(color_attachments=[t]) for t in textures]
        for fbo, (x, y, w, h) in zip(reads, RECTS):
            ctx.scissor = (x, y, w, h)
            bind(0x8CA8, fbo.glo)
            bind(0x8CA9, screen.glo)
            blit(0, 0, *PANEL, x, y + h, x + w, y, 0x4000, 0x2600)  # COLOR_BUFFER_BIT, NEAREST
        ctx.scissor = None
        bind(0x8D40, screen.glo)
        ctx.finish()
        for fbo in reads:
            gl.release_framebuffer(fbo)

    cases = {"draws": lambda: draws(False), "window_passes": window_passes,
             "encode_blit": encode_blit, "encodes": encodes, "window_encodes": window_encodes}
    sums = {k: [0.0, 0.0] for k in cases}
    load = os.getloadavg()
    for rep in range(a.frames + 2):
        for name, run in cases.items():
            ctx.finish()
            t0, c0 = time.perf_counter(), time.process_time()
            run()
            ctx.finish()
            if rep >= 2:  # two warm-up frames
                sums[name][0] += time.perf_counter() - t0
                sums[name][1] += time.process_time() - c0
    ms = {k: {"wall_ms": w / a.frames * 1e3, "cpu_ms": c / a.frames * 1e3} for k, (w, c) in sums.items()}
    res = {"frames": a.frames, "window": WINDOW, "panel": PANEL, "gl_renderer": gl.renderer_name(ctx),
           "load_average_1_5_15_before": load, "load_average_after": os.getloadavg(),
           "ms_per_frame": ms}
    PAGE.write(a, res)
    for k, v in ms.items():
        print(f"{k:<16} wall {v['wall_ms']:6.2f} ms  CPU {v['cpu_ms']:6.2f} ms")
    print("load", [round(x, 2) for x in load], "->", [round(x, 2) for x in res["load_average_after"]])


if __name__ == "__main__":
    main()
