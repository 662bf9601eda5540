"""Images of every bundled scene with every CPU ray method (ray casting, Whitted, path tracing,
radiosity, hybrid), for checking that a change to the numba kernel layer leaves warm images as
they were: ``record`` writes them to ``bench/results/kernel_images.npz``; ``check`` renders them
again and writes the RMSE of each against the recorded one to
``bench/results/kernel_images.json`` (the kernel-layer issue asks for every RMSE <= 1e-4).

Run: ``.venv/bin/python bench/kernel_images.py record`` before the change,
``.venv/bin/python bench/kernel_images.py check`` after it (``check`` also writes
``docs/benchmarks/kernel_images.md``).  ``--smoke``: ``record`` then ``check`` of the ``cornell``
scene alone at 16 x 12 (every method applies to it), in the ``--out`` folder.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from _common import Page, first_paragraph, table

ROOT = Path(__file__).resolve().parents[1]
SIZE = (64, 48)
SMOKE_SIZE, SMOKE_SCENES = (16, 12), ("cornell",)
METHODS = {"raycast": {}, "raytrace": {}, "pathtrace": {"spp": 4}, "radiosity": {"patch_size": 0.2},
           "hybrid": {"patch_size": 0.2}}
LIMIT = 1e-4


def images(size=SIZE, scenes=None) -> dict[str, np.ndarray]:
    """``{"scene/method": image}`` (float32, linear) of every scene (or those named) and method
    that applies."""
    import workbench
    out = {}
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        if scenes is not None and path.stem not in scenes:
            continue
        scene = workbench.load_scene(str(path))
        for method, options in METHODS.items():
            try:
                result = workbench.render(scene, method, width=size[0], height=size[1], **options)
            except workbench.WorkbenchError as e:  # not applicable, or over the memory limit
                print(f"{path.stem}/{method}: {e}", flush=True)
                continue
            out[f"{path.stem}/{method}"] = np.asarray(result.image, np.float32)
            print(f"{path.stem}/{method}", flush=True)
    return out


def tables(res: dict) -> str:
    rm = res["rmse"]
    per = {}
    for key, v in rm.items():
        per.setdefault(key.split("/")[1], []).append(v)
    w, h = res["size"]
    out = [f"Images {w} x {h} of every bundled scene and CPU ray method, against the images recorded before "
           f"the kernel-layer change (the anchor: the code before it).  Limit: RMSE <= {res['limit']:g}.", "",
           table(["worst RMSE", "limit", "within the limit", "images", "missing"],
                 [[res["worst_rmse"], res["limit"], res["worst_rmse"] <= res["limit"] and not res["missing"],
                   len(rm), ", ".join(res["missing"]) or "none"]]),
           "## Per method", "",
           table(["method", "options", "images", "worst RMSE"],
                 [[m, str(res["methods"].get(m, {})), len(v), max((x for x in v if x is not None), default=None)]
                  for m, v in sorted(per.items())])]
    return "\n".join(out)


PAGE = Page("kernel_images", "Kernel layer: images before and after", first_paragraph(__doc__),
            "python bench/kernel_images.py record (before the change); python bench/kernel_images.py check (after it)",
            tables, smoke_note="record then check of cornell at 16 x 12")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("action", nargs="?", choices=("record", "check"),
                    help="record the images, or check against the recorded ones (--smoke: both)")
    args = PAGE.parse(ap, argv)
    if args.action is None and not args.smoke:
        ap.error("record or check (or --smoke)")
    recorded = args.out / "kernel_images.npz"
    size, scenes = (SMOKE_SIZE, SMOKE_SCENES) if args.smoke else (SIZE, None)
    now = images(size, scenes)
    if args.action == "record" or args.smoke:
        np.savez_compressed(recorded, **now)
        if not args.smoke:
            return 0
        now = images(size, scenes)
    before = dict(np.load(recorded))
    rows = {}
    for key in sorted(set(before) | set(now)):
        if key not in before or key not in now:
            rows[key] = None
            continue
        rows[key] = float(np.sqrt(np.mean((now[key].astype(np.float64) - before[key]) ** 2)))
    worst = max((v for v in rows.values() if v is not None), default=0.0)
    report = {"size": list(size), "methods": METHODS, "limit": LIMIT, "worst_rmse": worst,
              "missing": sorted(k for k, v in rows.items() if v is None), "rmse": rows}
    PAGE.write(args, report)
    print(json.dumps({"worst_rmse": worst, "missing": report["missing"]}))
    return 0 if worst <= LIMIT and not report["missing"] else 1


if __name__ == "__main__":
    sys.exit(main())
