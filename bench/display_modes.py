"""Error and cost of every display mode against the 24-bit image, on bundled scenes.

Each scene is rendered once (``--method``, default phong), then shown through each mode
(workbench.core.display); the error against ``direct24`` is the workbench's usual metrics
(RMSE and PSNR on linear values, FLIP).  Times are warm (one untimed run first, which also
compiles the Floyd-Steinberg kernel).  Writes ``bench/results/display_modes.json``.

    .venv/bin/python bench/display_modes.py [--scenes whitted cornell] [--size 256x256]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import workbench  # noqa: E402
from workbench.compare.metrics import metrics  # noqa: E402
from workbench.core.display import apply_display_mode  # noqa: E402

DITHER_SUFFIXES = ("", "-bayer", "-fs")
MODES = (["direct24"] + [f"direct16-{b}{d}" for b in ("555", "565") for d in DITHER_SUFFIXES]
         + [f"indexed{n}-{p}{d}" for n in (2, 4, 16, 256) for p in ("mediancut", "kmeans")
            for d in DITHER_SUFFIXES])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=["whitted", "cornell"])
    ap.add_argument("--method", default="phong")
    ap.add_argument("--size", default="256x256")
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    out = {"method": args.method, "size": [w, h], "scenes": {}}
    for name in args.scenes:
        image = workbench.render(workbench.load_scene(name), args.method, width=w, height=h).image
        ref = apply_display_mode(image, "direct24")
        rows = {}
        for mode in MODES:
            apply_display_mode(image, mode)                  # warm-up (JIT, imports)
            t = time.perf_counter()
            shown = apply_display_mode(image, mode)
            dt = time.perf_counter() - t
            m = metrics(shown, ref)
            rows[mode] = {"rmse": round(m["rmse"], 6),
                          "psnr_db": None if m["psnr"] == float("inf") else round(m["psnr"], 2),
                          "flip": round(m["flip"], 4), "seconds": round(dt, 4)}
            print(f"{name:8s} {mode:26s} RMSE {m['rmse']:.5f}  PSNR {m['psnr']:6.2f} dB  "
                  f"FLIP {m['flip']:.4f}  {dt * 1e3:7.1f} ms")
        out["scenes"][name] = rows
    path = ROOT / "bench" / "results" / "display_modes.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=2) + "\n")
    print(f"-> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
