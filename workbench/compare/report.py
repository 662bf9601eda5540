"""``workbench compare``: every chosen method on one scene and camera, side by side, with run
times and errors against the scene's reference (:mod:`workbench.compare.reference`).

Output folder (written all-or-nothing, see :func:`workbench.compare.outputs.staged`)::

    grid.png                 labelled side-by-side grid (reference first; methods that do not
                             apply or failed listed under it with the reason)
    images/<m>.png|.npy      each method's image (sRGB PNG, linear float32 .npy); reference.*
    heat/<m>_flip.png        FLIP map against the reference, fixed scale [0, 1]
    heat/<m>_abs.png         mean |linear error| over RGB, scale shared by all methods (median of
                             their 99.5th percentiles, at most 1; larger errors saturate)
    report.json              every number (metrics, timings with compile apart, stats,
                             features used / left out, reference and why, machine, GL_RENDERER)
    report.html              all of it in one self-contained page (images embedded)

Timing: each method is called once cold (compilation happens there and is reported apart) and
``repeat`` times warm, sequentially in this process; the time shown is the warm median.
"""
from __future__ import annotations

import datetime as _dt
from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..core.imageio import save_npy, save_png, save_png8
from ..renderers.base import check_methods, default_methods, file_stem, get_renderer, render, stats_for_display
from ..renderers.raster_standins import parse_standins
from ..scene.model import Scene
from . import figures
from .html import esc, img_tag, page, table
from .metrics import metrics_and_maps
from .outputs import dumps, jsonable, loads, machine_info, staged
from .metrics import metrics
from .reference import References, matched_reason, physical_differences
from .runs import MethodRun, timed_run
from ..scene.features import scene_needs


def _fmt_opts(opts: dict) -> str:
    return ", ".join(f"{k}={v}" for k, v in opts.items())


def _gl_renderer(runs: list[MethodRun]) -> str | None:
    for r in runs:
        if r.result is not None:
            for k, v in r.result.stats.items():
                if k.lower() == "gl_renderer":
                    return str(v)
    return None


def _method_entry(run: MethodRun, ref_features: list[str]) -> dict:
    e = {"method": run.method, "status": run.status, "reason": run.reason, "options": run.options}
    if run.result is None:
        if run.trace:
            e["traceback"] = run.trace
        return e
    res = run.result
    e.update(options=res.options, time_s=run.time, cold_s=run.cold, compile_s=run.compile,
             warm_s=run.warm, timings=res.timings, stats=stats_for_display(res.stats),
             features_used=res.features_used, left_out=res.left_out,
             differs_physically=physical_differences(res.left_out, ref_features))
    return e


