"""``workbench compare SCENE --out DIR``: every method side by side, timed, against a reference."""
from __future__ import annotations

from .args import at_least_one, methods_list, size


def add_parser(sub):
    p = sub.add_parser("compare", help="render a scene with every method; grid, heat maps, JSON and HTML report")
    p.add_argument("scene", help="scene file or bundled scene name")
    p.add_argument("--out", required=True, help="output folder (report.html, report.json, grid.png, ...)")
    p.add_argument("--methods", type=methods_list, help="comma-separated methods (default: every registered one except mitsuba)")
    p.add_argument("--size", type=size, help="WIDTHxHEIGHT (default: the scene camera's)")
    p.add_argument("--reference", help="force the reference method (default: the documented rule)")
    p.add_argument("--repeat", type=at_least_one, default=1, help="warm timed runs per method after the cold one, at least 1: the time reported is a warm run's (default 1)")
    p.set_defaults(run=run)


def run(args) -> int:
    import sys
    from pathlib import Path

    from ..compare.report import compare
    from ..core.output_paths import check_output_dir
    from ..scene.io import load_scene
    check_output_dir(args.out, "--out")
    scene = load_scene(args.scene)
    rep = compare(scene, args.out, methods=args.methods, size=args.size, reference=args.reference,
                  repeat=args.repeat, command=" ".join(["workbench"] + sys.argv[1:]))
    ref = rep["reference"]
    print(f"{scene.name}: reference {ref['method']} ({ref['time_s']:.3g} s, own error {ref['noise_rmse']:.2g}) "
          f"- {ref['reason']}")
    for e in rep["methods"]:
        if e["status"] == "ok":
            m = e["metrics"]
            print(f"  {e['method']:<10} {e['time_s']:8.3g} s  compile {e['compile_s']:6.3g} s  "
                  f"RMSE {m['rmse']:.4g}  PSNR {m['psnr']:.4g} dB  FLIP {m['flip']:.4g}  "
                  + (f"vs matched {e['matched']['reference']['method']}: RMSE {e['matched']['metrics']['rmse']:.4g}"
                     if "metrics" in e["matched"] else "no matched reference"))
        else:
            print(f"  {e['method']:<10} {e['status']}: {e['reason']}")
    print(f"report: {(Path(args.out) / 'report.html').resolve()}")
    return 0
