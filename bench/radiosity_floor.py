"""Where radiosity's error floor on the Cornell box comes from (issue 13, part 7).

Radiosity's RMSE against a converged path tracer of the same scene (both clipped to [0, 1],
128 x 128) stops falling near 0.036 (Mitsuba 3, 4096 spp: 0.0455 / 0.0399 / 0.0361 / 0.0358 at
``patch_size`` 0.2 / 0.1 / 0.05 / 0.025).  Each candidate cause is isolated by one measured
difference image and reported as the RMSE of that image (RMSE components are not additive:
they overlap and partly cancel; the JSON also gives the root-sum-square for comparison):

* **total**: radiosity (hemicube, direct solve, Gouraud display) against the full path tracer
  (``pathtrace``, box filter, ``--spp`` samples per pixel, cached by
  :func:`workbench.compare.reference_cache.cached_render`);
* (a) **reference noise**: RMS of the reference's own per-pixel standard error (over the pixels
  the clip leaves below 1; clipped pixels have none);
* (b) **pixel filter**: the path tracer with every sample through the pixel centre (the
  point-sampled image radiosity's display produces) against the box-filtered reference;
* **matched**: radiosity against its matched reference, the path tracer with ``transport=diffuse``
  and ``pixel_filter=center`` (radiosity's physics and image definition): discretisation alone;
* (c) **Gouraud interpolation**: the same solution drawn with flat patches (each patch its own
  value, no interpolation) against the Gouraud display, and the flat image against the matched
  reference;
* (d) **hemicube bias**: the same patches with the exact point-to-polygon form factor times
  ray-cast visibility (``solver=progressive, shot_rows=raycast``, Wallace et al. 1989, converged
  to ``tol`` 1e-4: the hemicube's collocation at patch centres without its direction aliasing)
  against the hemicube's, and that image against the matched reference; and, where a size has
  at most ``--malley-max`` patches (the brute-force O(P^2 rays) kernel: 30 s at 937 patches,
  many minutes at 3,524), Malley's area-averaged ray-cast form factors (``--rays`` per patch);
* (e) **light leaks and junctions**: the matched error restricted to the pixels within
  ``--band`` pixels of a block's contact with the floor, and of the room's wall/floor/ceiling
  junctions (visible points only): RMS there, share of the total squared error, and the matched
  RMSE over the other pixels;
* (f) **missing physics**: full against diffuse transport, same seed and spp (``--f-spp``):
  identical paths on this all-Lambertian scene give an identical image.

Usage: ``.venv/bin/python bench/radiosity_floor.py [--size 128] [--spp 1024]`` writes
``bench/results/radiosity_floor.json`` and ``docs/benchmarks/radiosity_floor.md`` (the README's
table) and prints the table.  ``--smoke``: 16 x 16, 4 spp references, ``patch_size`` 0.2 alone, 16
Malley rays per patch.  The two 1024-spp path-traced images take about 2 x 2.5 min on the
busy 2-core host the first time, then come from the reference cache.
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from _common import Page, first_paragraph  # noqa: E402

MITSUBA_ISSUE = {0.2: 0.0455, 0.1: 0.0399, 0.05: 0.0361, 0.025: 0.0358}
"""Radiosity against Mitsuba 3 (scalar_rgb, 4096 spp, box filter, 128 x 128, clipped), issue 13."""
BLOCKS = ("short_block", "tall_block")
ROOM = ("floor", "ceiling", "back_wall", "right_wall", "left_wall")


def rmse(a, b, mask=None) -> float:
    d = np.clip(np.asarray(a, np.float64), 0, 1) - np.clip(np.asarray(b, np.float64), 0, 1)
    if mask is not None:
        d = d[mask]
    return float(np.sqrt(np.mean(d * d))) if d.size else 0.0


def segments(scene) -> dict:
    """World segments (n, 2, 3): ``contacts`` (the bottom edges of the blocks' sides, on the
    floor) and ``junctions`` (edges where two walls, the floor or the ceiling meet)."""
    polys = {o.name: np.asarray(o.vertices, dtype=np.float64) for o in scene.objects}
    contacts, junctions = [], []
    for name, v in polys.items():
        edges = [(v[k], v[(k + 1) % len(v)]) for k in range(len(v))]
        if name.startswith(BLOCKS):
            contacts += [e for e in edges if abs(e[0][1]) < 1e-9 and abs(e[1][1]) < 1e-9]
        elif name in ROOM:
            others = np.concatenate([polys[n] for n in ROOM if n != name])
            # both ends within 5 mm of another room polygon's corner (the box is not square)
            shared = [np.min(np.linalg.norm(others - a, axis=1)) < 5.0 and np.min(np.linalg.norm(others - b, axis=1)) < 5.0
                      for a, b in edges]
            open_front = [abs(a[2]) < 1e-9 and abs(b[2]) < 1e-9 for a, b in edges]  # the box's open side, z = 0
            junctions += [e for e, sh, fr in zip(edges, shared, open_front) if sh and not fr]
    return {"contacts": np.array(contacts), "junctions": np.array(junctions)}


def band_mask(scene, segs, depth, band: float) -> np.ndarray:
    """(H, W) bool: pixels within ``band`` pixels of a visible point of the segments (visible:
    its depth within 1 % of the depth the camera ray of its pixel sees)."""
    cam = scene.camera
    H, W = depth.shape
    t = np.linspace(0.0, 1.0, 400)[:, None]
    mask = np.zeros((H, W), bool)
    yy, xx = np.mgrid[0:H, 0:W]
    for a, b in segs:
        xy, z = cam.project(a + t * (b - a))
        for (x, y), zz in zip(xy, z):
            i, j = int(np.floor(y)), int(np.floor(x))
            ii, jj = min(max(i, 0), H - 1), min(max(j, 0), W - 1)
            seen = depth[max(ii - 1, 0):ii + 2, max(jj - 1, 0):jj + 2]
            if not (0 <= x < W and 0 <= y < H) or np.min(np.abs(seen - zz)) > 0.01 * zz:
                continue
            mask |= (xx + 0.5 - x) ** 2 + (yy + 0.5 - y) ** 2 <= band * band
    return mask


def silhouettes(depth) -> np.ndarray:
    """(H, W) bool: pixels next to a depth discontinuity (a neighbour's depth differs by more
    than 2 %, or one of them sees nothing), grown by one pixel."""
    d = np.where(np.isfinite(depth), depth, 1e30)
    jump = np.zeros(d.shape, bool)
    for ax in (0, 1):
        a, b = np.take(d, range(d.shape[ax] - 1), ax), np.take(d, range(1, d.shape[ax]), ax)
        big = np.abs(a - b) > 0.02 * np.minimum(a, b)
        pad = [(0, 0), (0, 0)]
        pad[ax] = (0, 1)
        jump |= np.pad(big, pad)
        pad[ax] = (1, 0)
        jump |= np.pad(big, pad)
    grown = jump.copy()
    grown[1:] |= jump[:-1]
    grown[:-1] |= jump[1:]
    grown[:, 1:] |= jump[:, :-1]
    grown[:, :-1] |= jump[:, 1:]
    return grown


def flat_display(patches, radiance, scene):
    """The solution drawn with each patch its own value (no vertex sharing, no interpolation)."""
    from workbench.renderers.radiosity.display import draw
    P = len(patches)
    flat = dataclasses.replace(patches, vertices=patches.corners.reshape(-1, 3),
                               vertex_ids=np.arange(4 * P, dtype=np.int64).reshape(P, 4))
    img, _ = draw(flat, radiance, scene.camera, scene.background)
    return img


def tables(out: dict) -> str:
    w, h = out["size"]
    return (f"`{out['scene']}` at {w} x {h}, clipped to {out['clip']}; {out['note']}.  The anchor is the converged "
            f"path tracer (`pathtrace`, {out['spp']} spp) of the same run, and Mitsuba 3 at 4096 spp as quoted "
            "from issue 13 (not run here).\n\n" + table(out)
            + ("\nSteps (s): " + ", ".join(f"{k} {v}" for k, v in out["steps_s"].items())
               + f"; total {out.get('total_s')} s.\n" if out.get("steps_s") else ""))


PAGE = Page("radiosity_floor", "Where radiosity's error floor on the Cornell box comes from", first_paragraph(__doc__),
            "python bench/radiosity_floor.py", tables, smoke_note="16 x 16, 4 spp, patch_size 0.2 alone")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=1024, help="samples per pixel of the path-traced references")
    ap.add_argument("--f-spp", type=int, default=64, help="samples per pixel of the full/diffuse check (f)")
    ap.add_argument("--rays", type=int, default=1024, help="Malley form factors: rays per patch")
    ap.add_argument("--malley-max", type=int, default=1000, help="Malley form factors up to this many patches")
    ap.add_argument("--band", type=float, default=1.5, help="half-width in pixels of the contact/junction bands")
    ap.add_argument("--sizes", type=float, nargs="+", default=[0.2, 0.1, 0.05, 0.025])
    args = PAGE.parse(ap, argv)
    if args.smoke:
        args.size, args.spp, args.f_spp, args.rays, args.malley_max, args.sizes = 16, 4, 2, 16, 100, [0.2]

    import workbench
    from workbench.compare.reference_cache import cached_render
    from workbench.renderers.base import convert_options, get_renderer
    from workbench.renderers.radiosity.display import draw
    from workbench.renderers.radiosity.method import solve_scene
    from workbench.scene.model import AreaLight

    t_start = time.perf_counter()
    N = args.size
    scene = workbench.load_scene("cornell")
    scene = scene.with_camera(scene.camera.with_resolution(N, N))
    out = {"date": time.strftime("%Y-%m-%d %H:%M"), "load_before": os.getloadavg(), "scene": "cornell",
           "size": [N, N], "clip": [0, 1], "spp": args.spp, "rays": args.rays, "band_px": args.band,
           "note": "each component is the RMSE of one isolated difference image (both sides clipped "
                   "to [0, 1]); components overlap and are not additive"}
    steps = {}

    def timed(label, f):
        t0 = time.perf_counter()
        v = f()
        steps[label] = round(time.perf_counter() - t0, 2)
        print(f"  {label}: {steps[label]} s", file=sys.stderr, flush=True)
        return v

    ref = timed("reference", lambda: cached_render(scene, "pathtrace", N, N, spp=args.spp, seed=1))
    matched = timed("matched", lambda: cached_render(scene, "pathtrace", N, N, spp=args.spp, seed=2,
                                                     transport="diffuse", pixel_filter="center"))
    ref_img, m_img = ref.image, matched.image
    for name, r in (("reference", ref), ("matched", matched)):
        se = r.stats["stderr"].astype(np.float64)
        below = np.clip(r.image, 0, 1) < 1.0
        out[name] = {"options": r.options, "cache": r.stats.get("cache"), "noise_rmse": r.stats["noise_rmse"],
                     "noise_rmse_clipped": float(np.sqrt(np.mean(np.where(below, se, 0.0) ** 2))),
                     "mean_radiance": [float(x) for x in r.image.mean((0, 1))]}
    # (b) pixel filter: centre against box (matched = full on this scene, see (f))
    out["b_pixel_filter"] = {"rmse_center_vs_box": rmse(m_img, ref_img),
                             "noise_of_that_difference": float(np.hypot(out["reference"]["noise_rmse_clipped"],
                                                                        out["matched"]["noise_rmse_clipped"]))}
    # (f) missing physics: full vs diffuse, same seed
    f_full = timed("f_full", lambda: workbench.render(scene, "pathtrace", width=N, height=N, spp=args.f_spp, seed=3))
    f_diff = timed("f_diffuse", lambda: workbench.render(scene, "pathtrace", width=N, height=N, spp=args.f_spp,
                                                        seed=3, transport="diffuse"))
    out["f_missing_physics"] = {"spp": args.f_spp, "rmse_full_vs_diffuse": rmse(f_full.image, f_diff.image),
                                "max_abs_difference": float(np.abs(f_full.image - f_diff.image).max()),
                                "identical": bool(np.array_equal(f_full.image, f_diff.image))}
    # masks for (e)
    depth = timed("depth", lambda: workbench.render(scene, "raycast", width=N, height=N).depth)
    segs = segments(scene)
    masks = {k: band_mask(scene, v, depth, args.band) for k, v in segs.items()}
    light = np.zeros((N, N), bool)
    for lt in scene.lights:
        if isinstance(lt, AreaLight):
            xy, _ = scene.camera.project(np.asarray(lt.vertices))
            lo, hi = np.floor(xy.min(0)).astype(int) - 1, np.ceil(xy.max(0)).astype(int) + 1
            light[max(lo[1], 0):hi[1], max(lo[0], 0):hi[0]] = True
    masks["light"] = light
    masks["silhouettes"] = silhouettes(depth)
    out["masks_pixels"] = {k: int(v.sum()) for k, v in masks.items()}
    # where the pixel filter matters: its squared difference on the light, on silhouettes and
    # creases (the bands), elsewhere
    d2 = ((np.clip(m_img.astype(np.float64), 0, 1) - np.clip(ref_img.astype(np.float64), 0, 1)) ** 2).sum(-1)
    edges = (masks["silhouettes"] | masks["contacts"] | masks["junctions"]) & ~light
    rest = ~(edges | light)
    out["b_pixel_filter"]["share_of_squared_difference"] = {
        "light": float(d2[light].sum() / d2.sum()), "silhouettes_and_creases": float(d2[edges].sum() / d2.sum()),
        "rest": float(d2[rest].sum() / d2.sum())}
    out["b_pixel_filter"]["rmse_off_light_and_edges"] = float(np.sqrt(d2[rest].sum() / (3 * d2.size)))

    opts = convert_options(get_renderer("radiosity"), {})
    rows = {}
    for ps in args.sizes:
        o = dict(opts, patch_size=ps)
        sol = timed(f"radiosity_{ps}", lambda: solve_scene(scene, o, "radiosity"))
        gouraud, _ = draw(sol.patches, sol.radiance, scene.camera, scene.background)
        flat = flat_display(sol.patches, sol.radiance, scene)
        exact = timed(f"exact_ff_{ps}", lambda: solve_scene(scene, dict(o, solver="progressive", shot_rows="raycast",
                                                                        tol=1e-4), "radiosity"))
        g_exact, _ = draw(exact.patches, exact.radiance, scene.camera, scene.background)
        g_ray = None
        if len(sol.patches) <= args.malley_max:
            ray = timed(f"malley_ff_{ps}", lambda: solve_scene(scene, dict(o, form_factors="raycast", rays=args.rays),
                                                               "radiosity"))
            g_ray, _ = draw(ray.patches, ray.radiance, scene.camera, scene.background)
        err = np.clip(gouraud.astype(np.float64), 0, 1) - np.clip(m_img.astype(np.float64), 0, 1)
        sq = (err ** 2).sum(-1)
        row = {"patches": len(sol.patches),
               "total_vs_reference": rmse(gouraud, ref_img),
               "total_vs_mitsuba_issue13": MITSUBA_ISSUE.get(ps),
               "total_vs_reference_off_light": rmse(gouraud, ref_img, ~light),
               "matched_discretisation": rmse(gouraud, m_img),
               "c_gouraud_vs_flat": rmse(gouraud, flat),
               "c_flat_vs_matched": rmse(flat, m_img),
               "d_hemicube_vs_exact_ff": rmse(gouraud, g_exact),
               "d_exact_ff_vs_matched": rmse(g_exact, m_img),
               "d_exact_ff_converged": bool(exact.stats["converged"]),
               "d_hemicube_vs_malley_ff": None if g_ray is None else rmse(gouraud, g_ray),
               "d_malley_ff_vs_matched": None if g_ray is None else rmse(g_ray, m_img),
               "mean_off_light_relative": float(gouraud[~light].mean() / m_img[~light].mean() - 1.0)}
        for k in ("contacts", "junctions", "light"):
            mk = masks[k]
            row[f"e_{k}"] = {"rms_in_band": float(np.sqrt(sq[mk].mean() / 3)) if mk.any() else 0.0,
                             "share_of_squared_error": float(sq[mk].sum() / max(sq.sum(), 1e-300)),
                             "matched_rmse_elsewhere": float(np.sqrt(sq[~mk].mean() / 3))}
        rest = ~(masks["contacts"] | masks["junctions"] | masks["light"])
        row["e_matched_rmse_off_all_bands"] = float(np.sqrt(sq[rest].mean() / 3))
        rows[str(ps)] = row
    out["patch_sizes"] = rows
    out["steps_s"] = steps
    out["total_s"] = round(time.perf_counter() - t_start, 1)
    out["load_after"] = os.getloadavg()
    print(table(out))
    PAGE.write(args, out)
    return 0


def table(out: dict) -> str:
    """The README's markdown table from the JSON."""
    ps = list(out["patch_sizes"])
    R = out["patch_sizes"]

    def row(label, how, key, sub=None):
        vals = [R[p][key] if sub is None else R[p][key][sub] for p in ps]
        cells = " | ".join("–" if v is None else (f"{100 * v:.0f} %" if sub == "share_of_squared_error" else f"{v:.4f}")
                           for v in vals)
        return f"| {label} | {how} | {cells} |"

    a, b, f = out["reference"], out["b_pixel_filter"], out["f_missing_physics"]
    n = len(ps)
    lines = ["| component | measured as (RMSE of the difference image, clipped to [0, 1]) | "
             + " | ".join(f"patch_size {p}" for p in ps) + " |",
             "|---|---|" + "---|" * n,
             "| | patches | " + " | ".join(str(R[p]["patches"]) for p in ps) + " |",
             row("total (issue 13)", "radiosity vs Mitsuba 3, 4096 spp, box (quoted)", "total_vs_mitsuba_issue13"),
             row("total", f"radiosity vs `pathtrace`, {out['spp']} spp, box", "total_vs_reference"),
             row("total off the light", f"the same over the pixels off the light (all but {out['masks_pixels']['light']})",
                 "total_vs_reference_off_light"),
             "| (a) reference noise | RMS per-pixel standard error of the reference (pixels below 1) | "
             + " | ".join([f"{a['noise_rmse_clipped']:.4f}"] * n) + " |",
             f"| (b) pixel filter | `pixel_filter=center` vs `box` path tracer (noise of that difference "
             f"{b['noise_of_that_difference']:.4f}) | " + " | ".join([f"{b['rmse_center_vs_box']:.4f}"] * n) + " |",
             f"| (b) where | share of its squared difference on the light's pixels / on silhouettes and "
             f"creases ({out['masks_pixels']['silhouettes']} + bands px) / elsewhere; RMSE of the difference "
             f"elsewhere alone | " + " | ".join(
                 ["{:.0f} % / {:.0f} % / {:.0f} %; {:.4f}".format(
                     100 * b["share_of_squared_difference"]["light"],
                     100 * b["share_of_squared_difference"]["silhouettes_and_creases"],
                     100 * b["share_of_squared_difference"]["rest"], b["rmse_off_light_and_edges"])] * n) + " |",
             row("discretisation", "radiosity vs matched `pathtrace` (`transport=diffuse`, `pixel_filter=center`)",
                 "matched_discretisation"),
             row("(c) Gouraud interpolation", "Gouraud display vs flat patches (same solution)", "c_gouraud_vs_flat"),
             row("(c) flat display", "flat patches vs matched", "c_flat_vs_matched"),
             row("(d) hemicube bias", "hemicube vs exact point-to-polygon factors x ray-cast visibility",
                 "d_hemicube_vs_exact_ff"),
             row("(d) exact-factor radiosity", "those exact factors vs matched", "d_exact_ff_vs_matched"),
             row("(d) hemicube vs Malley", f"hemicube vs area-averaged ray-cast factors ({out['rays']} rays/patch)",
                 "d_hemicube_vs_malley_ff"),
             row("(d) Malley radiosity", "area-averaged ray-cast factors vs matched", "d_malley_ff_vs_matched"),
             row("(e) block/floor contacts", f"matched error, RMS within {out['band_px']} px "
                 f"({out['masks_pixels']['contacts']} px)", "e_contacts", "rms_in_band"),
             row("(e) share", "of the matched squared error there", "e_contacts", "share_of_squared_error"),
             row("(e) room junctions", f"matched error, RMS within {out['band_px']} px "
                 f"({out['masks_pixels']['junctions']} px)", "e_junctions", "rms_in_band"),
             row("(e) share", "of the matched squared error there", "e_junctions", "share_of_squared_error"),
             row("(e) light", f"matched error on the light's pixels ({out['masks_pixels']['light']} px)",
                 "e_light", "rms_in_band"),
             row("(e) rest", "matched RMSE off all these bands", "e_matched_rmse_off_all_bands"),
             f"| (f) missing physics | full vs `transport=diffuse`, same seed, {f['spp']} spp | "
             + " | ".join([f"{f['rmse_full_vs_diffuse']:.4f}" + (" (identical)" if f["identical"] else "")] * n)
             + " |"]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
