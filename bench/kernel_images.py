"""Images of every bundled scene with every CPU ray method (ray casting, Whitted, path tracing,
radiosity, hybrid), for checking that a change to the numba kernel layer leaves warm images as
they were: ``record`` writes them to ``bench/results/kernel_images.npz``; ``check`` renders them
again and writes the RMSE of each against the recorded one to
``bench/results/kernel_images.json`` (the kernel-layer issue asks for every RMSE <= 1e-4).

Run: ``.venv/bin/python bench/kernel_images.py record`` before the change,
``.venv/bin/python bench/kernel_images.py check`` after it.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
SIZE = (64, 48)
METHODS = {"raycast": {}, "raytrace": {}, "pathtrace": {"spp": 4}, "radiosity": {"patch_size": 0.2},
           "hybrid": {"patch_size": 0.2}}
LIMIT = 1e-4


def images() -> dict[str, np.ndarray]:
    """``{"scene/method": image}`` (float32, linear) of every scene and method that applies."""
    import workbench
    out = {}
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        scene = workbench.load_scene(str(path))
        for method, options in METHODS.items():
            try:
                result = workbench.render(scene, method, width=SIZE[0], height=SIZE[1], **options)
            except workbench.WorkbenchError as e:  # not applicable, or over the memory limit
                print(f"{path.stem}/{method}: {e}", flush=True)
                continue
            out[f"{path.stem}/{method}"] = np.asarray(result.image, np.float32)
            print(f"{path.stem}/{method}", flush=True)
    return out


def main(argv: list[str]) -> int:
    if argv not in (["record"], ["check"]):
        print("usage: kernel_images.py record|check", file=sys.stderr)
        return 2
    RESULTS.mkdir(parents=True, exist_ok=True)
    recorded = RESULTS / "kernel_images.npz"
    now = images()
    if argv == ["record"]:
        np.savez_compressed(recorded, **now)
        return 0
    before = dict(np.load(recorded))
    rows = {}
    for key in sorted(set(before) | set(now)):
        if key not in before or key not in now:
            rows[key] = None
            continue
        rows[key] = float(np.sqrt(np.mean((now[key].astype(np.float64) - before[key]) ** 2)))
    worst = max((v for v in rows.values() if v is not None), default=0.0)
    report = {"size": list(SIZE), "methods": METHODS, "limit": LIMIT, "worst_rmse": worst,
              "missing": sorted(k for k, v in rows.items() if v is None), "rmse": rows}
    (RESULTS / "kernel_images.json").write_text(json.dumps(report, indent=1) + "\n")
    print(json.dumps({"worst_rmse": worst, "missing": report["missing"]}))
    return 0 if worst <= LIMIT and not report["missing"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
