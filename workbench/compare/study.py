"""``workbench study``: error against run time along each method's quality knob.

For every method and every value of its knob (``get_renderer(m).knob.values``, cheapest to most
accurate, or another option given with ``--sweep``; ``--quick`` keeps at most 4 of them, evenly
spread and including both ends), the
point is rendered once cold (shader / JIT compile time reported apart) and ``repeat`` times warm;
its run time is the median of the warm wall times.  Its error against the scene's reference
(RMSE, PSNR, FLIP; :mod:`workbench.compare.metrics`) is measured on the last image.

How timing is protected on a small shared machine: every timed render runs sequentially in
this one process, nothing else of the study running meanwhile.  Only the error evaluation
(FLIP dominates it) runs in parallel worker processes, after the last timed render, when
``jobs > 1``.  Machine load at the start is recorded with the results.

Outputs in ``out_dir``: ``study.csv``, ``study.json``, ``study.png`` (log-log error against
warm run time per method, RMSE and FLIP panels, the Pareto front over all methods marked),
``study.html``.
"""
from __future__ import annotations

import csv
import datetime as _dt
import io
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..renderers.base import check_methods, default_methods, get_renderer
from ..scene.model import Scene
from .html import esc, img_tag, page, table
from .metrics import metrics
from .outputs import dumps, machine_info, staged
from .reference import SAMPLING_NOTE, choose_reference
from .runs import timed_run

CSV_FIELDS = ["method", "knob", "value", "status", "reason", "time_s", "cold_s", "compile_s", "rmse",
              "psnr", "flip", "nonfinite_pixels", "is_reference", "pareto_rmse", "pareto_flip"]


def sweep_values(values: tuple, quick: bool) -> list:
    """The knob values to visit: all of them, or (quick) at most 4 evenly spread with both ends."""
    values = list(values)
    if not quick or len(values) <= 4:
        return values
    idx = sorted(set(np.linspace(0, len(values) - 1, 4).round().astype(int).tolist()))
    return [values[i] for i in idx]


def pareto(times: list[float], errors: list[float]) -> list[bool]:
    """Points not dominated by another (no other point at most as slow *and* at most as wrong,
    one of both strictly).  Points with a non-positive or non-finite error or time are not on
    the front (they cannot appear on a log-log plot)."""
    t, e = np.asarray(times, dtype=float), np.asarray(errors, dtype=float)
    valid = np.isfinite(t) & np.isfinite(e) & (t > 0) & (e > 0)
    out = []
    for i in range(len(t)):
        if not valid[i]:
            out.append(False)
            continue
        dom = valid & (t <= t[i]) & (e <= e[i]) & ((t < t[i]) | (e < e[i]))
        out.append(not dom.any())
    return out


def _metrics_job(args):
    image, ref = args
    return metrics(image, ref)


def evaluate(images: list[np.ndarray], reference: np.ndarray, jobs: int) -> list[dict]:
    """Metrics of every image against the reference, in ``jobs`` worker processes if > 1."""
    if jobs <= 1 or len(images) < 2:
        return [metrics(im, reference) for im in images]
    import multiprocessing
    # "spawn": fresh workers, not forks of a process holding GL contexts and numba threads
    with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
        return list(pool.map(_metrics_job, [(im, reference) for im in images]))


def study(scene: Scene, out_dir: str | Path, methods: list[str] | None = None,
          size: tuple[int, int] | None = None, quick: bool = False, repeat: int | None = None,
          reference: str | None = None, reference_image: tuple[np.ndarray, str] | None = None,
          sweeps: dict[str, tuple[str, list]] | None = None, jobs: int = 1, progress: bool = True,
          command: str = "") -> dict:
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
    repeat = (2 if quick else 5) if repeat is None else int(repeat)
    if repeat < 1:
        raise WorkbenchError(f"a study needs at least one warm run per point, got repeat={repeat}")
    if reference_image is not None:
        ref_img = np.asarray(reference_image[0], dtype=np.float32)
        h, w = ref_img.shape[:2]
        ref_info = {"method": "given", "options": {}, "reason": reference_image[1]}
    else:
        w, h = size if size else ((160, max(1, round(160 / scene.camera.aspect))) if quick
                                  else (scene.camera.width, scene.camera.height))
        ref = choose_reference(scene, w, h, reference)
        ref_img = ref.run.image
        ref_info = {"method": ref.method, "options": ref.options, "reason": ref.reason,
                    "time_s": ref.run.time, "compile_s": ref.run.compile}
    load = machine_info()

    plan = []
    for m in names:
        try:
            knob = get_renderer(m).knob
        except ImportError as e:
            plan.append((m, None, None, f"cannot be loaded ({e})"))
            continue
        option, values = sweeps.get(m, (knob.name, knob.values))
        plan += [(m, option, v, "") for v in sweep_values(tuple(values), quick)]
    points, images = [], []
    from tqdm import tqdm
    bar = tqdm(total=len(plan) * (repeat + 1), desc=f"study {scene.name}", unit="render",
               disable=not progress, leave=False)
    skip: dict[str, str] = {}
    for m, knob, value, why in plan:
        p = {"method": m, "knob": knob, "value": value, "status": "failed" if why else "ok", "reason": why}
        if why or m in skip:
            p.update(status=p["status"] if why else "not_applicable", reason=why or skip[m])
            bar.update(repeat + 1)
            points.append(p)
            continue
        run = timed_run(scene, m, w, h, repeat=repeat, options={knob: value})
        bar.update(repeat + 1)
        p.update(status=run.status, reason=run.reason)
        if run.status == "not_applicable":
            skip[m] = run.reason  # the scene, not the setting, makes it inapplicable
        if run.status == "ok":
            p.update(time_s=run.time, warm_s=run.warm, cold_s=run.cold, compile_s=run.compile,
                     nonfinite_pixels=run.result.stats.get("nonfinite_pixels", 0),
                     features_used=run.result.features_used, left_out=run.result.left_out,
                     is_reference=(m == ref_info["method"] and {knob: value} == ref_info["options"]))
            images.append((len(points), run.image))
        points.append(p)
    bar.close()
    for (i, _), mt in zip(images, evaluate([im for _, im in images], ref_img, jobs)):
        points[i].update(mt)
    ok = [p for p in points if p["status"] == "ok"]
    for key in ("rmse", "flip"):
        for p, f in zip(ok, pareto([p["time_s"] for p in ok], [p[key] for p in ok])):
            p[f"pareto_{key}"] = f
    for p in ok:
        p["pareto"] = p["pareto_rmse"]

    result = {
        "kind": "study", "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command": command, "quick": quick, "repeat": repeat, "size": [w, h], "jobs": jobs,
        "scene": {"name": scene.name, "source": scene.source, "needs": sorted(scene.needs())},
        "reference": ref_info,
        "timing_protocol": "per point: 1 cold call (compile reported apart) + `repeat` warm calls, all "
                           "sequential in one process; time_s = median of warm wall times; error "
                           f"evaluation afterwards ({'in %d worker processes' % jobs if jobs > 1 else 'in-process'})",
        "points": points, "machine": load,
        "notes": [SAMPLING_NOTE] if any(p["knob"] == "spp" for p in points) else [],
    }
    with staged(out_dir, last=("study.json", "study.html")) as stage:
        plot(points, stage / "study.png", f"{scene.name} {w}x{h}: error against warm run time "
             f"(reference {ref_info['method']})")
        (stage / "study.csv").write_text(to_csv(points))
        (stage / "study.json").write_text(dumps(result))
        (stage / "study.html").write_text(render_html(result, stage))
    return json.loads(dumps(result))


