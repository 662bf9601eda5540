"""What every bench script shares (issue #30): the ``--smoke`` / ``--out`` / ``--docs`` /
``--from-json`` arguments, the machine and versions header, the outside anchors' presence, and
writing the result as JSON (``bench/results/NAME.json``) and as a Markdown page
(``docs/benchmarks/NAME.md``, NAME the script's stem).

A script declares its page once::

    PAGE = Page("zbuffer", "The CPU Z-buffer against its GL twin", what=..., command=..., tables=tables)

and in ``main``::

    args = PAGE.parse(ap, argv)     # adds the shared arguments; --from-json renders the page and exits
    ...                             # measure (tiny sizes with args.smoke)
    PAGE.write(args, result)        # args.out/NAME.json and args.docs/NAME.md

``--smoke`` runs the same code at tiny sizes and repeats (seconds on a warm numba cache) and
never writes into ``bench/results`` or ``docs/benchmarks``: its results go to ``--out`` (a new
temporary folder when not given), its page beside them.  ``--from-json [PATH]`` measures
nothing: it renders the page from a stored result (default ``bench/results/NAME.json``), which
is how the committed pages are made (``bench/_tables.py`` does it for every script).

Outside anchors (POV-Ray, Mitsuba 3, pyviewfactor, pyrender) may be absent: :func:`anchor_version`
answers None, the script says so and skips that column.  ``BENCH_HIDE_ANCHORS=povray,mitsuba``
(or ``all``) makes present ones count as absent, so that the fallback can be tested.
"""
from __future__ import annotations

import argparse
import datetime
import functools
import importlib.metadata
import importlib.util
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
DOCS = ROOT / "docs" / "benchmarks"
HIDE_ENV = "BENCH_HIDE_ANCHORS"

ANCHORS = {"povray": "POV-Ray 3.7 (the `povray` program)",
           "mitsuba": "Mitsuba 3 (the Python package `mitsuba`)",
           "pyviewfactor": "pyviewfactor (exact view factors)",
           "pyrender": "pyrender (the package `pyrender2`)",
           "embreex": "Embree (the package `embreex`)"}
"""The outside programs the scripts compare against, by the name :func:`anchor_version` takes."""
_DISTRIBUTIONS = {"mitsuba": ("mitsuba", "mitsuba"), "pyviewfactor": ("pyviewfactor", "pyviewfactor"),
                  "pyrender": ("pyrender2", "pyrender"), "embreex": ("embreex", "embreex")}


# --------------------------------------------------------------------------- machine, versions
def first_paragraph(doc: str) -> str:
    """A docstring's first paragraph as one line (the page's description)."""
    return " ".join(doc.strip().split("\n\n")[0].split())


def _version(dist: str) -> str | None:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return None


def hidden() -> set[str]:
    names = {x.strip() for x in os.environ.get(HIDE_ENV, "").split(",") if x.strip()}
    return set(ANCHORS) if "all" in names else names


@functools.lru_cache(maxsize=None)
def _anchor_version(name: str) -> str | None:
    if name == "povray":
        exe = shutil.which("povray")
        if exe is None:
            return None
        try:
            p = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30)
        except (OSError, subprocess.SubprocessError):
            return None
        m = re.search(r"POV-Ray\s+(\S+)", p.stdout + p.stderr)
        return m.group(1) if m else "unknown version"
    dist, module = _DISTRIBUTIONS[name]
    v = _version(dist)
    if v is None and importlib.util.find_spec(module) is not None:
        v = "unknown version"
    return v


def anchor_version(name: str) -> str | None:
    """The version of outside anchor ``name`` (a key of :data:`ANCHORS`), None when it is absent
    (or hidden by ``BENCH_HIDE_ANCHORS``)."""
    return None if name in hidden() else _anchor_version(name)


def skip_note(name: str) -> str:
    return f"{ANCHORS[name]} not found on this machine: its column is skipped"


def git_commit() -> str:
    try:
        p = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                           timeout=30)
        return p.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def load_average() -> list[float]:
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return []


