"""``workbench study``: error against run time along each method's quality knob.

For every method and every value of its knob (``get_renderer(m).knob.values``, cheapest to most
accurate, or another option given with ``--sweep``, or on a scene with hypertextures the march's
step or the 3D texture's resolution when the method has them: :data:`.reference.MEDIUM_KNOBS`; ``--quick``
keeps at most 4 of them, evenly spread and including both ends), the
point is rendered once cold (shader / JIT compile time reported apart) and ``repeat`` times warm;
its run time is the median of the warm wall times.  Its error against the scene's reference
(RMSE, PSNR, FLIP; :mod:`workbench.compare.metrics`) is measured on the last image.

How timing is protected on a small shared machine: every timed render runs sequentially in
this one process, nothing else of the study running meanwhile.  Only the error evaluation
(FLIP dominates it) runs in parallel worker processes, after the last timed render, when
``jobs > 1``.  Machine load at the start is recorded with the results.

On a Dask cluster (``cluster="tcp://HOST:8786"``, :mod:`.executors`) the points run on the
cluster's workers instead, each point's renders on one worker (the worker is named in the
point's ``worker``), and so does the error evaluation; the references are rendered here.  The
rows are the same as a local run's, in the same order (the grid's, not the order the points
finished); only the times (and the Pareto flags that follow from them) are the workers'.

Outputs in ``out_dir``: ``study.csv``, ``study.json``, ``study.png`` (log-log error against
warm run time per method, RMSE and FLIP panels, the Pareto front over all methods marked),
``study.html``.
"""
from __future__ import annotations

import csv
import datetime as _dt
import io
from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..renderers.base import check_methods, convert_options, default_methods, get_renderer
from ..scene.model import Scene
from .executors import Executor, open_executor
from .html import esc, img_tag, page, table
from .metrics import metrics
from .outputs import dumps, jsonable, machine_info, staged
from .reference import MEDIUM_KNOBS, SAMPLING_NOTE, References
from .runs import timed_run
from ..scene.features import HYPERTEXTURES, scene_needs

CSV_FIELDS = ["method", "knob", "value", "status", "reason", "time_s", "cold_s", "compile_s", "rmse",
              "psnr", "flip", "rmse_matched", "flip_matched", "matched_reference", "nonfinite_pixels",
              "is_reference", "pareto_rmse", "pareto_flip"]


def sweep_values(values: tuple, quick: bool) -> list:
    """The knob values to visit: all of them, or (quick) at most 4 evenly spread with both ends."""
    values = list(values)
    if not quick or len(values) <= 4:
        return values
    idx = sorted(set(np.linspace(0, len(values) - 1, 4).round().astype(int).tolist()))
    return [values[i] for i in idx]


def method_sweep(scene: Scene, method: str, sweeps: dict[str, tuple[str, list]]) -> tuple[str, tuple]:
    """``(option, values)`` the study sweeps for ``method``: the ``sweeps`` entry if given, else
    on a scene with hypertextures the first option of :data:`.reference.MEDIUM_KNOBS` that the method's
    options table declares, else the method's knob.  Raises ImportError when the method's module
    cannot be loaded."""
    r = get_renderer(method)
    if method in sweeps:
        option, values = sweeps[method]
        return option, tuple(values)
    if HYPERTEXTURES in scene_needs(scene):
        for option, values in MEDIUM_KNOBS:
            if option in r.options:
                return option, values
    return r.knob.name, tuple(r.knob.values)


def study_plan(scene: Scene, names: list[str], sweeps: dict[str, tuple[str, list]],
               quick: bool) -> list[tuple[str, str | None, object, str]]:
    """The study's grid: ``(method, option, value, why)`` per point, in the order they run;
    ``why`` is empty, or says why the method cannot be loaded (one point, option and value None)."""
    plan = []
    for m in names:
        try:
            option, values = method_sweep(scene, m, sweeps)
        except ImportError as e:
            plan.append((m, None, None, f"cannot be loaded ({e})"))
            continue
        plan += [(m, option, v, "") for v in sweep_values(values, quick)]
    return plan


