"""The CPU Z-buffer against its GL twin: share of differing pixels and run times.

For each scene (those without bump or opacity maps, which ``zbuffer`` leaves out) and shading
mode, ``zbuffer`` and the GL method of the same mode with ``interpolation=screen`` render the
scene at ``--size``; a pixel differs when a channel differs by more than 0.01 (linear).
Differing pixels are split into those whose visible triangle the near plane cuts
(``zbuffer.near_clipped_mask``: both must give the new corners screen-linear values; GLSL's
``noperspective`` on llvmpipe gave NaN there, counted in ``gl_nonfinite``) and the others
(pixel centres on triangle edges, depth ties, float32 texture patterns).
Times: warm wall-clock seconds of ``workbench.render`` (the second of two calls), zbuffer's
phases (vertices, scan, shade) apart.

    .venv/bin/python bench/zbuffer.py [--size 320x240] [--scenes whitted,quadrics,mesh,csg]

Writes ``bench/results/zbuffer.json`` and ``docs/benchmarks/zbuffer.md`` and prints it.  ``--smoke``:
``whitted`` alone at 32 x 24.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time

import numpy as np

import workbench
from _common import Page, first_paragraph, ratio, table
from workbench.renderers.base import get_renderer
from workbench.renderers.zbuffer import near_clipped_mask

DIFFERS = 1e-2


def _timed(scene, method, w, h, **opts):
    workbench.render(scene, method, width=w, height=h, **opts)
    t0 = time.perf_counter()
    r = workbench.render(scene, method, width=w, height=h, **opts)
    return r, time.perf_counter() - t0


def tables(res: dict) -> str:
    rows = [[r["scene"], r["mode"], r["triangles"], r["differing"], r["near_clipped"], r["other"], r["gl_nonfinite"],
             r["zbuffer_seconds"], r["gl_seconds"], ratio(r["zbuffer_seconds"], r["gl_seconds"])] for r in res["rows"]]
    return (f"{res['size']}; a pixel differs when a channel differs by more than {DIFFERS} (linear).  The anchor is "
            "the GL method of the same mode (`interpolation=screen`, `standins=off`) on llvmpipe, same run.\n\n"
            + table(["scene", "mode", "triangles", "differing px", "near-clipped", "other", "GL non-finite",
                     "zbuffer (s)", "GL (s)", "zbuffer / GL"], rows))


PAGE = Page("zbuffer", "The CPU Z-buffer against its GL twin", first_paragraph(__doc__), "python bench/zbuffer.py",
            tables, smoke_note="whitted alone at 32 x 24")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--scenes", default="whitted,quadrics,mesh,csg")
    a = PAGE.parse(ap, argv)
    if a.smoke:
        a.size, a.scenes = "32x24", "whitted"
    w, h = (int(x) for x in a.size.split("x"))
    rows = []
    for name in a.scenes.split(","):
        scene = workbench.load_scene(name)
        for mode in ("flat", "gouraud", "phong"):
            z, tz = _timed(scene, "zbuffer", w, h, shading=mode)
            _, tg = _timed(scene, mode, w, h, interpolation="screen", standins="off")
            g = get_renderer(mode).render(scene.with_camera(scene.camera.with_resolution(w, h)), w, h,
                                          interpolation="screen", standins="off").image
            clipped = near_clipped_mask(scene, w, h)
            diff = np.abs(z.image - np.nan_to_num(g, nan=0.0)).max(-1) > DIFFERS
            rows.append({"scene": name, "mode": mode, "pixels": w * h,
                         "differing": int(diff.sum()), "differing_share": float(diff.mean()),
                         "near_clipped": int((diff & clipped).sum()), "other": int((diff & ~clipped).sum()),
                         "other_share": float((diff & ~clipped).mean()),
                         "gl_nonfinite": int((~np.isfinite(g).all(-1)).sum()),
                         "zbuffer_seconds": tz, "gl_seconds": tg,
                         "zbuffer_phases": {k: z.timings[k] for k in ("vertices", "scan", "shade")},
                         "triangles": z.stats["triangles"], "clipped_triangles": z.stats["near_clipped"]})
            print(json.dumps(rows[-1]))
    out = {"size": a.size, "machine": platform.processor() or platform.machine(),
           "load_average": os.getloadavg(), "rows": rows}
    PAGE.write(a, out)


if __name__ == "__main__":
    main()