def compare(scene: Scene, out_dir: str | Path, methods: list[str] | None = None,
            size: tuple[int, int] | None = None, reference: str | None = None,
            repeat: int = 1, command: str = "") -> dict:
    """Render ``scene`` with each method and write the comparison report into ``out_dir``.

    Parameters
    ----------
    methods : registered method names (default: all registered except the opt-in outside
        references, ``base.default_methods()``; those that raise ``NotApplicable`` are listed
        with their reason).
    size : (width, height); the scene camera's resolution by default.
    reference : force the reference method (default: the rule of :mod:`.reference`).
    repeat : warm runs per method after the cold one (0: time = cold - compile).

    Returns
    -------
    The ``report.json`` content as a dict.
    """
    names = default_methods() if not methods else list(methods)
    check_methods(names)  # unknown names, unusable glsl: files
    if repeat < 0:
        raise WorkbenchError(f"repeat must be >= 0, got {repeat}")
    w, h = size if size else (scene.camera.width, scene.camera.height)
    refs = References(scene, w, h, reference)
    ref = refs.full
    ref_img = ref.run.image
    ref_features = list(ref.run.result.features_used)
    runs = [timed_run(scene, m, w, h, repeat=repeat) for m in names]

    entries = [_method_entry(r, ref_features) for r in runs]
    maps = {}
    for r, e in zip(runs, entries):
        if r.status == "ok":
            e["metrics"], m = metrics_and_maps(r.image, ref_img)
            maps[r.method] = (m["flip"], m["abs"])
            e["matched"] = _matched_entry(refs, r)
            ladder = _standin_ladder(scene, r, w, h, ref_img)
            if ladder:
                e["standins_ladder"] = ladder
    # shared scale: the median over methods of their 99.5th percentile, at most display white
    # (1.0); larger errors saturate, so one far-off method does not blacken every other map
    abs_max = max(min(1.0, float(np.median([np.percentile(a, 99.5) for _, a in maps.values()] or [1.0]))), 1e-6)

    report = {
        "kind": "compare", "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command": command,
        "scene": {"name": scene.name, "source": scene.source, "description": scene.description,
                  "needs": sorted(scene_needs(scene))},
        "size": [w, h], "repeat": repeat,
        "timing_protocol": "one cold call (compile reported apart) then `repeat` warm calls, "
                           "sequential in one process; time_s = median of the warm calls",
        "reference": {**ref.describe(), "stats": stats_for_display(ref.run.result.stats),
                      "files": {"png": "images/reference.png", "npy": "images/reference.npy"}},
        "error_split": ("metrics: against the full reference (total error); matched.metrics: against "
                        "the method's matched reference, which computes exactly the method's own physics "
                        "(discretisation error); missing_physics_rmse = total RMSE - matched RMSE"),
        "heatmap_scales": {"flip": [0.0, 1.0], "abs": [0.0, abs_max]},
        "methods": entries,
        "machine": machine_info(_gl_renderer(runs + [ref.run])),
    }
    with staged(out_dir, last=("report.json", "report.html")) as stage:
        save_png(stage / "images/reference.png", ref_img)
        save_npy(stage / "images/reference.npy", ref_img)
        tiles = [{"title": f"reference: {ref.method}",
                  "lines": [_fmt_opts(ref.options) or "default options", f"time {ref.run.time:.3g} s",
                            f"own error {ref.noise:.2g}" if ref.noise else "error 0 by definition"],
                  "image": ref_img}]
        notes = []
        for r, e in zip(runs, entries):
            if r.status != "ok":
                notes.append(f"{r.method}: {r.status.replace('_', ' ')}: {r.reason}")
                continue
            stem = file_stem(r.method)
            files = {"png": f"images/{stem}.png", "npy": f"images/{stem}.npy",
                     "heat_flip": f"heat/{stem}_flip.png", "heat_abs": f"heat/{stem}_abs.png"}
            save_png(stage / files["png"], r.image)
            save_npy(stage / files["npy"], r.image)
            fmap, amap = maps[r.method]
            save_png8(stage / files["heat_flip"], figures.heatmap(fmap, 0.0, 1.0, "FLIP", r.method))
            save_png8(stage / files["heat_abs"], figures.heatmap(amap, 0.0, abs_max, "|linear error|", r.method))
            e["files"] = files
            mt = e["metrics"]
            tiles.append({"title": r.method, "lines": [
                f"{r.time:.3g} s; compile {r.compile:.2g} s",
                f"RMSE {mt['rmse']:.3g}  PSNR {mt['psnr']:.3g} dB", f"FLIP {mt['flip']:.3g}",
                (f"vs matched: RMSE {e['matched']['metrics']['rmse']:.3g}" if "metrics" in e["matched"]
                 else "no matched reference")],
                "image": r.image})
        save_png8(stage / "grid.png", figures.grid(tiles, notes=notes))
        (stage / "report.json").write_text(dumps(report))
        (stage / "report.html").write_text(render_html(report, stage, Path(out_dir)))
    return jsonable(report, strict=False)


def _matched_entry(refs: References, run: MethodRun) -> dict:
    """The run's error against its matched reference and the gap to its total error."""
    mref = refs.matched(run.method, run.options)
    if mref is None:
        return {"none": matched_reason(run.method)}
    mt = metrics(run.image, mref.image)
    return {"reference": mref.describe(), "metrics": mt}


