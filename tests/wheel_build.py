"""The wheel the packaging tests share (``tests/project/test_wheel.py``, ``tests/project/test_packaging.py``):
built once per test run from a copy of the project's files (a build writes ``build/`` and
``*.egg-info`` beside its sources; the checkout stays clean), the way a user builds it (``pip
wheel``; in an isolated build environment unless this interpreter can build wheels itself), then
installed with ``pip install --no-deps --target SITE`` (fixtures ``built_wheel`` and
``installed_wheel`` of ``conftest.py``)."""
from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROJECT_FILES = ("pyproject.toml", "setup.py", "README.md", "workbench", "shaders", "scenes", "stress", "examples")


def can_build_offline() -> bool:
    """This interpreter builds wheels itself (setuptools with ``bdist_wheel``): no isolated
    build environment (and no index) needed."""
    import setuptools
    major, minor = (int(x) for x in setuptools.__version__.split(".")[:2])
    return importlib.util.find_spec("wheel") is not None or (major, minor) >= (70, 1)


def clean_env(**extra) -> dict:
    """This environment without ``PYTHONPATH``/``PYTHONHOME`` (nothing of the checkout) and
    without ``PYTHONDONTWRITEBYTECODE`` (with it setuptools says that it skips byte-compiling:
    a note about the environment, not the package)."""
    drop = ("PYTHONPATH", "PYTHONHOME", "PYTHONDONTWRITEBYTECODE")
    env = {k: v for k, v in os.environ.items() if k not in drop}
    env.update(extra)
    return env


def build_wheel(tmp: Path) -> tuple[str, Path]:
    """(output of ``pip wheel``, path of the wheel) built under ``tmp``."""
    src = tmp / "src"
    src.mkdir()
    for name in PROJECT_FILES:
        p = ROOT / name
        if p.is_dir():
            shutil.copytree(p, src / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy2(p, src / name)
    dist = tmp / "dist"
    cmd = [sys.executable, "-m", "pip", "wheel", "--no-deps", "-w", str(dist), str(src)]
    if can_build_offline():
        cmd.insert(4, "--no-build-isolation")
    p = subprocess.run(cmd, capture_output=True, text=True, env=clean_env(), timeout=600)
    output = p.stdout + p.stderr
    assert p.returncode == 0, output[-3000:]
    wheels = list(dist.glob("workbench-*.whl"))
    assert len(wheels) == 1, wheels
    return output, wheels[0]


def install_wheel(wheel: Path, tmp: Path) -> tuple[Path, dict, Path]:
    """(site folder, environment with ``PYTHONPATH=site`` only and a numba cache of its own,
    working folder outside the checkout) of ``wheel`` installed under ``tmp``."""
    site = tmp / "site"
    p = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--quiet", "--target", str(site),
                        str(wheel)], capture_output=True, text=True, env=clean_env(), timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    work = tmp / "work"
    work.mkdir()
    return site, clean_env(PYTHONPATH=str(site), NUMBA_CACHE_DIR=str(tmp / "numba_cache")), work