def now_utc() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def environment(anchors=()) -> dict:
    """The facts needed to read a run's numbers: machine, versions, outside anchors, date, load."""
    from workbench.compare.outputs import cpu_model
    return {"date": now_utc(), "cpu_model": cpu_model(), "cores": os.cpu_count(),
            "platform": platform.platform(), "python": platform.python_version(),
            "numpy": _version("numpy"), "numba": _version("numba"), "git_commit": git_commit(),
            "anchors": {a: anchor_version(a) for a in anchors}, "load_average_start": load_average()}


# --------------------------------------------------------------------------- Markdown helpers
def fmt(v, digits: int = 3) -> str:
    """A table cell: numbers to ``digits`` significant digits, None as a dash."""
    if v is None:
        return "–"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v != v:
            return "nan"
        if v == 0:
            return "0"
        if abs(v) >= 10 ** digits:
            return f"{v:.0f}"
        if abs(v) < 10 ** -(digits + 1):
            return f"{v:.{digits - 1}e}"
        return f"{v:.{digits}g}"
    return str(v).replace("|", "\\|").replace("\n", " ")


def ratio(a, b) -> str:
    """``a / b`` as a table cell (a dash when either is missing or ``b`` is 0)."""
    try:
        return f"{a / b:.2f}" if a is not None and b else "–"
    except TypeError:
        return "–"


def table(header: list[str], rows: list[list]) -> str:
    """A Markdown table; cells through :func:`fmt` unless already strings."""
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        out.append("| " + " | ".join(c if isinstance(c, str) else fmt(c) for c in r) + " |")
    return "\n".join(out) + "\n"


def kv_table(pairs, header=("quantity", "value")) -> str:
    return table(list(header), [[k, v] for k, v in pairs])


def get(d, *keys, default=None):
    """``d[k0][k1]...`` or ``default`` when a level is missing."""
    for k in keys:
        if isinstance(d, dict) and k in d:
            d = d[k]
        elif isinstance(d, list) and isinstance(k, int) and -len(d) <= k < len(d):
            d = d[k]
        else:
            return default
    return d