def pareto(times: list[float], errors: list[float]) -> list[bool]:
    """Points not dominated by another (no other point at most as slow *and* at most as wrong,
    one of both strictly).  A zero error is a valid point (a method that meets the reference
    exactly is on the front if nothing faster does as well); points with a negative or
    non-finite error, or a non-positive time, are not on the front.  The reference itself is
    left out by the caller (its error is zero by definition)."""
    t, e = np.asarray(times, dtype=float), np.asarray(errors, dtype=float)
    valid = np.isfinite(t) & np.isfinite(e) & (t > 0) & (e >= 0)
    out = []
    for i in range(len(t)):
        if not valid[i]:
            out.append(False)
            continue
        dom = valid & (t <= t[i]) & (e <= e[i]) & ((t < t[i]) | (e < e[i]))
        out.append(not dom.any())
    return out


def _metrics_job(reference, image):
    return metrics(image, reference)


def _metrics_pair(_, pair):
    image, reference = pair
    return metrics(image, reference)


def evaluate(images: list[np.ndarray], reference: np.ndarray, jobs: int = 1,
             executor: Executor | None = None) -> list[dict]:
    """Metrics of every image against the reference: on ``executor``'s workers when given,
    else in ``jobs`` local worker processes if > 1 (spawned: fresh processes, not forks of one
    holding GL contexts and numba threads)."""
    if executor is None:
        with open_executor(jobs) as ex:
            return ex.map(_metrics_job, list(images), shared=reference)
    return executor.map(_metrics_job, list(images), shared=reference)


def _timed_point(shared, item) -> dict:
    """One point of the grid: ``shared = (scene, width, height, repeat)``, ``item = (method,
    knob, value, options)``; what the study keeps of its :func:`timed_run`, image included."""
    scene, w, h, repeat = shared
    method, _, _, options = item
    run = timed_run(scene, method, w, h, repeat=repeat, options=options)
    out = {"method": method, "status": run.status, "reason": run.reason}
    if run.status == "ok":
        out.update(time_s=run.time, warm_s=run.warm, cold_s=run.cold, compile_s=run.compile,
                   nonfinite_pixels=run.result.stats.get("nonfinite_pixels", 0),
                   features_used=run.result.features_used, left_out=run.result.left_out, image=run.image)
    return out


def _skip_inapplicable(item, earlier: list[dict]) -> dict | None:
    """A method found not to apply at one setting is not run at the next: the scene, not the
    setting, makes it inapplicable (the first point's reason stands for the rest)."""
    for r in earlier:
        if r["method"] == item[0] and r["status"] == "not_applicable":
            return {"method": item[0], "status": "not_applicable", "reason": r["reason"]}
    return None


