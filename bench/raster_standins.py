"""The raster stand-ins for global effects (issue 15): by how much each reduces Phong's error
against the Whitted reference on ``whitted``, at what frame rate on llvmpipe, and that scenes
needing none keep their frame rate.

* ``steps``: Phong (and Gouraud) at ``--width`` x ``--height`` with ``standins`` = off (the bare
  local model), each stand-in alone, and cumulatively envmap, + blend, + shadows (= all): RMSE,
  PSNR and FLIP against the scene's full reference (:func:`workbench.compare.reference.
  choose_reference`: the Whitted ray tracer, depth 12, 16 stratified samples per pixel, from the
  reference cache), and the frame rate of ``draw_to`` + ``finish`` (as bench/raster_fps.py:
  the maps are drawn when the scene changes, not per camera move: a frame is the image pass with
  its map lookups), the CPU time per frame, the time with read-back, and (``*_maps_redrawn``) a
  frame that also redraws every environment map (what each live edit of the scene costs);
* ``sweeps``: all stand-ins with one knob varied (``envmap_resolution``, ``envmap_iterations``,
  ``shadow_resolution``, ``shadow_bias``);
* ``unneeded``: every bundled scene's plan (which stand-ins the default options build) and, for
  the scenes that need none, Phong and Gouraud frame rates with stand-ins on and off at 512 x 512.

    .venv/bin/python bench/raster_standins.py [--seconds 1.0] [--width 512] [--height 384]

Writes ``bench/results/raster_standins.json`` and ``docs/benchmarks/raster_standins.md`` (and prints
the table) and the figure ``docs/images/whitted_standins.png`` (``--figure-only``: just the figure).
``--smoke``: 32 x 24, 0.05 s per rate, the steps "none" and "all", one sweep of one value, two scenes
for the "unneeded" part; the figure goes to the ``--out`` folder.
"""
from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import workbench
from _common import Page, first_paragraph
from raster_fps import _rate
from workbench.compare.metrics import metrics
from workbench.compare.reference import choose_reference
from workbench.renderers import gl
from workbench.renderers import raster_standins as sti
from workbench.renderers.raster import RasterSession
from workbench.scene.features import scene_needs
from workbench.scene.library import bundled

STEPS = [("none", "off"), ("envmap", "envmap"), ("+blend", "envmap,blend"), ("+shadows = all", "on"),
         ("blend alone", "blend"), ("shadows alone", "shadows")]
SWEEPS = {"envmap_resolution": (16, 32, 64, 128, 256), "envmap_iterations": (0, 1, 2, 3, 5),
          "shadow_resolution": (128, 256, 512, 1024, 2048), "shadow_bias": (0.0, 0.0005, 0.002, 0.01, 0.03)}


def measure(scene, mode: str, reference, width: int, height: int, seconds: float, **options) -> dict:
    """Error against ``reference`` and frame rates of one session."""
    opts = sti.StandinOptions.parse(**options)
    t0 = time.perf_counter()
    session = RasterSession(scene, mode, standins=opts)
    setup = time.perf_counter() - t0
    cam = scene.camera.with_resolution(width, height)
    image = session.draw(cam)
    m = metrics(image, reference) if reference is not None else {}
    fbo = session.framebuffer(width, height)

    def frame():
        session.draw_to(fbo, cam)
        session.ctx.finish()

    r = _rate(frame, seconds)
    full = _rate(lambda: session.draw(cam, with_depth=True), seconds / 2)
    redraw = {}
    if session.env_maps:
        def frame_and_maps():
            session.draw_environment_maps()
            frame()
        e = _rate(frame_and_maps, seconds / 2)
        redraw = {"fps_maps_redrawn": round(e["fps"], 1), "cpu_ms_maps_redrawn": round(e["cpu_ms"], 2)}
    row = {"mode": mode, **{k: v for k, v in options.items()},
           "standins_built": sorted(session.standins_used), "env_maps": len(session.env_maps),
           "shadow_tiles": session.shadow_layout.tiles if session.shadow_layout else 0,
           "setup_seconds": round(setup, 3), "compile_seconds": round(session.timings["compile"], 3),
           "fps": round(r["fps"], 1), "fps_best": round(r["fps_best"], 1), "cpu_ms_per_frame": round(r["cpu_ms"], 2),
           "ms_with_readback": round(1e3 / full["fps_median"], 2), **redraw}
    if m:
        row.update(rmse=round(m["rmse"], 5), psnr=round(m["psnr"], 2), flip=round(m["flip"], 4))
    session.release()
    print(row, flush=True)
    return row


