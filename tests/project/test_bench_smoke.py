"""Every bench script runs (issue #30: "every bench script has a smoke mode that a test runs, so
none can break unseen"): ``python bench/NAME.py --smoke --out TMP`` as a user runs it, from the
repository root, exits 0, writes ``TMP/NAME.json`` (parses; marked as a smoke run, with its
machine and versions) and the page ``TMP/NAME.md`` (its tables rendered), and changes nothing
under ``bench/results`` or ``docs/``.  The scripts with an outside anchor run once more with
every anchor hidden (``BENCH_HIDE_ANCHORS=all``): they say so and skip its column.  And the pages
of the stored results render (``bench/_tables.py``).

Smoke sizes are tiny, so on a warm numba cache each script takes seconds (its imports, a GL
context, a child process or two); the first run on a cold cache compiles the kernels each needs.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench"
SCRIPTS = sorted(p.stem for p in BENCH.glob("*.py") if not p.name.startswith("_"))
ANCHORED = [n for n in SCRIPTS if "anchors=(" in (BENCH / f"{n}.py").read_text()]
"""Scripts comparing against an outside program (POV-Ray, Mitsuba 3, pyviewfactor, pyrender)."""
NEEDS_XVFB = {"ui_fps", "ui_drag_profile"}
"""Scripts that open the UI window on a private Xvfb display (they start it themselves)."""
SLOW: dict[str, str] = {
    "wheel_install": "builds and installs the wheel (pip), then starts the installed commands: ~30 s",
    "ui_fps": "the window's fps script counts frames for 10 s, fixed in its session (tests/app/ui/sessions.py)",
    "accel": "compiles a past revision's BVH builder beside today's: about 15 min on an empty numba cache",
    "kinds_exporters": "every kind through the POV-Ray and Mitsuba exporters: about 8 min on an empty cache",
    "raytrace_profile": "compiles its own profiling kernels for every kind: about 7 min on an empty cache",
}
"""Smoke runs too long for the default test run (``-m slow`` runs them), and why."""
WATCHED = (ROOT / "bench" / "results", ROOT / "docs")


def snapshot() -> dict:
    """Size and modification time of every file under ``bench/results`` and ``docs``."""
    out = {}
    for d in WATCHED:
        for p in d.rglob("*"):
            if p.is_file():
                st = p.stat()
                out[str(p.relative_to(ROOT))] = (st.st_size, st.st_mtime_ns)
    return out


_HIDE = "BENCH_HIDE_ANCHORS"


def run(args: list[str], extra_env: dict | None = None, timeout: float = 1500) -> subprocess.CompletedProcess:
    """``python ARGS`` from the repository root, the checkout first on the import path."""
    path = os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    env = {**os.environ, "PYTHONPATH": path}
    env.pop(_HIDE, None)
    env.update(extra_env or {})
    return subprocess.run([sys.executable, *args], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=timeout)


def _tail(p: subprocess.CompletedProcess) -> str:
    return f"exit {p.returncode}\n--- stdout\n{p.stdout[-3000:]}\n--- stderr\n{p.stderr[-5000:]}"


def check_outputs(name: str, out: Path) -> tuple[dict, str]:
    js = out / f"{name}.json"
    md = out / f"{name}.md"
    assert js.is_file() and js.stat().st_size > 0, f"{js} not written"
    assert md.is_file() and md.stat().st_size > 0, f"{md} not written"
    res = json.loads(js.read_text())
    assert res["smoke"] is True
    env = res["environment"]
    assert env["cores"] and env["cpu_model"] and env["python"] and env["numpy"] and env["numba"]
    page = md.read_text()
    assert page.startswith("# "), page[:200]
    assert "Smoke run" in page and env["python"] in page
    assert "could not be rendered" not in page, page
    assert "|---" in page  # at least one table
    return res, page


def _param(name: str):
    marks = [pytest.mark.slow] if name in SLOW else []
    return pytest.param(name, marks=marks, id=name)


@pytest.mark.timeout(1800)
@pytest.mark.parametrize("name", [_param(n) for n in SCRIPTS])
def test_smoke(name, tmp_path):
    if name in NEEDS_XVFB and shutil.which("Xvfb") is None:
        pytest.skip("Xvfb not installed")
    before = snapshot()
    t0 = time.perf_counter()
    p = run([f"bench/{name}.py", "--smoke", "--out", str(tmp_path)])
    took = time.perf_counter() - t0
    assert p.returncode == 0, _tail(p)
    check_outputs(name, tmp_path)
    assert snapshot() == before, "the smoke run changed bench/results or docs"
    print(f"{name}: smoke run {took:.1f} s")


@pytest.mark.timeout(1800)
@pytest.mark.parametrize("name", [_param(n) for n in ANCHORED])
def test_smoke_without_anchors(name, tmp_path):
    """With every outside anchor hidden the script says so, skips its column and still writes
    its result and page."""
    before = snapshot()
    p = run([f"bench/{name}.py", "--smoke", "--out", str(tmp_path)], {_HIDE: "all"})
    assert p.returncode == 0, _tail(p)
    assert "not found on this machine" in p.stdout, _tail(p)
    res, page = check_outputs(name, tmp_path)
    assert res["environment"]["anchors"] and not any(res["environment"]["anchors"].values())
    assert "absent on this machine" in page
    assert snapshot() == before


def test_every_script_has_the_shared_options():
    """Each script parses the shared options (bench/_common.py: --smoke, --out, --docs,
    --from-json) through its page, so that the test above reaches all of them."""
    for name in SCRIPTS:
        text = (BENCH / f"{name}.py").read_text()
        assert "PAGE.parse(" in text and "PAGE.write(" in text, name


def test_pages_of_the_stored_results(tmp_path):
    """The pages of the last measured runs render from their stored JSON (bench/_tables.py,
    what makes docs/benchmarks), each with its tables."""
    before = snapshot()
    p = run(["bench/_tables.py", "--docs", str(tmp_path)], timeout=600)
    assert p.returncode == 0, _tail(p)
    stored = [n for n in SCRIPTS if (BENCH / "results" / f"{n}.json").exists()]
    for name in stored:
        page = (tmp_path / f"{name}.md").read_text()
        assert page.startswith("# ") and "|---" in page, name
        assert "stored result of the last measured run" in page, name
    assert snapshot() == before