def study(scene: Scene, out_dir: str | Path, methods: list[str] | None = None,
          size: tuple[int, int] | None = None, quick: bool = False, repeat: int | None = None,
          reference: str | None = None, reference_image: tuple[np.ndarray, str] | None = None,
          sweeps: dict[str, tuple[str, list]] | None = None, jobs: int = 1, progress: bool = True,
          command: str = "", fixed: dict[str, dict] | None = None, cluster: str | None = None) -> dict:
    """Sweep each method's knob, time it and measure its error; write the study files.

    Parameters
    ----------
    methods : method names (default: every registered one except the opt-in outside references,
        ``base.default_methods()``).
    size : (width, height); default 160 pixels wide (quick) or the camera's resolution, at
        the camera's aspect ratio.
    repeat : warm runs per point (default 2 quick, 5 otherwise); time = their median.
    reference : force the reference method (rule of :mod:`.reference` otherwise).
    reference_image : ``(image (H, W, 3), description)`` to use as the reference instead of a
        render (e.g. an analytic image); its size sets the study's size.
    sweeps : ``{method: (option, values)}`` to sweep another option than the method's knob
        (e.g. radiosity's ``hemicube_resolution``), values cheapest first.
    jobs : worker processes for the error evaluation (after all timing is done).
    cluster : address of a Dask scheduler (``tcp://HOST:8786``): the points and the error
        evaluation run on its workers (:mod:`.executors`; needs ``workbench[cluster]``);
        ``jobs`` must then be 1.
    fixed : ``{method: {option: value}}`` held at every point of that method's sweep (e.g.
        ``standins=off`` for Gouraud and Phong; the matched reference follows them).
    """
    names = default_methods() if not methods else list(methods)
    check_methods(names)  # unknown names, unusable glsl: files
    sweeps = sweeps or {}
    for m, (option, values) in sweeps.items():
        if m not in names:
            raise WorkbenchError(f"--sweep {m}:{option}: method {m!r} is not among the studied methods")
        if option not in get_renderer(m).options:
            raise WorkbenchError(f"--sweep {m}:{option}: {m} has no option {option!r} "
                                 f"(accepted: {', '.join(sorted(get_renderer(m).options))})")
        if not values:
            raise WorkbenchError(f"--sweep {m}:{option}: no values to sweep")
        for v in values:    # every value converted now: a bad one fails before any render
            try:
                convert_options(get_renderer(m), {option: v})
            except WorkbenchError as e:
                raise WorkbenchError(f"--sweep {m}:{option}: {e}") from None
    fixed = fixed or {}
    for m, opts in fixed.items():
        if m not in names:
            raise WorkbenchError(f"--set {m}:...: method {m!r} is not among the studied methods")
        try:
            convert_options(get_renderer(m), dict(opts))
        except WorkbenchError as e:
            raise WorkbenchError(f"--set for {m}: {e}") from None
    repeat = (2 if quick else 5) if repeat is None else int(repeat)
    if repeat < 1:
        raise WorkbenchError(f"a study needs at least one warm run per point, got repeat={repeat}")
    if reference is not None:
        get_renderer(reference)  # an unknown --reference fails now, not after the sweep
    if reference_image is not None:
        h, w = np.asarray(reference_image[0]).shape[:2]
    else:
        w, h = size if size else ((160, max(1, round(160 / scene.camera.aspect))) if quick
                                  else (scene.camera.width, scene.camera.height))
    load = machine_info()
    with open_executor(jobs, cluster) as ex:  # a bad --cluster fails here, before any render
        return _study(scene, out_dir, names, w, h, quick, repeat, reference, reference_image, sweeps,
                      jobs, progress, command, fixed, load, ex)


def _study(scene, out_dir, names, w, h, quick, repeat, reference, reference_image, sweeps, jobs, progress,
           command, fixed, load, ex: Executor) -> dict:
    plan = study_plan(scene, names, sweeps, quick)
    points, images = [], []
    from tqdm import tqdm
    bar = tqdm(total=len(plan) * (repeat + 1), desc=f"study {scene.name}", unit="render",
               disable=not progress, leave=False)
    todo = [(m, knob, value, {**fixed.get(m, {}), knob: value}) for m, knob, value, why in plan if not why]
    bar.update((len(plan) - len(todo)) * (repeat + 1))
    runs = iter(ex.map_timed(_timed_point, todo, shared=(scene, w, h, repeat), skip=_skip_inapplicable,
                             done=lambda _: bar.update(repeat + 1)))
    where = iter(ex.last_where or [None] * len(todo))
    for m, knob, value, why in plan:  # the grid's order, whichever order the points finished in
        p = {"method": m, "knob": knob, "value": value, "status": "failed" if why else "ok", "reason": why,
             "options": dict(fixed.get(m, {}))}
        if why:
            points.append(p)
            continue
        run, worker = next(runs), next(where)
        p.update(status=run["status"], reason=run["reason"])
        if run["status"] == "ok":
            p.update({k: v for k, v in run.items() if k not in ("method", "status", "reason", "image")})
            if worker is not None:
                p["worker"] = worker
            images.append((len(points), run["image"]))
        points.append(p)
    bar.close()
    ok = [p for p in points if p["status"] == "ok"]
    if not ok:  # said before the reference is rendered: it may take minutes
        why = sorted({f"{p['method']}: {p['status']} ({p['reason']})" for p in points})
        raise WorkbenchError(f"nothing to study on {scene.name}: no setting rendered ({'; '.join(why)})")
    refs = None
    if reference_image is not None:
        ref_img = np.asarray(reference_image[0], dtype=np.float32)
        ref_info = {"method": "given", "options": {}, "reason": reference_image[1]}
    else:
        if progress:
            print(f"study {scene.name}: rendering the reference (cached after the first run)", flush=True)
        refs = References(scene, w, h, reference)
        ref_img = refs.full.image
        ref_info = refs.full.describe()
    for p in ok:
        p["is_reference"] = p["method"] == ref_info["method"] and {p["knob"]: p["value"]} == ref_info["options"]
    for (i, _), mt in zip(images, evaluate([im for _, im in images], ref_img, executor=ex)):
        points[i].update(mt)
    matched = _matched_errors(refs, points, images, ex) if refs is not None else {}
    front = [p for p in ok if not p["is_reference"]]
    for key in ("rmse", "flip"):
        for p in ok:
            p[f"pareto_{key}"] = False
        for p, f in zip(front, pareto([p["time_s"] for p in front], [p[key] for p in front])):
            p[f"pareto_{key}"] = f
    for p in ok:
        p["pareto"] = p["pareto_rmse"]

    result = {
        "kind": "study", "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command": command, "quick": quick, "repeat": repeat, "size": [w, h], "jobs": jobs,
        "executor": ex.describe(),
        "scene": {"name": scene.name, "source": scene.source, "needs": sorted(scene_needs(scene))},
        "reference": ref_info, "matched_references": matched,
        "timing_protocol": "per point: 1 cold call (compile reported apart) + `repeat` warm calls, all "
                           f"{ex.where_timed()}; time_s = median of warm wall times; error "
                           f"evaluation afterwards ({ex.where_untimed()})",
        "points": points, "machine": load,
        "notes": [SAMPLING_NOTE, ERROR_SPLIT_NOTE],
    }
    with staged(out_dir, last=("study.json", "study.html")) as stage:
        plot(points, stage / "study.png", f"{scene.name} {w}x{h}: error against warm run time "
             f"(reference {ref_info['method']})")
        (stage / "study.csv").write_text(to_csv(points))
        (stage / "study.json").write_text(dumps(result))
        (stage / "study.html").write_text(render_html(result, stage))
    return jsonable(result, strict=False)


