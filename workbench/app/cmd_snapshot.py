"""``workbench snapshot record|check SCENE... --methods a,b --dir DIR``: snapshot tests of
images (:mod:`workbench.compare.snapshot`).

``record`` renders and stores each scene x method; ``check`` renders again and compares with
the stored image under ``--tolerance`` in ``--metric`` (exit 0 when every one passes, 1 when one
fails or is missing: the difference image and heat map are written next to the stored image),
``--update`` rewriting the failing and missing ones.  Bad arguments: one line, exit 2.
"""
from __future__ import annotations

import argparse

ACTIONS = ("record", "check")


def add_parser(sub):
    p = sub.add_parser("snapshot", help="record or check stored images of scenes x methods (snapshot tests)")
    p.add_argument("action", metavar="record|check", help="record: store the images; check: compare with them")
    p.add_argument("scenes", nargs="*", metavar="SCENE", help="scene files or bundled scene names")
    # scenes may also follow the options (argparse gives a "*" positional the empty list when
    # options come first): the CLI appends the leftover words to this list
    p.set_defaults(trailing_positionals="scenes")
    p.add_argument("--methods", default="", help="comma-separated methods (registered, or glsl:FILE)")
    p.add_argument("--dir", default="", help="folder of the stored snapshots")
    p.add_argument("--size", default="", help="WIDTHxHEIGHT (record: default the scene camera's; "
                                              "check: default the stored image's)")
    p.add_argument("--metric", default="rmse", help="rmse (default) or flip")
    p.add_argument("--tolerance", default=None, help="largest accepted metric value (default: rmse 0.005, flip 0.02)")
    p.add_argument("--update", action="store_true", help="check: rewrite the snapshots that fail or are missing")
    p.set_defaults(run=run)


def _record_command(scene: str, method: str, directory: str, size) -> str:
    import shlex
    words = ["workbench", "snapshot", "record", scene, "--methods", method, "--dir", directory]
    if size:
        words += ["--size", f"{size[0]}x{size[1]}"]
    return " ".join(shlex.quote(w) for w in words)


def run(args) -> int:
    from ..core.errors import WorkbenchError
    from .args import methods_list, size as parse_size
    if args.action not in ACTIONS:
        raise WorkbenchError(f"snapshot: action must be record or check, got {args.action!r}")
    if not args.scenes:
        raise WorkbenchError("snapshot: name at least one SCENE")
    methods = methods_list(args.methods)
    if not methods:
        raise WorkbenchError("snapshot: --methods needs at least one method")
    if not args.dir:
        raise WorkbenchError("snapshot: --dir is required (the folder of the stored snapshots)")
    from pathlib import Path

    from ..core.output_paths import check_output_dir
    if args.action == "record" or args.update:   # it will write: writable, before any render
        check_output_dir(args.dir, "--dir")
    elif Path(args.dir).exists() and not Path(args.dir).is_dir():
        raise WorkbenchError(f"--dir: {args.dir} is not a folder")
    try:
        size = parse_size(args.size) if args.size else None
    except argparse.ArgumentTypeError as e:
        raise WorkbenchError(f"snapshot: --size: {e}") from None
    if args.action == "record" and (args.update or args.tolerance is not None or args.metric != "rmse"):
        raise WorkbenchError("snapshot record: --metric, --tolerance and --update belong to check")
    from ..compare.snapshot import check, check_settings, record
    from ..renderers.base import check_methods
    from ..scene.io import load_scene
    tolerance = check_settings(args.metric, args.tolerance)
    check_methods(methods)
    scenes = [(s, load_scene(s)) for s in args.scenes]  # every scene loads before any render
    failed = 0
    for arg, scene in scenes:
        for m in methods:
            if args.action == "record":
                out = record(scene, m, args.dir, size=size)
            else:
                out = check(scene, m, args.dir, size=size, metric=args.metric, tolerance=tolerance,
                            update=args.update, record_hint=_record_command(arg, m, args.dir, size))
            failed += not out.ok
            print(("ok     " if out.ok else "FAILED ") + out.message)
    if failed:
        print(f"{failed} snapshot(s) failed")
    return 1 if failed else 0
