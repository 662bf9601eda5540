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
``bench/results/kinds_exporters.json`` and ``docs/benchmarks/kinds_exporters.md`` and prints it.  Run:
``PYTHONPATH=. .venv/bin/python bench/kinds_exporters.py [--povray] [--mitsuba] [--size 320x240]``
(both parts when neither is named).  Without POV-Ray or Mitsuba its part runs our side alone.
``--smoke``: the ``kinds`` scene alone at 32 x 24 for POV-Ray; 16 x 12, 4 spp, one tessellation level
(2) for Mitsuba.
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
sys.path.insert(0, str(ROOT / "bench"))

import workbench  # noqa: E402
from _common import Page, first_paragraph, fmt, ratio, skip_note, table  # noqa: E402
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


def povray_part(w: int, h: int, only=None, have_povray: bool = True) -> dict:
    res = {}
    for name, scene in kind_scenes().items():
        if only is not None and name not in only:
            continue
        l0 = load()
        if not have_povray:  # our side alone
            ours = workbench.render(scene, "raytrace", width=w, height=h, transmissive_shadows=True)
            res[name] = dict(ours_trace_s=ours.timings["trace"], ours_trace_cpu_s=ours.timings.get("trace_cpu"),
                             povray="skipped", load=[l0, load()])
            continue
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


def mitsuba_part(w: int, h: int, spp: int, levels=(4, 16), have_mitsuba: bool = True) -> dict:
    scene = comparable(workbench.load_scene("kinds"))
    lab = labels(workbench.render(id_scene(scene), "raycast", width=w, height=h).image)
    l0 = load()
    pt = workbench.render(scene, "pathtrace", width=w, height=h, spp=spp)
    res = {"scene": "kinds without Phong lobe and ambient, inverse-square point light, black background",
           "size": f"{w}x{h}", "spp": spp,
           "pathtrace": dict(trace_s=pt.timings["trace"], trace_cpu_s=pt.timings.get("trace_cpu"),
                             left_out=pt.left_out, load=[l0, load()])}
    se_pt = np.asarray(pt.std_error, dtype=np.float64)
    if not have_mitsuba:
        res["mitsuba"] = skip_note("mitsuba")
        return res
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


def tables(res: dict) -> str:
    out = []
    pv = res.get("povray")
    if pv:
        out += [f"## POV-Ray 3.7 (anchor) against the ray tracer, {pv['size']}, no antialiasing", "",
                f"{pv['date']}, load {pv.get('load_start')} -> {pv.get('load_end')}.  Trace times: POV-Ray's own "
                "\"Trace Time\", ours `timings[\"trace\"]`.", ""]
        rows = []
        for name, r in pv["scenes"].items():
            if r.get("povray") == "skipped":
                rows.append([name, "skipped", "–", "–", "–", "–", "–", r["ours_trace_s"], "–"])
                continue
            rows.append([name, r["rmse"], r["max_abs"], r["fraction_beyond_1em4"],
                         min(r["iou_per_object"].values()) if r["iou_per_object"] else None,
                         r["id_pixels_differing"], r["povray_trace_s"], r["ours_trace_s"],
                         ratio(r["povray_trace_s"], r["ours_trace_s"])])
        out.append(table(["scene", "RMSE", "max abs", "fraction > 1e-4", "min IoU per object", "ID pixels differing",
                          "POV-Ray trace (s)", "ours trace (s)", "POV-Ray / ours"], rows))
    mi = res.get("mitsuba")
    if mi:
        pt = mi["pathtrace"]
        out += [f"## Mitsuba 3 (anchor, tessellated kinds) against the path tracer, {mi['size']}, {mi['spp']} spp", "",
                f"{mi['date']}; scene: {mi['scene']}.  Path tracer: trace {fmt(pt['trace_s'])} s "
                f"({fmt(pt.get('trace_cpu_s'))} CPU s).", ""]
        if isinstance(mi.get("mitsuba"), str):
            out.append(mi["mitsuba"] + ".\n")
        rows = [[k.rsplit("_", 1)[1], r["triangles"], r["variant"], r["rmse"], r["noise_rms"], r["excess"],
                 r["render_s"], r.get("render_cpu_s"), pt["trace_s"], ratio(r["render_s"], pt["trace_s"])]
                for k, r in mi.items() if k.startswith("mitsuba_level_")]
        if rows:
            out.append(table(["tessellation level", "triangles", "variant", "RMSE", "noise RMS", "excess",
                              "Mitsuba render (s)", "Mitsuba CPU (s)", "pathtrace trace (s)", "Mitsuba / ours"], rows))
    return "\n".join(out)


PAGE = Page("kinds_exporters", "The new object kinds through POV-Ray and Mitsuba 3", first_paragraph(__doc__),
            "python bench/kinds_exporters.py", tables, anchors=("povray", "mitsuba"),
            smoke_note="kinds at 32 x 24 (POV-Ray); 16 x 12, 4 spp, tessellation 2 (Mitsuba)")


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--povray", action="store_true")
    ap.add_argument("--mitsuba", action="store_true")
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--mitsuba-size", default="160x120")
    ap.add_argument("--spp", type=int, default=256)
    a = PAGE.parse(ap, argv)
    only, levels = None, (4, 16)
    if a.smoke:
        a.size, a.mitsuba_size, a.spp, only, levels = "32x24", "16x12", 4, ("kinds",), (2,)
    both = not (a.povray or a.mitsuba)
    w, h = (int(v) for v in a.size.split("x"))
    out = a.out / "kinds_exporters.json"
    res = json.loads(out.read_text()) if out.exists() and not both else {}
    res["machine"] = f"{os.cpu_count()} CPUs (shared)"
    t0 = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    if a.povray or both:
        have = PAGE.anchor(a, "povray") is not None
        res["povray"] = {"date": t0, "size": f"{w}x{h}", "load_start": load(),
                         "scenes": povray_part(w, h, only, have), "load_end": load()}
        if not have:
            res["povray"]["note"] = skip_note("povray")
    if a.mitsuba or both:
        mw, mh = (int(v) for v in a.mitsuba_size.split("x"))
        res["mitsuba"] = {"date": t0, "load_start": load(),
                          **mitsuba_part(mw, mh, a.spp, levels, PAGE.anchor(a, "mitsuba") is not None),
                          "load_end": load()}
    return PAGE.write(a, res)


if __name__ == "__main__":
    main()