ERROR_SPLIT_NOTE = ("Two errors per point: against the full reference (total error) and against the "
                    "method's matched reference, which computes exactly the method's own physics "
                    "(discretisation error: it falls along the knob). Their gap is the cost of the physics "
                    "the method leaves out. Dashed lines in the plot are the matched errors.")


def _matched_errors(refs: References, points: list[dict], images: list, ex: Executor) -> dict:
    """Each rendered point's error against its method's matched reference (``rmse_matched``,
    ``flip_matched``, ``matched_reference``); returns the matched references' descriptions."""
    out, todo = {}, []
    for i, im in images:
        p = points[i]
        ref = refs.matched(p["method"], {**p.get("options", {}), p["knob"]: p["value"]})
        if ref is None:
            p["matched_reference"] = ""
            continue
        label = f"{ref.method} ({', '.join(f'{k}={v}' for k, v in ref.options.items())})"
        out.setdefault(label, ref.describe())
        p["matched_reference"] = label
        todo.append((i, im, ref.image))
    for (i, _, _), mt in zip(todo, ex.map(_metrics_pair, [(im, r) for _, im, r in todo])):
        points[i].update(rmse_matched=mt["rmse"], flip_matched=mt["flip"], psnr_matched=mt["psnr"])
    return out


def to_csv(points: list[dict]) -> str:
    buf = io.StringIO()
    wr = csv.DictWriter(buf, CSV_FIELDS, extrasaction="ignore", lineterminator="\n")
    wr.writeheader()
    for p in points:
        wr.writerow({k: p.get(k, "") for k in CSV_FIELDS})
    return buf.getvalue()


