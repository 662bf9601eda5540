"""``workbench study SCENE --out DIR``: error against run time along each method's quality knob."""
from __future__ import annotations

import argparse

from .args import at_least_one, methods_list, size


def _sweep(text: str) -> tuple[str, tuple[str, list[str]]]:
    """``[METHOD:]OPTION=V1,V2,...`` -> (method or "", (option, values))."""
    key, eq, values = text.partition("=")
    method, _, option = key.rpartition(":")
    if not eq or not option.strip():
        raise argparse.ArgumentTypeError(f"expected [METHOD:]OPTION=V1,V2,..., got {text!r}")
    vals = [v.strip() for v in values.split(",") if v.strip()]
    if not vals:
        raise argparse.ArgumentTypeError(f"no values in {text!r}")
    return method.strip(), (option.strip(), vals)


def _fixed(text: str) -> tuple[str, str, str]:
    """``[METHOD:]OPTION=VALUE`` -> (method or "", option, value)."""
    key, eq, value = text.partition("=")
    method, _, option = key.rpartition(":")
    if not eq or not option.strip() or not value.strip():
        raise argparse.ArgumentTypeError(f"expected [METHOD:]OPTION=VALUE, got {text!r}")
    return method.strip(), option.strip(), value.strip()


def sweeps_of(items, methods: list[str]) -> dict[str, tuple[str, list[str]]]:
    """``{method: (option, values)}`` from ``--sweep`` items; one without a method applies to
    every studied method that has the option (at least one must)."""
    from ..core.errors import WorkbenchError
    from ..renderers.base import get_renderer
    out = {}
    for method, (option, values) in items:
        targets = [method] if method else [m for m in methods if option in get_renderer(m).options]
        if not targets:
            raise WorkbenchError(f"--sweep {option}=...: no studied method has an option {option!r}")
        for m in targets:
            out[m] = (option, values)
    return out


def fixed_options(items, methods: list[str]) -> dict[str, dict]:
    """``{method: {option: value}}`` from ``--set`` items: one with a method applies to it, one
    without to every studied method that has the option (at least one must)."""
    from ..core.errors import WorkbenchError
    from ..renderers.base import get_renderer
    out: dict[str, dict] = {}
    for method, option, value in items:
        targets = [method] if method else [m for m in methods if option in get_renderer(m).options]
        if not targets:
            raise WorkbenchError(f"--set {option}={value}: no studied method has an option {option!r}")
        for m in targets:
            out.setdefault(m, {})[option] = value
    return out


def add_parser(sub):
    p = sub.add_parser("study", help="sweep each method's quality knob: error against run time (CSV, JSON, plot)")
    p.add_argument("scene", help="scene file or bundled scene name")
    p.add_argument("--out", required=True, help="output folder (study.csv, study.json, study.png, study.html)")
    p.add_argument("--methods", type=methods_list, help="comma-separated methods (default: every registered one except mitsuba)")
    p.add_argument("--size", type=size, help="WIDTHxHEIGHT (default: 160 wide with --quick, else the camera's)")
    p.add_argument("--quick", action="store_true", help="small sweep: at most 4 knob values, 2 warm runs, 160 px wide")
    p.add_argument("--repeat", type=at_least_one, help="warm runs per point (default 2 quick, 5 otherwise)")
    p.add_argument("--reference", help="force the reference method (default: the documented rule)")
    p.add_argument("--sweep", type=_sweep, action="append", default=[], metavar="[METHOD:]OPTION=V1,V2,...",
                   help="sweep this option instead of the method's knob (repeatable; without METHOD: every "
                        "studied method that has it), e.g. radiosity:hemicube_resolution=16,32,64,128")
    p.add_argument("--set", type=_fixed, action="append", default=[], metavar="[METHOD:]OPTION=VALUE",
                   help="hold an option at every point (repeatable; without METHOD: every studied method "
                        "that has it), e.g. standins=off")
    p.add_argument("--jobs", type=int, default=1,
                   help="worker processes for the error evaluation, run after all timing (default 1)")
    p.add_argument("--cluster", metavar="ADDRESS",
                   help="run the points and the error evaluation on the workers of a Dask scheduler, e.g. "
                        "tcp://HOST:8786 (needs workbench[cluster] here and the same workbench version on "
                        "every worker; not with --jobs above 1; times are the workers'; docs/guide/cluster.md)")
    p.set_defaults(run=run)


def run(args) -> int:
    import sys
    from pathlib import Path

    from ..compare.executors import check_options
    from ..compare.study import study
    from ..core.output_paths import check_output_dir
    from ..scene.io import load_scene
    check_options(args.jobs, args.cluster)
    check_output_dir(args.out, "--out")
    scene = load_scene(args.scene)
    from ..renderers.base import check_methods, default_methods
    methods = list(args.methods) if args.methods else default_methods()
    check_methods(methods)
    res = study(scene, args.out, methods=args.methods, size=args.size, quick=args.quick, repeat=args.repeat,
                reference=args.reference, sweeps=sweeps_of(args.sweep, methods), jobs=args.jobs, progress=sys.stderr.isatty(),
                command=" ".join(["workbench"] + sys.argv[1:]), fixed=fixed_options(args.set, methods),
                cluster=args.cluster)
    ref = res["reference"]
    print(f"{scene.name} {res['size'][0]}x{res['size'][1]}: reference {ref['method']} {ref['options']}")
    for p in res["points"]:
        if p["status"] == "ok":
            matched = f"  vs matched {p['rmse_matched']:.4g}" if "rmse_matched" in p else ""
            print(f"  {p['method']:<10} {p['knob']}={p['value']!s:<6} {p['time_s']:9.4g} s  RMSE {p['rmse']:.4g}"
                  f"{matched}  FLIP {p['flip']:.4g}{'  *pareto' if p.get('pareto') else ''}")
        else:
            print(f"  {p['method']:<10} {p['knob']}={p['value']}: {p['status']}: {p['reason']}")
    print(f"study: {(Path(args.out) / 'study.png').resolve()}")
    failed = [p for p in res["points"] if p["status"] == "failed"]
    if failed:  # the study is written, but not whole: say so and exit 1 (as snapshot check)
        print(f"workbench: {len(failed)} of {len(res['points'])} study points failed (listed above)",
              file=sys.stderr)
        return 1
    return 0