def _standin_ladder(scene: Scene, run: MethodRun, w: int, h: int, ref_img: np.ndarray) -> list[dict]:
    """By how much each stand-in reduces the error (issue 15): the total RMSE of a run that
    drew the raster's stand-ins (``stats["standins"]`` not empty), rendered again with none
    (``standins=off``) and then adding its stand-ins one at a time in ``KINDS`` order
    (environment maps, blending, shadow maps), its own options otherwise; the last step is
    the run itself.  Empty for a method or run without stand-ins."""
    if not getattr(get_renderer(run.method), "draws_standins", False) or not run.result.stats.get("standins"):
        return []
    kinds = parse_standins(run.options.get("standins", "on")).split(",")
    steps = ["off"] + [",".join(kinds[:i + 1]) for i in range(len(kinds) - 1)]
    ladder = []
    for st in steps:
        img = render(scene, run.method, width=w, height=h, **{**run.options, "standins": st}).image
        ladder.append({"standins": st, "rmse": metrics(img, ref_img)["rmse"]})
    ladder.append({"standins": ",".join(kinds), "rmse": metrics(run.image, ref_img)["rmse"]})
    return ladder


def _list(items) -> str:
    """``left_out`` notes (or their printed forms, from a report's JSON) as one cell."""
    return "; ".join(map(str, items)) if items else "none"


def render_html(report: dict, stage: Path, out_dir: Path) -> str:
    """The self-contained page of a comparison report (images from ``stage``; the study's
    plot and Pareto table from ``out_dir`` when ``workbench study`` wrote there before)."""
    ref = report["reference"]
    scene = report["scene"]
    b = [f"<h1>{esc(scene['name'])}: methods side by side</h1>",
         f"<p>{esc(scene['description'])}<br><span class='muted'>{esc(scene['source'])} · "
         f"{report['size'][0]}x{report['size'][1]} · {esc(report['created'])}</span></p>",
         f"<p>Scene uses: {esc(', '.join(scene['needs']))}</p>",
         f"<h2>Reference: {esc(ref['method'])} ({esc(_fmt_opts(ref['options']) or 'default options')})</h2>",
         f"<p>{esc(ref['reason'])}. Contains: {esc(ref['what'])}. Time {ref['time_s']:.3g} s "
         f"(cache: {esc(ref['cache'] or 'not used')}).</p>",
         f"<p>Its own error: {ref['noise_rmse']:.3g} ({esc(ref['noise_note'])}); differences below "
         "this are not resolved. Image definition: " + esc(ref['image_definition']) + ".</p>",
         "<h2>Side by side</h2>", img_tag(stage / "grid.png", "grid"),
         f"<p class='muted'>Timing: {esc(report['timing_protocol'])} (repeat = {report['repeat']}).</p>"]
    rows, cls = [], []
    for e in report["methods"]:
        if e["status"] != "ok":
            rows.append([e["method"], ("raw", f"<b>{esc(e['status'])}</b>: {esc(e['reason'])}"),
                         "", "", "", "", "", "", "", "", "", ""])
            cls.append("warn" if e["status"] in ("not_applicable", "over_memory") else "bad")
            continue
        mt, mm = e["metrics"], e["matched"]
        if "metrics" in mm:
            r = mm["reference"]
            matched = (mm["metrics"]["rmse"], f"{r['method']} ({_fmt_opts(r['options'])})",
                       mt["rmse"] - mm["metrics"]["rmse"])
        else:
            matched = ("", mm["none"], "")
        rows.append([e["method"], _fmt_opts(e["options"]), e["time_s"], e["compile_s"], mt["rmse"],
                     matched[0], matched[2], matched[1],
                     mt["psnr"], mt["flip"], ", ".join(e["features_used"]), _list(e["left_out"]),
                     ", ".join(e["differs_physically"]) or "none"])
        cls.append("")
    b += ["<h2>Numbers</h2>", table(["method", "options", "time (s, warm)", "compile (s)", "RMSE (total)",
                                     "RMSE vs matched (discretisation)", "gap (missing physics)",
                                     "matched reference", "PSNR (dB)",
                                     "FLIP", "features used", "left out", "differs physically from reference by"],
                                    rows, numeric={2, 3, 4, 5, 6, 8, 9}, row_class=cls),
          "<p class='muted'>" + esc(report["error_split"]) + ".</p>",
          "<p class='muted'>'differs physically': features the reference computes that the method leaves "
          "out; its error then measures the missing effect, not only discretisation.</p>",
          _ladder_section(report["methods"]),
          "<h2>Error heat maps against the reference</h2>",
          "<p>FLIP (perceptual, scale 0..1) and mean |linear error| over RGB "
          f"(scale 0..{report['heatmap_scales']['abs'][1]:.3g}, shared by all methods: the median of their "
          "99.5th percentiles, at most 1; larger errors saturate).</p>"]
    for e in report["methods"]:
        if e["status"] == "ok":
            b.append("<div>" + "".join(f"<figure>{img_tag(stage / e['files'][k], k)}<figcaption>"
                                        f"{esc(e['method'])} {k[5:]}</figcaption></figure>"
                                        for k in ("heat_flip", "heat_abs")) + "</div>")
    b += [_study_section(out_dir), "<h2>Statistics per method</h2>"]
    for e in [{"method": f"reference ({ref['method']})", **ref}] + [x for x in report["methods"] if "stats" in x]:
        b.append(f"<details><summary>{esc(e['method'])}</summary>"
                 + table(["key", "value"], [[k, v] for k, v in e.get("timings", {}).items()]
                         + [[k, v] for k, v in e["stats"].items()]) + "</details>")
    b += ["<h2>Machine</h2>", table(["key", "value"], [[k, v] for k, v in report["machine"].items()])]
    return page(f"{scene['name']} comparison", "\n".join(b))