FIGURE = Path(__file__).resolve().parents[1] / "docs" / "images" / "whitted_standins.png"


def figure(scene, reference, width: int, height: int, path: Path = FIGURE) -> None:
    """docs/images/whitted_standins.png: the Whitted reference, Phong with stand-ins off, with
    environment maps seen from the centre (``envmap_iterations=0``: parallax), with all stand-ins
    at their defaults, and the absolute error of the last (x4), each panel labelled with its RMSE."""
    import numpy as np
    from PIL import Image, ImageDraw
    from workbench.core.imageio import to_srgb8
    panels = [("Whitted reference", reference)]
    for label, opts in [("phong, standins=off", {"standins": "off"}),
                        ("all, envmap_iterations=0 (parallax)", {"envmap_iterations": 0}),
                        ("phong, all stand-ins", {})]:
        img = workbench.render(scene, "phong", width=width, height=height, **opts).image
        panels.append((f"{label}: RMSE {metrics(img, reference)['rmse']:.4f}", img))
    panels.append(("|all - reference| x 4", np.clip(4.0 * np.abs(panels[-1][1] - reference), 0.0, 1.0)))
    tiles = []
    for label, img in panels:
        im = Image.fromarray(to_srgb8(img))
        ImageDraw.Draw(im).text((6, 6), label, fill=(0, 0, 0))
        tiles.append(np.asarray(im))
    half = [np.asarray(Image.fromarray(x).resize((width // 2, height // 2))) for x in tiles]
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.concatenate([np.concatenate(half[:3], 1), np.concatenate(half[3:] + [255 + 0 * half[0]], 1)],
                                   0).astype(np.uint8)).save(path)
    print("wrote", path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=1.0)
    ap.add_argument("--width", type=int, default=512)
    ap.add_argument("--height", type=int, default=384)
    ap.add_argument("--figure-only", action="store_true", help="only write docs/images/whitted_standins.png")
    args = PAGE.parse(ap, argv)
    steps_, sweeps_, scenes, unneeded_size = STEPS, SWEEPS, bundled(), 512
    if args.smoke:
        args.width, args.height, args.seconds = 32, 24, 0.05
        steps_ = [st for st in STEPS if st[0] in ("none", "+shadows = all")]
        sweeps_, scenes, unneeded_size = {"envmap_resolution": SWEEPS["envmap_resolution"][:1]}, bundled()[:2], 32
    W, H, sec = args.width, args.height, args.seconds
    load_before = os.getloadavg()
    scene = workbench.load_scene("whitted")
    ref = choose_reference(scene, W, H)
    figure(scene, ref.image, W, H, args.out / FIGURE.name if args.smoke else FIGURE)
    if args.figure_only:
        return
    steps = []
    for label, standins in steps_:
        for mode in ("phong", "gouraud") if label in ("none", "+shadows = all") else ("phong",):
            steps.append({"step": label, **measure(scene, mode, ref.image, W, H, sec, standins=standins)})
    sweeps = {k: [measure(scene, "phong", ref.image, W, H, sec / 2, **{k: v}) for v in values]
              for k, values in sweeps_.items()}
    unneeded = []
    for path in scenes:
        s = workbench.load_scene(path.stem)
        p = sti.plan(scene_needs(s), sti.StandinOptions(), "phong", user_model=False, n_lights=len(s.point_lights()))
        row = {"scene": path.stem, "standins_built": sorted(p.covered)}
        if not p.any:
            for mode in ("phong", "gouraud"):
                for standins in ("on", "off"):
                    r = measure(s, mode, None, unneeded_size, unneeded_size, sec, standins=standins)
                    row[f"{mode}_{standins}"] = {k: r[k] for k in ("fps", "fps_best", "cpu_ms_per_frame", "env_maps",
                                                                   "shadow_tiles")}
        unneeded.append(row)
    result = {"benchmark": "raster_standins", "scene": "whitted", "size": [W, H], "gl_renderer": gl.renderer_name(),
              "reference": {"method": ref.method, "options": ref.options},
              "machine": platform.platform(), "cpu_count": os.cpu_count(),
              "load_average_1min": {"before": round(load_before[0], 2), "after": round(os.getloadavg()[0], 2)},
              "defaults": {"envmap_resolution": sti.DEFAULT_ENV_RESOLUTION, "envmap_iterations": sti.DEFAULT_ENV_ITERATIONS,
                           "shadow_resolution": sti.DEFAULT_SHADOW_RESOLUTION, "shadow_bias": sti.DEFAULT_SHADOW_BIAS},
              "note": "fps = draw_to + finish (environment maps drawn every frame; shadow maps once per session, "
                      "in setup_seconds); 2 shared cores: the load average lowers fps, cpu_ms_per_frame much less",
              "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
              "steps": steps, "sweeps": sweeps, "unneeded": unneeded}
    print(markdown(result))
    PAGE.write(args, result)


def markdown(r: dict) -> str:
    """The result as Markdown tables."""
    W, H = r["size"]
    out = [f"The anchor is the Whitted ray tracer's image (the reference, same run); the stand-ins' RMSE against "
           f"it, step by step, at {W} x {H}.", "",
           f"Reference: {r['reference']['method']} {r['reference']['options']}; {r['gl_renderer']}; "
           f"load average {r['load_average_1min']['before']} -> {r['load_average_1min']['after']} on "
           f"{r['cpu_count']} cores; {r['date']}.", "",
           "| step | method | RMSE | PSNR | FLIP | fps (best batch) | CPU ms/frame | ms with read-back | setup s |",
           "|---|---|---|---|---|---|---|---|---|"]
    for s in r["steps"]:
        out.append(f"| {s['step']} (`standins={s['standins']}`) | {s['mode']} | {s['rmse']:.4f} | {s['psnr']:.2f} | "
                   f"{s['flip']:.4f} | {s['fps']} ({s['fps_best']}) | {s['cpu_ms_per_frame']} | "
                   f"{s['ms_with_readback']} | {s['setup_seconds']} |")
    for knob, rows in r["sweeps"].items():
        out += ["", f"Phong, all stand-ins, `{knob}` swept:", "", "| value | RMSE | fps (best) | CPU ms/frame |",
                "|---|---|---|---|"]
        out += [f"| {x[knob]} | {x['rmse']:.4f} | {x['fps']} ({x['fps_best']}) | {x['cpu_ms_per_frame']} |" for x in rows]
    out += ["", "Frames that also redraw the environment maps (a live edit): "
            + "; ".join(f"{s['step']} {s['mode']}: {s['fps_maps_redrawn']} fps, {s['cpu_ms_maps_redrawn']} CPU ms"
                        for s in r["steps"] if "fps_maps_redrawn" in s)]
    out += ["", "Bundled scenes: stand-ins built by default (Phong); scenes needing none, frame rate at 512 x 512 "
            "with stand-ins on / off:", "", "| scene | stand-ins built | phong fps on / off | gouraud fps on / off |",
            "|---|---|---|---|"]
    for u in r["unneeded"]:
        fps = [f"{u[f'{m}_on']['fps']} / {u[f'{m}_off']['fps']}" if f"{m}_on" in u else "" for m in ("phong", "gouraud")]
        out.append(f"| {u['scene']} | {', '.join(u['standins_built']) or 'none'} | {fps[0]} | {fps[1]} |")
    return "\n".join(out) + "\n"


PAGE = Page("raster_standins", "Raster stand-ins for global effects on `whitted`", first_paragraph(__doc__),
            "python bench/raster_standins.py", markdown, smoke_note="32 x 24, 0.05 s per rate, steps none and all, one sweep of one value")


if __name__ == "__main__":
    main()
