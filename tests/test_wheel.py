"""Packaging by the book: ``pip wheel .`` builds without a warning, the wheel holds every data
folder, and the installed copy runs on its own from another folder (``PYTHONPATH`` = the
install folder only) with the version that pyproject.toml states.

The wheel is built from a copy of the project's files (a build writes ``build/`` and
``*.egg-info`` beside its sources; the checkout stays clean), the way a user builds it (``pip
wheel``; in an isolated build environment unless this interpreter can build wheels itself),
then installed with ``pip install --no-deps --target SITE``.  ``tests/test_packaging.py``
compares the installed copy's images with the checkout's.
"""
from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
PROJECT_FILES = ("pyproject.toml", "setup.py", "README.md", "workbench", "shaders", "scenes", "stress", "examples")
VERSION = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
PIP_INDEX_NOTE = "is ignored: it is neither"
"""pip's note about a configured local index folder missing on this machine (workbench.sh
filters it too): about the machine, not the package."""


def _can_build_offline() -> bool:
    """This interpreter builds wheels itself (setuptools with ``bdist_wheel``): no isolated
    build environment (and no index) needed."""
    import setuptools
    major, minor = (int(x) for x in setuptools.__version__.split(".")[:2])
    return importlib.util.find_spec("wheel") is not None or (major, minor) >= (70, 1)


def _clean_env(**extra) -> dict:
    """This environment without ``PYTHONPATH``/``PYTHONHOME`` (nothing of the checkout) and
    without ``PYTHONDONTWRITEBYTECODE`` (with it setuptools says that it skips byte-compiling:
    a note about the environment, not the package)."""
    drop = ("PYTHONPATH", "PYTHONHOME", "PYTHONDONTWRITEBYTECODE")
    env = {k: v for k, v in os.environ.items() if k not in drop}
    env.update(extra)
    return env


def warning_lines(output: str) -> list[str]:
    """The lines of a build's output that warn (any case), pip's index note aside."""
    return [line for line in output.splitlines() if re.search("warn", line, re.I) and PIP_INDEX_NOTE not in line]


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """(output of ``pip wheel``, path of the wheel)."""
    tmp = tmp_path_factory.mktemp("wheel_build")
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
    if _can_build_offline():
        cmd.insert(4, "--no-build-isolation")
    p = subprocess.run(cmd, capture_output=True, text=True, env=_clean_env(), timeout=600)
    output = p.stdout + p.stderr
    assert p.returncode == 0, output[-3000:]
    wheels = list(dist.glob("workbench-*.whl"))
    assert len(wheels) == 1, wheels
    return output, wheels[0]


@pytest.fixture(scope="module")
def installed(built, tmp_path_factory):
    """(site folder, environment with ``PYTHONPATH=site`` only, working folder outside the checkout)."""
    _, wheel = built
    tmp = tmp_path_factory.mktemp("wheel_site")
    site = tmp / "site"
    p = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--quiet", "--target", str(site),
                        str(wheel)], capture_output=True, text=True, env=_clean_env(), timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    work = tmp / "work"
    work.mkdir()
    env = _clean_env(PYTHONPATH=str(site), NUMBA_CACHE_DIR=str(tmp / "numba_cache"))
    return site, env, work


def _run(args, env, cwd, timeout=600) -> subprocess.CompletedProcess:
    p = subprocess.run(args, capture_output=True, text=True, env=env, cwd=cwd, timeout=timeout)
    assert p.returncode == 0, f"{args}: {p.stdout[-2000:]}{p.stderr[-2000:]}"
    return p


