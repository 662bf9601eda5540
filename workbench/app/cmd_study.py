"""``workbench study SCENE --out DIR``: error against run time along each method's quality knob."""
from __future__ import annotations

import argparse

from .args import methods_list, size


def _sweep(text: str) -> tuple[str, tuple[str, list[str]]]:
    try:
        method, rest = text.split(":", 1)
        option, values = rest.split("=", 1)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected METHOD:OPTION=V1,V2,..., got {text!r}") from None
    vals = [v.strip() for v in values.split(",") if v.strip()]
    if not vals:
        raise argparse.ArgumentTypeError(f"no values in {text!r}")
    return method.strip(), (option.strip(), vals)


def add_parser(sub):
    p = sub.add_parser("study", help="sweep each method's quality knob: error against run time (CSV, JSON, plot)")
    p.add_argument("scene", help="scene file or bundled scene name")
    p.add_argument("--out", required=True, help="output folder (study.csv, study.json, study.png, study.html)")
    p.add_argument("--methods", type=methods_list, help="comma-separated methods (default: every registered one except mitsuba)")
    p.add_argument("--size", type=size, help="WIDTHxHEIGHT (default: 160 wide with --quick, else the camera's)")
    p.add_argument("--quick", action="store_true", help="small sweep: at most 4 knob values, 2 warm runs, 160 px wide")
    p.add_argument("--repeat", type=int, help="warm runs per point (default 2 quick, 5 otherwise)")
    p.add_argument("--reference", help="force the reference method (default: the documented rule)")
    p.add_argument("--sweep", type=_sweep, action="append", default=[], metavar="METHOD:OPTION=V1,V2,...",
                   help="sweep this option instead of the method's knob (repeatable), e.g. "
                        "radiosity:hemicube_resolution=16,32,64,128")
    p.add_argument("--jobs", type=int, default=1,
                   help="worker processes for the error evaluation, run after all timing (default 1)")
    p.set_defaults(run=run)


def run(args) -> int:
    import sys
    from pathlib import Path

    from ..compare.study import study
    from ..core.errors import WorkbenchError
    from ..core.output_paths import check_output_dir
    from ..scene.io import load_scene
    if args.jobs < 1:
        raise WorkbenchError(f"--jobs must be >= 1, got {args.jobs}")
    check_output_dir(args.out, "--out")
    scene = load_scene(args.scene)
    res = study(scene, args.out, methods=args.methods, size=args.size, quick=args.quick, repeat=args.repeat,
                reference=args.reference, sweeps=dict(args.sweep), jobs=args.jobs, progress=sys.stderr.isatty(),
                command=" ".join(["workbench"] + sys.argv[1:]))
    ref = res["reference"]
    print(f"{scene.name} {res['size'][0]}x{res['size'][1]}: reference {ref['method']} {ref['options']}")
    for p in res["points"]:
        if p["status"] == "ok":
            print(f"  {p['method']:<10} {p['knob']}={p['value']!s:<6} {p['time_s']:9.4g} s  RMSE {p['rmse']:.4g}"
                  f"  FLIP {p['flip']:.4g}{'  *pareto' if p.get('pareto') else ''}")
        else:
            print(f"  {p['method']:<10} {p['knob']}={p['value']}: {p['status']}: {p['reason']}")
    print(f"study: {(Path(args.out) / 'study.png').resolve()}")
    return 0
