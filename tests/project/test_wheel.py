"""Packaging by the book: ``pip wheel .`` builds without a warning, the wheel holds every data
folder, and the installed copy runs on its own from another folder (``PYTHONPATH`` = the
install folder only) with the version that pyproject.toml states.

The wheel is the one ``tests/wheel_build.py`` builds and installs once per run.  ``tests/project/test_packaging.py``
compares the installed copy's images with the checkout's.
"""
from __future__ import annotations

import re
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from wheel_build import ROOT

VERSION = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
PIP_INDEX_NOTE = "is ignored: it is neither"
"""pip's note about a configured local index folder missing on this machine (workbench.sh
filters it too): about the machine, not the package."""


def warning_lines(output: str) -> list[str]:
    """The lines of a build's output that warn (any case), pip's index note aside."""
    return [line for line in output.splitlines() if re.search("warn", line, re.I) and PIP_INDEX_NOTE not in line]


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


def test_the_build_prints_no_warning(built_wheel):
    output, _ = built_wheel
    assert "Successfully built workbench" in output or "Saved" in output, output[-2000:]
    assert warning_lines(output) == [], "\n".join(warning_lines(output))


def test_the_wheel_holds_every_data_folder_and_the_version(built_wheel):
    _, wheel = built_wheel
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


def test_the_installed_copy_runs_from_another_folder(installed_wheel, gl_ctx):
    site, env, work = installed_wheel
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
def test_the_installed_copy_ray_casts_from_another_folder(installed_wheel):
    site, env, work = installed_wheel
    out = work / "raycast.png"
    p = _run([sys.executable, "-m", "workbench.app.cli", "render", "whitted", "-m", "raycast", "--size", "16x12",
              "-o", str(out)], env, work, timeout=1200)
    assert "warning" not in p.stderr.lower(), p.stderr
    assert Image.open(out).size == (16, 12)
    assert np.asarray(Image.open(out)).std() > 0
