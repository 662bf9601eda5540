"""The new object kinds (blob, isosurface, lathe, prism) through the outside renderers.

1. POV-Ray 3.7 (``--povray``): every scene of ``tests/povray_kind_scenes.py`` (``kinds`` and
   each new kind alone on its floor, an isosurface torus, an open lathe, the new kinds as CSG
   operands), exported by :mod:`workbench.renderers.povray_sdl` (POV-Ray's own ``blob``,
   ``isosurface``, ``lathe``, ``prism``) and rendered by the ``povray`` method, against the
   ray tracer (``raytrace``, ``transmissive_shadows``) at the same camera and size, no
   antialiasing: RMSE, mean and max difference (our image clipped at 1 as POV-Ray's output),
   the fraction of pixels beyond 1e-4, per object the RMSE over its pixels and the
   intersection over union of its pixels in the "ID" renders (POV-Ray against the ray
   caster), and each program's trace time.
2. Mitsuba 3 (``--mitsuba``): ``kinds`` made comparable (no Phong lobe, no ambient: Mitsuba
   has neither; the point light inverse-square with the intensity that gives the same light
   at the scene's centre; black background, which Mitsuba would turn into a light), the new
   kinds exported as their tessellations (``scalar_rgb``, the method's child process), against
   the path tracer (exact intersections), both box-filtered, at two tessellation levels:
   RMSE overall and per object, and the RMS noise of the difference (both images' standard
   errors), so that the part of the error the noise cannot explain shows.

The load average is recorded before and after (the machine is shared).  Writes
``bench/results/kinds_exporters.json`` and prints it.  Run:
``PYTHONPATH=. .venv/bin/python bench/kinds_exporters.py [--povray] [--mitsuba] [--size 320x240]``
(both parts when neither is named).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))  # the comparison scenes are shared with the tests
OUT = ROOT / "bench" / "results" / "kinds_exporters.json"

import workbench  # noqa: E402
from povray_kind_scenes import id_scene, kind_scenes, labels, object_ious  # noqa: E402
from workbench.scene import model as m  # noqa: E402


def load() -> float:
    return round(os.getloadavg()[0], 2)


def per_object_rmse(a: np.ndarray, b: np.ndarray, lab: np.ndarray, scene) -> dict:
    """RMSE of ``a - b`` over each object's pixels (``lab``: the ray caster's ID labels)."""
    out = {}
    for i, o in enumerate(scene.objects):
        sel = lab == i
        if sel.any():
            out[o.name or o.kind] = float(np.sqrt(np.mean((a[sel] - b[sel]) ** 2)))
    return out


def povray_part(w: int, h: int) -> dict:
    res = {}
    for name, scene in kind_scenes().items():
        l0 = load()
        pov = workbench.render(scene, "povray", width=w, height=h, threads=2)
        ours = workbench.render(scene, "raytrace", width=w, height=h, transmissive_shadows=True)
        a, b = pov.image.astype(np.float64), np.minimum(ours.image, 1.0).astype(np.float64)
        d = np.abs(a - b).max(-1)
        ids = id_scene(scene)
        la = labels(workbench.render(ids, "povray", width=w, height=h).image)
        lb = labels(workbench.render(ids, "raycast", width=w, height=h).image)
        res[name] = dict(
            left_out=pov.left_out, rmse=float(np.sqrt(np.mean((a - b) ** 2))), mean_abs=float(d.mean()),
            max_abs=float(d.max()), fraction_beyond_1em4=float((d > 1e-4).mean()),
            rmse_per_object=per_object_rmse(a, b, lb, scene),
            iou_per_object=dict(zip([o.name or o.kind for o in scene.objects], object_ious(la, lb, len(scene.objects)))),
            id_pixels_differing=int((la != lb).sum()),
            povray_trace_s=pov.timings["trace"], povray_parse_s=pov.timings["parse"],
            ours_trace_s=ours.timings["trace"], ours_trace_cpu_s=ours.timings.get("trace_cpu"),
            load=[l0, load()])
        print(name, json.dumps({k: v for k, v in res[name].items() if k in ("rmse", "fraction_beyond_1em4", "iou_per_object")}), flush=True)
    return res


def comparable(scene: m.Scene) -> m.Scene:
    """``kinds`` as both a path tracer and Mitsuba can render it (module docstring, part 2)."""
    mats = {k: replace(mt, ks=0.0, ka=0.0) for k, mt in scene.materials.items()}
    lo = np.array([-4.0, 0.0, -1.5])
    hi = np.array([4.0, 2.2, 2.0])
    centre = 0.5 * (lo + hi)
    lights = []
    for light in scene.lights:
        if isinstance(light, m.PointLight) and light.falloff == "none":
            r2 = float(np.sum((np.asarray(light.position) - centre) ** 2))
            light = replace(light, falloff="inverse_square", intensity=light.intensity * r2)
        lights.append(light)
    return replace(scene, materials=mats, lights=tuple(lights), background=(0.0, 0.0, 0.0), ambient=(0.0, 0.0, 0.0))


def mitsuba_part(w: int, h: int, spp: int, levels=(4, 16)) -> dict:
    scene = comparable(workbench.load_scene("kinds"))
    lab = labels(workbench.render(id_scene(scene), "raycast", width=w, height=h).image)
    l0 = load()
    pt = workbench.render(scene, "pathtrace", width=w, height=h, spp=spp)
    res = {"scene": "kinds without Phong lobe and ambient, inverse-square point light, black background",
           "size": f"{w}x{h}", "spp": spp,
           "pathtrace": dict(trace_s=pt.timings["trace"], trace_cpu_s=pt.timings.get("trace_cpu"),
                             left_out=pt.left_out, load=[l0, load()])}
    se_pt = np.asarray(pt.std_error, dtype=np.float64)
    for level in levels:
        l0 = load()
        mi = workbench.render(scene, "mitsuba", width=w, height=h, spp=spp, variant="scalar_rgb", tessellation=level)
        a, b = mi.image.astype(np.float64), pt.image.astype(np.float64)
        noise = np.sqrt(np.mean(np.asarray(mi.stats["stderr"], dtype=np.float64) ** 2 + se_pt ** 2))
        rmse = float(np.sqrt(np.mean((a - b) ** 2)))
        res[f"mitsuba_level_{level}"] = dict(
            rmse=rmse, noise_rms=float(noise), excess=float(np.sqrt(max(rmse ** 2 - noise ** 2, 0.0))),
            rmse_per_object=per_object_rmse(a, b, lab, scene),
            noise_per_object={o.name or o.kind: float(np.sqrt(np.mean(np.asarray(mi.stats["stderr"], dtype=np.float64)[lab == i] ** 2
                                                                      + se_pt[lab == i] ** 2)))
                              for i, o in enumerate(scene.objects) if (lab == i).any()},
            triangles=mi.stats["triangles"], variant=mi.stats["variant"], render_s=mi.timings["render"],
            render_cpu_s=mi.stats["render_cpu_seconds"], export_s=mi.timings["export"],
            left_out=mi.left_out, load=[l0, load()])
        print(level, json.dumps({k: res[f"mitsuba_level_{level}"][k] for k in ("rmse", "noise_rms", "rmse_per_object")}), flush=True)
    return res


def main() -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--povray", action="store_true")
    ap.add_argument("--mitsuba", action="store_true")
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--mitsuba-size", default="160x120")
    ap.add_argument("--spp", type=int, default=256)
    a = ap.parse_args()
    both = not (a.povray or a.mitsuba)
    w, h = (int(v) for v in a.size.split("x"))
    res = json.loads(OUT.read_text()) if OUT.exists() else {}
    res["machine"] = f"{os.cpu_count()} CPUs (shared)"
    t0 = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    if a.povray or both:
        res["povray"] = {"date": t0, "size": f"{w}x{h}", "load_start": load(), "scenes": povray_part(w, h),
                         "load_end": load()}
    if a.mitsuba or both:
        mw, mh = (int(v) for v in a.mitsuba_size.split("x"))
        res["mitsuba"] = {"date": t0, "load_start": load(), **mitsuba_part(mw, mh, a.spp), "load_end": load()}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    main()
