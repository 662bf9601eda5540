"""``workbench`` command line.  Each subcommand lives in its own ``cmd_*`` module with
``add_parser(subparsers)`` and ``run(args) -> int``; heavy modules load inside ``run`` only, so
``workbench --help`` answers at once.

Every user error (bad scene, bad argument, unknown method) is printed as one line
``workbench: error: ...`` with exit status 2; never a traceback.

Run as the ``workbench`` program (``argv`` not given), the process ends with ``os._exit`` once
the command is done, its output flushed and the ``atexit`` handlers run: the interpreter's
teardown (collecting numba's and numpy's objects, joining thread pools) would add about 0.2 s
to every command and does nothing a finished command needs.
"""
from __future__ import annotations

import argparse
import atexit
import importlib
import os
import sys

COMMANDS = ["cmd_scenes", "cmd_info", "cmd_methods", "cmd_render", "cmd_colour", "cmd_compare", "cmd_study", "cmd_stress", "cmd_snapshot", "cmd_ui"]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="workbench",
        description="Rendering workbench: classic image-synthesis methods side by side on one "
                    "scene and camera, with run times and errors.")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"workbench.app.{name}").add_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    if argv is not None:
        return _run(argv)
    code = _run(None)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # closed by a broken pipe
            pass
    atexit._run_exitfuncs()
    os._exit(code)


def _run(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    from ..core.errors import WorkbenchError
    try:
        return int(args.run(args) or 0)
    except WorkbenchError as e:
        print(f"workbench: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into head & co.
        sys.stderr.close()
        return 0
    except KeyboardInterrupt:
        print("workbench: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