def _ladder_section(methods: list[dict]) -> str:
    """The stand-ins' table: each raster run's total RMSE with none of its stand-ins, then adding
    them one at a time (:func:`_standin_ladder`)."""
    rows = [[e["method"], step["standins"], step["rmse"],
             "" if i == 0 else e["standins_ladder"][i - 1]["rmse"] - step["rmse"]]
            for e in methods for i, step in enumerate(e.get("standins_ladder", []))]
    if not rows:
        return ""
    return ("<h2>Stand-ins: how much each reduces the error</h2><p>The raster methods' stand-ins for "
            "global effects (environment maps, blending, shadow maps), added one at a time to the bare "
            "local model (<code>standins=off</code>); RMSE against the full reference.</p>"
            + table(["method", "standins", "RMSE (total)", "reduction by this step"], rows, numeric={2, 3}))


def _study_section(out_dir: Path) -> str:
    js, png = out_dir / "study.json", out_dir / "study.png"
    if not (js.is_file() and png.is_file()):
        return ("<h2>Error against run time</h2><p class='muted'>No study in this folder "
                "(run <code>workbench study SCENE --out DIR</code> first to include it).</p>")
    study = loads(js.read_text())
    rows = [[p["method"], f"{p['knob']}={p['value']}", p["time_s"], p["rmse"], p["flip"]]
            for p in study["points"] if p.get("pareto")]
    return ("<h2>Error against run time</h2>" + img_tag(png, "study") +
            "".join(f"<p>{esc(n)}</p>" for n in study.get("notes", [])) +
            f"<p>Study of {esc(study['scene']['name'])} at {study['size'][0]}x{study['size'][1]} "
            f"(reference {esc(study['reference']['method'])}); Pareto front:</p>"
            + table(["method", "setting", "time (s)", "RMSE", "FLIP"], rows, numeric={2, 3, 4}))