def plot(points: list[dict], path: Path, title: str) -> None:
    """Log-log error against warm run time, one line per method along its knob (solid: against
    the full reference; dashed: against the method's matched reference), the Pareto front over
    all methods as a dashed black step line through ringed points; RMSE and FLIP panels.  A zero
    error cannot sit on a log axis: such points are drawn on a floor line (half the smallest
    positive error) with a downward triangle and said in the panel's title."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    ok = [p for p in points if p["status"] == "ok" and p["time_s"] > 0]
    methods = list(dict.fromkeys(p["method"] for p in ok))
    for ax, key, label in ((axes[0], "rmse", "RMSE (linear, display range)"), (axes[1], "flip", "mean FLIP")):
        errs = [p[k] for p in ok for k in (key, f"{key}_matched") if k in p and p[k] > 0]
        floor = 0.5 * min(errs) if errs else 1e-6
        zeros = 0
        for k, m in enumerate(methods):
            pts = [p for p in ok if p["method"] == m]
            colour = f"C{k % 10}"
            t = [p["time_s"] for p in pts]
            e = [p[key] if p[key] > 0 else floor for p in pts]
            zeros += sum(1 for p in pts if p[key] <= 0)
            ax.plot(t, e, "-", color=colour, label=f"{m} ({pts[0]['knob']})", lw=1.2)
            for p, ti, ei in zip(pts, t, e):
                ax.plot([ti], [ei], "v" if p[key] <= 0 else "o", color=colour, ms=4)
                ax.annotate(str(p["value"]), (ti, ei), fontsize=7, xytext=(3, 3),
                            textcoords="offset points", color=colour)
            mpts = [p for p in pts if f"{key}_matched" in p]
            if mpts:
                ax.plot([p["time_s"] for p in mpts], [max(p[f"{key}_matched"], floor) for p in mpts],
                        "s--", color=colour, ms=3, lw=1, alpha=0.8, label=f"{m}: vs matched")
        front = sorted((p["time_s"], max(p[key], floor)) for p in ok if p.get(f"pareto_{key}"))
        if front:
            ft, fe = zip(*front)
            ax.step(ft, fe, "k--", where="post", lw=1, label="Pareto front")
            ax.plot(ft, fe, "o", mfc="none", mec="k", ms=9)
        if ok:
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_xlabel("warm wall time per image (s)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        if zeros:
            ax.set_title(f"{zeros} point(s) with zero error drawn at the floor {floor:.2g} (triangles)", fontsize=8)
        ax.legend(fontsize=6, ncol=2)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _ref_line(ref: dict) -> str:
    """One readable line on a reference: method, options, why, what it contains, its noise."""
    opts = ", ".join(f"{k}={v}" for k, v in ref.get("options", {}).items()) or "default options"
    line = f"{ref['method']} ({opts}): {ref.get('reason', '')}"
    if ref.get("what"):
        line += f"; contains: {ref['what']}"
    if ref.get("noise_note"):
        line += f"; its own error: {ref.get('noise_rmse', 0):.3g} ({ref['noise_note']})"
    return line


def render_html(result: dict, stage: Path) -> str:
    rows = [[p["method"], f"{p['knob']}={p['value']}", p["status"] + (f": {p['reason']}" if p["reason"] else ""),
             p.get("time_s", ""), p.get("compile_s", ""), p.get("rmse", ""), p.get("rmse_matched", ""),
             p.get("psnr", ""), p.get("flip", ""), p.get("flip_matched", ""),
             "yes" if p.get("pareto") else ""] for p in result["points"]]
    ref = result["reference"]
    matched = result.get("matched_references", {})
    body = [f"<h1>{esc(result['scene']['name'])}: error against run time</h1>",
            f"<p>Full reference: {esc(_ref_line(ref))}</p>",
            "<p>Matched references:</p><ul>" + "".join(f"<li>{esc(_ref_line(r))}</li>" for r in matched.values())
            + "</ul>" if matched else "",
            img_tag(stage / "study.png", "study"),
            f"<p class='muted'>{esc(result['timing_protocol'])}</p>",
            "".join(f"<p>{esc(n)}</p>" for n in result["notes"]),
            table(["method", "setting", "status", "time (s, warm median)", "compile (s)", "RMSE (total)",
                   "RMSE (vs matched)", "PSNR (dB)", "FLIP (total)", "FLIP (vs matched)", "Pareto (RMSE)"],
                  rows, numeric={3, 4, 5, 6, 7, 8, 9}),
            "<h2>Features per method</h2>",
            table(["method", "features used", "left out"], _features(result["points"])),
            "<h2>Machine</h2>", table(["key", "value"], [[k, v] for k, v in result["machine"].items()])]
    return page(f"{result['scene']['name']} study", "\n".join(body))


def _features(points: list[dict]) -> list[list[str]]:
    """One row per method: what it built of the scene and what it left out (first rendered point)."""
    seen, rows = set(), []
    for p in points:
        if p["status"] == "ok" and p["method"] not in seen:
            seen.add(p["method"])
            rows.append([p["method"], ", ".join(p["features_used"]), "; ".join(map(str, p["left_out"])) or "none"])
    return rows
