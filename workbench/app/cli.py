"""``workbench`` command line.  Each subcommand lives in its own ``cmd_*`` module with
``add_parser(subparsers)`` and ``run(args) -> int``; heavy modules load inside ``run`` only, so
``workbench --help`` answers at once.

Every user error (bad scene, bad argument, unknown method) is printed as one line
``workbench: error: ...`` with exit status 2; never a traceback.

Run as the ``workbench`` program (``argv`` not given), the process ends with ``os._exit`` once
the command is done, its output flushed and the ``atexit`` handlers run: the interpreter's
teardown (collecting numba's and numpy's objects, joining thread pools) would add about 0.2 s
to every command and does nothing a finished command needs.

The program also holds Python's cyclic garbage collector off while it starts: the modules it
imports (numpy, numba, the command's own; a command's ``prepare(args)``, when it sets one,
imports those it will use, e.g. ``render`` its method's renderer) make a few hundred thousand
objects that live until the process ends, and each time they have grown by a quarter the
collector's full pass scans them all again (CPython's ``long_lived_pending >
long_lived_total / 4`` rule): about 0.1 s of CPU in a warm ``workbench render``.  Once started,
what exists is frozen (``gc.freeze``: never scanned again) and the collector runs as usual for
the command itself.
"""
from __future__ import annotations

import argparse
import atexit
import gc
import importlib
import os
import warnings
import sys

from ..core.numba_start import load_cache_hits_without_registries, skip_blas_probe

COMMANDS = ["cmd_scenes", "cmd_info", "cmd_methods", "cmd_render", "cmd_colour", "cmd_compare", "cmd_study", "cmd_stress", "cmd_snapshot", "cmd_ui"]


class UsageError(Exception):
    """A command line argparse refuses; its message is printed as one line by :func:`_run`."""


class Parser(argparse.ArgumentParser):
    """argparse, with its errors raised as :class:`UsageError` (one line and status 2 from
    :func:`_run`, like every other user error) instead of a usage block printed and
    ``sys.exit`` called inside the parser.  Sub-command parsers are of this class too
    (``add_subparsers`` creates parsers of the parent's class)."""

    def error(self, message: str):
        sub = self.prog.split(" ", 1)[1] if " " in self.prog else ""
        raise UsageError(f"{sub}: {message}" if sub else message)


def build_parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="workbench",
        description="Rendering workbench: classic image-synthesis methods side by side on one "
                    "scene and camera, with run times and errors.")
    p.add_argument("--version", action=_Version, help="print the version and exit")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"workbench.app.{name}").add_parser(sub)
    for command in _leaf_parsers(sub):
        command.add_argument("--max-memory", metavar="SIZE", default=None,
                             help="memory limit of each render, e.g. 8G or 512M (sets "
                                  "WORKBENCH_MAX_MEMORY for this command; default: that variable, "
                                  "else half the physical memory)")
    return p


class _Version(argparse.Action):
    """``--version``: print ``workbench VERSION`` and exit, the version looked up only then."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from .. import __version__
        print(f"workbench {__version__}")
        parser.exit()


def _leaf_parsers(sub) -> list[argparse.ArgumentParser]:
    """The parsers that take a command's options: each command's, or its subcommands' when it
    has some (``colour wheel``, ``snapshot record``); aliases share a parser, listed once."""
    leaves = {}
    for command in sub.choices.values():
        nested = [a for a in command._actions if isinstance(a, argparse._SubParsersAction)]
        for parser in ([c for n in nested for c in n.choices.values()] if nested else [command]):
            leaves[id(parser)] = parser
    return list(leaves.values())


def main(argv: list[str] | None = None) -> int:
    if argv is not None:
        return _run(argv)
    gc.disable()  # until the command has started: see the module's docstring
    # the program only: a library user's process keeps numba's own start-up
    skip_blas_probe()
    load_cache_hits_without_registries()
    code = _run(None)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # closed by a broken pipe
            pass
    atexit._run_exitfuncs()
    os._exit(code)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A :class:`SceneWarning` as one ``workbench: warning:`` line; others as Python shows them."""
    from ..core.errors import SceneWarning
    if issubclass(category, SceneWarning):
        print(f"workbench: warning: {message}", file=sys.stderr)
    else:
        _PYTHON_SHOWWARNING(message, category, filename, lineno, file, line)


_PYTHON_SHOWWARNING = warnings.showwarning


def _run(argv: list[str] | None) -> int:
    from ..core.errors import WorkbenchError
    warnings.showwarning = _show_warning
    try:
        from .args import value_after_option
        parser = build_parser()
        args, extra = parser.parse_known_args(value_after_option(sys.argv[1:] if argv is None else list(argv)))
        trailing = getattr(args, "trailing_positionals", None)
        if trailing:                                # `snapshot record --dir D SCENE`
            getattr(args, trailing).extend(w for w in extra if not w.startswith("-"))
            extra = [w for w in extra if w.startswith("-")]
        if extra:
            parser.error(f"unrecognized arguments: {' '.join(extra)}")
        if getattr(args, "max_memory", None) is not None:  # one limit for this process and its children
            from ..core.memory import ENV, parse_size
            os.environ[ENV] = str(parse_size(args.max_memory, "--max-memory"))
        prepare = getattr(args, "prepare", None)
        if prepare is not None:
            prepare(args)
        if argv is None:                            # the program: its start-up is over
            gc.freeze()
            gc.enable()
        return int(args.run(args) or 0)
    except (UsageError, WorkbenchError) as e:
        return _error(str(e))
    except BrokenPipeError:  # output piped into head & co.
        sys.stderr.close()
        return 0
    except OSError as e:          # a file that vanished or a full disk, after the checks
        return _error(f"{str(e.filename) + ': ' if e.filename else ''}{e.strerror or e}")
    except KeyboardInterrupt:
        print("workbench: interrupted", file=sys.stderr)
        return 130


def _error(message: str) -> int:
    """Print one line ``workbench: error: ...`` (line breaks folded) and return status 2."""
    print("workbench: error: " + " ".join(message.split()), file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