def to_csv(points: list[dict]) -> str:
    buf = io.StringIO()
    wr = csv.DictWriter(buf, CSV_FIELDS, extrasaction="ignore", lineterminator="\n")
    wr.writeheader()
    for p in points:
        wr.writerow({k: p.get(k, "") for k in CSV_FIELDS})
    return buf.getvalue()


def plot(points: list[dict], path: Path, title: str) -> None:
    """Log-log error against warm run time, one line per method along its knob, the Pareto
    front over all methods as a dashed step line through ringed points; RMSE and FLIP panels."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    ok = [p for p in points if p["status"] == "ok"]
    methods = list(dict.fromkeys(p["method"] for p in ok))
    for ax, key, label in ((axes[0], "rmse", "RMSE (linear)"), (axes[1], "flip", "mean FLIP")):
        dropped = 0
        for k, m in enumerate(methods):
            pts = [p for p in ok if p["method"] == m and p[key] > 0 and p["time_s"] > 0]
            dropped += sum(1 for p in ok if p["method"] == m) - len(pts)
            if not pts:
                continue
            t, e = [p["time_s"] for p in pts], [p[key] for p in pts]
            ax.plot(t, e, "o-", color=f"C{k % 10}", label=f"{m} ({pts[0]['knob']})", ms=4)
            for p in pts:
                ax.annotate(str(p["value"]), (p["time_s"], p[key]), fontsize=7, xytext=(3, 3),
                            textcoords="offset points", color=f"C{k % 10}")
        front = sorted((p["time_s"], p[key]) for p in ok if p.get(f"pareto_{key}"))
        if front:
            ft, fe = zip(*front)
            ax.step(ft, fe, "k--", where="post", lw=1, label="Pareto front")
            ax.plot(ft, fe, "o", mfc="none", mec="k", ms=9)
        if any(p[key] > 0 and p["time_s"] > 0 for p in ok):
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_xlabel("warm wall time per image (s)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        if dropped:
            ax.set_title(f"{dropped} point(s) with zero error (the reference) not shown", fontsize=8)
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def render_html(result: dict, stage: Path) -> str:
    rows = [[p["method"], f"{p['knob']}={p['value']}", p["status"] + (f": {p['reason']}" if p["reason"] else ""),
             p.get("time_s", ""), p.get("compile_s", ""), p.get("rmse", ""), p.get("psnr", ""),
             p.get("flip", ""), "yes" if p.get("pareto") else ""] for p in result["points"]]
    ref = result["reference"]
    body = [f"<h1>{esc(result['scene']['name'])}: error against run time</h1>",
            f"<p>Reference: {esc(ref['method'])} {esc(ref['options'])}: {esc(ref['reason'])}</p>",
            img_tag(stage / "study.png", "study"),
            f"<p class='muted'>{esc(result['timing_protocol'])}</p>",
            "".join(f"<p>{esc(n)}</p>" for n in result["notes"]),
            table(["method", "setting", "status", "time (s, warm median)", "compile (s)", "RMSE",
                   "PSNR (dB)", "FLIP", "Pareto (RMSE)"], rows, numeric={3, 4, 5, 6, 7}),
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
            rows.append([p["method"], ", ".join(p["features_used"]), "; ".join(p["left_out"]) or "none"])
    return rows