def test_the_version_comes_from_pyproject(monkeypatch):
    """``workbench.__version__`` and ``workbench --version`` give pyproject.toml's version: from the
    installed metadata, or from pyproject.toml itself in a checkout that is not installed."""
    import importlib.metadata

    import workbench
    assert workbench.__version__ == VERSION

    def not_installed(name):
        raise importlib.metadata.PackageNotFoundError(name)
    monkeypatch.setattr(importlib.metadata, "version", not_installed)
    assert workbench._version() == VERSION
    p = subprocess.run([sys.executable, "-m", "workbench", "--version"], capture_output=True, text=True,
                       cwd=ROOT, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == f"workbench {VERSION}"


def test_warning_lines_finds_what_setuptools_prints():
    """The filter of the next test sees a setuptools warning, whatever its case."""
    sample = ("running build_py\n"
              "  /tmp/x/setuptools/command/build_py.py:215: _Warning: Package 'a.b' is absent from the `packages` configuration.\n"
              "warning: build_py: byte-compiling is disabled, skipping.\n"
              "WARNING: Location '/opt/x' " + PIP_INDEX_NOTE + " a file nor a directory\n"
              "Successfully built workbench\n")
    assert len(warning_lines(sample)) == 2


def test_the_build_prints_no_warning(built):
    output, _ = built
    assert "Successfully built workbench" in output or "Saved" in output, output[-2000:]
    assert warning_lines(output) == [], "\n".join(warning_lines(output))


def test_the_wheel_holds_every_data_folder_and_the_version(built):
    _, wheel = built
    assert wheel.name.startswith(f"workbench-{VERSION}-"), wheel.name
    names = set(zipfile.ZipFile(wheel).namelist())
    for path in ("workbench/_data/shaders/raster.frag", "workbench/_data/shaders/include/lighting.glsl",
                 "workbench/_data/scenes/whitted.toml", "workbench/_data/scenes/assets/earth_latlong.png",
                 "workbench/_data/stress/cases.toml", "workbench/_data/examples/shading/toon.glsl",
                 "workbench/app/cli.py"):
        assert path in names, path
    assert any(n.startswith("workbench/core/data/") and n.endswith(".csv") for n in names)
    # every file of the data folders, none left behind
    for folder in ("shaders", "scenes", "stress", "examples"):
        here = {p.relative_to(ROOT / folder).as_posix() for p in (ROOT / folder).rglob("*")
                if p.is_file() and "__pycache__" not in p.parts}
        packed = {n.removeprefix(f"workbench/_data/{folder}/") for n in names
                  if n.startswith(f"workbench/_data/{folder}/")}
        assert here <= packed, (folder, sorted(here - packed))


def test_the_installed_copy_runs_from_another_folder(installed, gl_ctx):
    site, env, work = installed
    code = ("import workbench\nfrom workbench.core.resources import data_dir\n"
            "print(workbench.__version__)\nprint(workbench.__file__)\n"
            "print(data_dir('shaders'))\nprint(data_dir('scenes'))")
    version, file, shaders, scenes = _run([sys.executable, "-c", code], env, work).stdout.split()
    assert version == VERSION
    for path in (file, shaders, scenes):
        assert Path(path).resolve().is_relative_to(site.resolve()), path
    assert _run([str(site / "bin" / "workbench"), "--version"], env, work).stdout.strip() == f"workbench {VERSION}"
    helped = _run([sys.executable, "-m", "workbench.app.cli", "--help"], env, work).stdout
    for command in ("render", "compare", "study", "snapshot", "ui"):
        assert command in helped
    # the bundled scenes and shaders are found: a GL render of a bundled scene
    out = work / "phong.png"
    p = _run([sys.executable, "-m", "workbench.app.cli", "render", "whitted", "-m", "phong", "--size", "16x12",
              "-o", str(out)], env, work)
    assert "warning" not in p.stderr.lower(), p.stderr
    assert Image.open(out).size == (16, 12)
    assert np.asarray(Image.open(out)).std() > 0  # a picture, not a blank frame


@pytest.mark.slow  # the installed copy has its own numba cache: the ray caster compiles cold (minutes)
def test_the_installed_copy_ray_casts_from_another_folder(installed):
    site, env, work = installed
    out = work / "raycast.png"
    p = _run([sys.executable, "-m", "workbench.app.cli", "render", "whitted", "-m", "raycast", "--size", "16x12",
              "-o", str(out)], env, work, timeout=1200)
    assert "warning" not in p.stderr.lower(), p.stderr
    assert Image.open(out).size == (16, 12)
    assert np.asarray(Image.open(out)).std() > 0