# --------------------------------------------------------------------------- stored results
def _git_stored(path: Path) -> str | None:
    try:
        p = subprocess.run(["git", "log", "-1", "--format=%h %cs", "--", str(path)], cwd=ROOT,
                           capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return None
    return p.stdout.strip() or None


def _find_keys(d, suffix: str, found: dict, depth: int = 0) -> None:
    if depth > 6:
        return
    if isinstance(d, dict):
        for k, v in d.items():
            if isinstance(k, str) and k.endswith(suffix) and isinstance(v, (str, int, float)):
                found.setdefault(k, v)
            else:
                _find_keys(v, suffix, found, depth + 1)
    elif isinstance(d, list):
        for v in d[:3]:
            _find_keys(v, suffix, found, depth + 1)


def recorded_environment(res: dict) -> dict:
    """What an older result (written before the ``environment`` record) says of its run."""
    nr = "not recorded"
    m = res.get("machine")
    env = {"python": res.get("python") or get(m, "python") or nr, "numpy": get(m, "numpy") or nr,
           "numba": res.get("numba") or nr, "anchors": {}}
    bits = []
    if isinstance(m, dict):
        bits = [get(m, "processor"), f"{get(m, 'cpu_count')} CPUs" if get(m, "cpu_count") else None,
                get(m, "platform")]
    else:
        bits = [m, res.get("processor") or None,
                f"{res['cpu_count']} CPUs" if res.get("cpu_count") else None]
    env["machine"] = ", ".join(str(b) for b in bits if b) or nr
    date = res.get("date")
    if date is None:
        dates = {}
        _find_keys(res, "date", dates)
        date = next(iter(dates.values()), None)
    env["date"] = date
    loads = {k: v for k, v in res.items() if "load" in k and isinstance(v, (int, float, list, dict))}
    env["load"] = "; ".join(f"{k} {_rounded(v)}" for k, v in loads.items()) or nr
    versions = {}
    _find_keys(res, "_version", versions)
    env["versions_in_result"] = versions
    return env


def _rounded(v):
    if isinstance(v, float):
        return round(v, 2)
    if isinstance(v, list):
        return [_rounded(x) for x in v]
    if isinstance(v, dict):
        return {k: _rounded(x) for k, x in v.items()}
    return v


# --------------------------------------------------------------------------- the page
@dataclass
class Page:
    """One bench script's result page (see the module docstring)."""

    name: str
    title: str
    what: str
    command: str
    tables: Callable[[dict], str]
    anchors: tuple = ()
    variants: bool = False
    """Also render ``NAME_*.json`` found beside the result (runs of the script with other options)."""
    smoke_note: str = ""
    """What ``--smoke`` shrinks (shown in --help)."""

    # ------------------------------------------------------------------ arguments
    def add_arguments(self, ap: argparse.ArgumentParser) -> None:
        g = ap.add_argument_group("shared bench options (bench/_common.py)")
        g.add_argument("--smoke", action="store_true",
                       help="tiny sizes and repeats, seconds on a warm numba cache: checks that the script "
                            "runs; writes only to --out (a new temporary folder by default)"
                            + (f"; {self.smoke_note}" if self.smoke_note else ""))
        g.add_argument("--out", type=Path, default=None,
                       help="folder of the JSON result (default bench/results; with --smoke a temporary folder)")
        g.add_argument("--docs", type=Path, default=None,
                       help="folder of the Markdown page NAME.md (default docs/benchmarks when --out is "
                            "bench/results, else the --out folder)")
        g.add_argument("--from-json", nargs="?", const="", default=None, metavar="PATH",
                       help="measure nothing: render the page from a stored result "
                            f"(default bench/results/{self.name}.json) into --docs")

    def parse(self, ap: argparse.ArgumentParser, argv=None) -> argparse.Namespace:
        """Parse with the shared options; with ``--from-json`` render the page and exit."""
        self.add_arguments(ap)
        args = ap.parse_args(argv)
        self.argv = list(sys.argv[1:] if argv is None else argv)
        if args.from_json is not None:
            src = Path(args.from_json) if args.from_json else RESULTS / f"{self.name}.json"
            path = self.render_stored(src, args.docs or DOCS)
            print(f"-> {path}")
            sys.exit(0)
        if args.out is None:
            args.out = Path(tempfile.mkdtemp(prefix=f"bench-smoke-{self.name}-")) if args.smoke else RESULTS
        args.out = Path(args.out).resolve()
        if args.docs is None:
            args.docs = DOCS if args.out == RESULTS.resolve() else args.out
        if args.smoke and args.out == RESULTS.resolve():
            ap.error("--smoke never writes into bench/results: give another --out")
        args.out.mkdir(parents=True, exist_ok=True)
        if args.smoke:
            # tiny references stay out of the user's reference cache
            os.environ.setdefault("WORKBENCH_REFERENCE_CACHE", str(args.out / "reference-cache"))
        args.env = environment(self.anchors)
        for a, v in args.env["anchors"].items():
            if v is None:
                print(f"{self.name}: {skip_note(a)}", flush=True)
        return args

    def anchor(self, args, name: str) -> str | None:
        """The anchor's version as recorded at the start of this run (None: absent)."""
        return args.env["anchors"].get(name)

    # ------------------------------------------------------------------ writing
    def write(self, args, res: dict, stem: str | None = None) -> dict:
        """``res`` (plus the run's environment) to ``args.out/STEM.json`` and the page to
        ``args.docs/NAME.md``."""
        env = dict(args.env, load_average_end=load_average(), finished=now_utc(),
                   command=" ".join(["python", f"bench/{self.name}.py", *self.argv]))
        res = dict(res, environment=env, smoke=bool(args.smoke))
        path = Path(args.out) / f"{stem or self.name}.json"
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(res, indent=1, default=_plain) + "\n")
        tmp.replace(path)
        Path(args.docs).mkdir(parents=True, exist_ok=True)
        md = Path(args.docs) / f"{self.name}.md"
        md.write_text(self.page(json.loads(path.read_text()), path, stored=False))
        print(f"-> {path}\n-> {md}", flush=True)
        return res

    def render_stored(self, src: Path, docs: Path) -> Path:
        res = json.loads(Path(src).read_text())
        Path(docs).mkdir(parents=True, exist_ok=True)
        md = Path(docs) / f"{self.name}.md"
        md.write_text(self.page(res, Path(src), stored=True))
        return md

    # ------------------------------------------------------------------ rendering
    def page(self, res: dict, path: Path, stored: bool) -> str:
        lines = [f"# {self.title}", "", self.what, "",
                 f"Full run: `{self.command}` (writes `bench/results/{self.name}.json` and this page); "
                 f"`--smoke` runs the same code at tiny sizes in seconds and writes elsewhere "
                 f"(`tests/project/test_bench_smoke.py`); `python bench/{self.name}.py --from-json` renders this page "
                 f"again from the stored JSON.", ""]
        by = _git_stored(path) if stored else None
        if stored:
            rel = _relative(path)
            lines += [f"This page was rendered from `{rel}`, the stored result of the last measured run"
                      + (f" (committed in {by})" if by else "") + ": nothing was measured again for it. "
                      "Facts that run did not record are marked \"not recorded\".", ""]
        if res.get("smoke"):
            lines += ["**Smoke run**: tiny sizes and repeats, to check that the script works; its numbers "
                      "are not measurements.", ""]
        lines += [self._header(res, by), ""]
        body = self._body(res, path)
        lines.append(body)
        return "\n".join(lines).rstrip() + "\n"

    def _body(self, res: dict, path: Path) -> str:
        parts = [_safe_tables(self.tables, res)]
        if self.variants and path is not None:
            for other in sorted(Path(path).parent.glob(f"{self.name}_*.json")):
                try:
                    data = json.loads(other.read_text())
                except (OSError, ValueError):
                    continue
                body = _safe_tables(self.tables, data).replace("\n## ", "\n### ")
                body = body[1:] if body.startswith("## ") else body
                parts.append(f"## Variant `{other.stem}` (`{_relative(other)}`)\n\n" + body)
        return "\n".join(parts)

    def _header(self, res: dict, stored_by: str | None = None) -> str:
        env = res.get("environment")
        rows = []
        if env:
            rows.append(("machine", f"{env.get('cpu_model')}, {env.get('cores')} cores ({env.get('platform')})"))
            rows.append(("Python / numpy / numba", f"{env.get('python')} / {env.get('numpy')} / {env.get('numba')}"))
            for a in self.anchors:
                v = get(env, "anchors", a)
                rows.append((ANCHORS[a], v if v else "absent on this machine: its column is skipped"))
            rows.append(("date", f"{env.get('date')} to {env.get('finished')}"))
            rows.append(("load average (1, 5, 15 min)", f"{env.get('load_average_start')} at the start, "
                                                          f"{env.get('load_average_end')} at the end"))
            rows.append(("code", f"commit {env.get('git_commit')}"))
            rows.append(("command of this run", f"`{env.get('command')}`"))
        else:
            env = recorded_environment(res)
            rows.append(("machine (as recorded)", env["machine"]))
            rows.append(("Python / numpy / numba", f"{env['python']} / {env['numpy']} / {env['numba']}"))
            for a in self.anchors:
                found = {k: v for k, v in env["versions_in_result"].items() if a in k.lower()}
                rows.append((ANCHORS[a], ", ".join(str(v) for v in found.values()) or "used; version not recorded"))
            committed = f"not recorded; the result was committed on {stored_by.split()[-1]}" if stored_by else "not recorded"
            rows.append(("date", env["date"] or committed))
            rows.append(("load average", env["load"]))
        return kv_table(rows, ("run", ""))


def _safe_tables(fn, res) -> str:
    try:
        return fn(res)
    except Exception as e:  # noqa: BLE001 -- an old result lacking a field still gets a page
        return (f"(The tables could not be rendered from this result: {type(e).__name__}: {e}. "
                "Its JSON holds the numbers.)\n")


def _relative(p: Path) -> str:
    try:
        return str(Path(p).resolve().relative_to(ROOT))
    except ValueError:
        return str(p)


def _plain(x):
    """JSON fallback: numpy scalars and arrays, paths."""
    if hasattr(x, "tolist"):
        return x.tolist()
    if isinstance(x, Path):
        return str(x)
    return str(x)
