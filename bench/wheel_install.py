"""The wheel, installed on its own: build it, install it into a fresh folder, time its commands.

Builds the wheel from a copy of the project's files (``pip wheel --no-deps``), installs it with
``pip install --no-deps --target SITE`` (pip compiles the bytecode at install, as in a fresh
virtual environment), then from a temporary working folder with ``PYTHONPATH=SITE`` and this
interpreter (for the dependencies):

* ``SITE/bin/workbench --help``: the first run after the install (cold: nothing of the package
  in the OS file cache beyond what pip just wrote) and the best of 5 following runs;
* ``python -m workbench --help``, best of 5;
* ``workbench render whitted -m phong --size 320x240 -o ...`` (the issue's target), first run.

Writes ``bench/results/wheel_install.json`` and ``docs/benchmarks/wheel_install.md`` and prints it.
Run: ``.venv/bin/python bench/wheel_install.py``.  ``--smoke``: one run of each command, the render at
32 x 24 (the wheel is built as in the full run: pip's isolated build, which installs setuptools
from the package index, about 30 s).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import Page, first_paragraph, kv_table

ROOT = Path(__file__).resolve().parents[1]
PROJECT_FILES = ("pyproject.toml", "setup.py", "README.md", "workbench", "shaders", "scenes", "stress", "examples")


def _timed(cmd, env, cwd) -> float:
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{cmd} failed:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    return wall


def tables(res: dict) -> str:
    size = res.get("render_size", "320x240")
    render = res.get("render_whitted_phong_first_s", res.get("render_whitted_phong_320x240_first_s"))
    return (f"{res['command']}.  No outside anchor: the first run against the warm ones.\n\n"
            + kv_table([("wheel build (s)", res["build_s"]),
                        ("wheel size (bytes)", res["wheel_bytes"]), ("pip install --target (s)", res["install_s"]),
                        ("`workbench --help`, first run (s)", res["help_cold_s"]),
                        (f"`workbench --help`, best of {res.get('repeat', 5)} (s)", res["help_warm_best_of_5_s"]),
                        (f"`python -m workbench --help`, best of {res.get('repeat', 5)} (s)", res["python_m_help_best_of_5_s"]),
                        (f"`workbench render whitted -m phong --size {size}`, first run (s)", render)]))


PAGE = Page("wheel_install", "The wheel, installed on its own", first_paragraph(__doc__), "python bench/wheel_install.py",
            tables, smoke_note="one run per command, render at 32 x 24")


def main(argv=None) -> dict:
    args = PAGE.parse(argparse.ArgumentParser(description=__doc__.splitlines()[0]), argv)
    repeat, size = (1, "32x24") if args.smoke else (5, "320x240")
    res: dict = {"load_average_start": os.getloadavg(), "repeat": repeat, "render_size": size,
}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        src = tmp / "src"
        src.mkdir()
        for name in PROJECT_FILES:
            p = ROOT / name
            if p.is_dir():
                shutil.copytree(p, src / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
            else:
                shutil.copy2(p, src / name)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(tmp / "dist"),
                        str(src)], check=True, capture_output=True)
        res["build_s"] = time.perf_counter() - t0
        (whl,) = (tmp / "dist").glob("workbench-*.whl")
        res["wheel_bytes"] = whl.stat().st_size
        site = tmp / "site"
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--quiet", "--target", str(site),
                        str(whl)], check=True, capture_output=True)
        res["install_s"] = time.perf_counter() - t0
        work = tmp / "work"
        work.mkdir()
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "PYTHONDONTWRITEBYTECODE")}
        env.update(PYTHONPATH=str(site), NUMBA_CACHE_DIR=str(tmp / "numba_cache"))
        script = [str(site / "bin" / "workbench")]
        res["help_cold_s"] = _timed(script + ["--help"], env, work)
        res["help_warm_best_of_5_s"] = min(_timed(script + ["--help"], env, work) for _ in range(repeat))
        res["python_m_help_best_of_5_s"] = min(_timed([sys.executable, "-m", "workbench", "--help"], env, work)
                                               for _ in range(repeat))
        res["render_whitted_phong_first_s"] = _timed(
            script + ["render", "whitted", "-m", "phong", "--size", size, "-o", str(work / "w.png")], env, work)
        res["command"] = "workbench --help from a --target install of the wheel, PYTHONPATH=SITE, cwd outside the checkout"
    res["load_average_end"] = os.getloadavg()
    print(json.dumps(res, indent=2))
    return PAGE.write(args, res)


if __name__ == "__main__":
    main()
