"""Error and cost of every display mode against the 24-bit image, on bundled scenes.

Each scene is rendered once (``--method``, default phong), then shown through each mode
(workbench.core.display); the error against ``direct24`` is the workbench's usual metrics
(RMSE and PSNR on linear values, FLIP).  Times are warm (one untimed run first, which also
compiles the Floyd-Steinberg kernel).  Writes ``bench/results/display_modes.json`` and
``docs/benchmarks/display_modes.md``.

    .venv/bin/python bench/display_modes.py [--scenes whitted cornell] [--size 256x256]

``--smoke``: ``whitted`` alone at 32 x 32, every mode.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import workbench  # noqa: E402
from workbench.compare.metrics import metrics  # noqa: E402
from workbench.core.display import apply_display_mode  # noqa: E402
from _common import Page, first_paragraph, table  # noqa: E402

DITHER_SUFFIXES = ("", "-bayer", "-fs")
MODES = (["direct24"] + [f"direct16-{b}{d}" for b in ("555", "565") for d in DITHER_SUFFIXES]
         + [f"indexed{n}-{p}{d}" for n in (2, 4, 16, 256) for p in ("mediancut", "kmeans")
            for d in DITHER_SUFFIXES])


def tables(res: dict) -> str:
    w, h = res["size"]
    out = [f"Each scene rendered once with `{res['method']}` at {w} x {h}, then shown through every mode; error "
           "against the 24-bit image (`direct24`, the anchor: an error of 0).  Warm times.", ""]
    for name, rows in res["scenes"].items():
        out += [f"## {name}", "", table(["mode", "RMSE", "PSNR (dB)", "FLIP", "time (ms)"],
                                        [[m, r["rmse"], r["psnr_db"], r["flip"], 1e3 * r["seconds"]]
                                         for m, r in rows.items()])]
    return "\n".join(out)


PAGE = Page("display_modes", "Display modes: error and cost against the 24-bit image", first_paragraph(__doc__),
            "python bench/display_modes.py", tables, smoke_note="whitted alone at 32 x 32")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=["whitted", "cornell"])
    ap.add_argument("--method", default="phong")
    ap.add_argument("--size", default="256x256")
    args = PAGE.parse(ap, argv)
    if args.smoke:
        args.scenes, args.size = ["whitted"], "32x32"
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
    PAGE.write(args, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
