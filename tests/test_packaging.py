"""The built wheel works on its own: its data folders (shaders, scenes, stress catalogue) are
inside the package, and it renders from a folder outside the checkout, through ``python -m
workbench``, the ``workbench`` script and the Python API.

The wheel is built from a copy of the project's files (so nothing is written into the checkout),
installed with ``pip install --no-deps --target SITE``, and run with this interpreter (for the
dependencies) and ``PYTHONPATH=SITE`` from a temporary working folder; every run checks that
``workbench`` was imported from SITE, not from the checkout.
"""
from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import workbench

ROOT = Path(__file__).resolve().parents[1]
PROJECT_FILES = ("pyproject.toml", "setup.py", "README.md", "workbench", "shaders", "scenes", "stress", "examples")
W, H = 64, 48


def _can_build_offline() -> bool:
    """This interpreter builds wheels itself (setuptools with ``bdist_wheel``): no isolated
    build environment (and no index) needed."""
    import setuptools
    major, minor = (int(x) for x in setuptools.__version__.split(".")[:2])
    return importlib.util.find_spec("wheel") is not None or (major, minor) >= (70, 1)


@pytest.fixture(scope="module")
def wheel_site(tmp_path_factory):
    """(site dir, environment, working folder) of a freshly built and installed wheel."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    src.mkdir()
    for name in PROJECT_FILES:
        p = ROOT / name
        if p.is_dir():
            shutil.copytree(p, src / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy2(p, src / name)
    dist = tmp / "dist"
    cmd = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(dist), str(src)]
    if _can_build_offline():
        cmd.insert(4, "--no-build-isolation")
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    (whl,) = dist.glob("workbench-*.whl")
    site = tmp / "site"
    out = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--quiet", "--target",
                          str(site), str(whl)], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    work = tmp / "work"  # the working folder of every run: outside the checkout
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(PYTHONPATH=str(site), NUMBA_CACHE_DIR=str(tmp / "numba_cache"))
    return site, env, work


def _run(args, env, cwd, timeout=600):
    t0 = time.perf_counter()
    out = subprocess.run(args, capture_output=True, text=True, env=env, cwd=cwd, timeout=timeout)
    wall = time.perf_counter() - t0
    assert out.returncode == 0, f"{args}: {out.stdout[-2000:]}{out.stderr[-2000:]}"
    return out.stdout, wall


API = """
import json, sys
import numpy as np
import workbench
from workbench.core.resources import data_dir
site, method, w, h, out = sys.argv[1:6]
assert workbench.__file__.startswith(site), workbench.__file__
r = workbench.render(workbench.load_scene("whitted"), method, width=int(w), height=int(h))
np.save(out, r.image)
print(json.dumps({"file": workbench.__file__, "shaders": str(data_dir("shaders")),
                  "scenes": str(data_dir("scenes")), "stress": str(data_dir("stress"))}))
"""


def _render_both_ways(method, site, env, work):
    """The whitted scene rendered by ``python -m workbench render`` and by the API in the
    installed copy; returns the two images and the API run's report."""
    cli_npy, api_npy = work / f"cli_{method}.npy", work / f"api_{method}.npy"
    _run([sys.executable, "-m", "workbench", "render", "whitted", "-m", method, "--size", f"{W}x{H}",
          "-o", str(work / f"{method}.png"), "--npy", str(cli_npy)], env, work)
    stdout, _ = _run([sys.executable, "-c", API, str(site), method, str(W), str(H), str(api_npy)], env, work)
    return np.load(cli_npy), np.load(api_npy), json.loads(stdout.strip().splitlines()[-1])


def test_wheel_installs_data_and_renders_phong_from_another_folder(wheel_site, gl_ctx):
    site, env, work = wheel_site
    # the data folders are inside the installed package (not found through the checkout)
    for name, probe in (("shaders", "raster.frag"), ("shaders", "include/lighting.glsl"),
                        ("scenes", "whitted.toml"), ("scenes", "assets/earth_latlong.png"),
                        ("stress", "cases.toml"), ("examples", "shading/toon.glsl")):
        assert (site / "workbench" / "_data" / name / probe).is_file(), (name, probe)
    cli, api, info = _render_both_ways("phong", site, env, work)
    for key in ("file", "shaders", "scenes", "stress"):
        assert Path(info[key]).is_relative_to(site.resolve()) or Path(info[key]).is_relative_to(site), info
    # the same program gives the same image as the checkout's
    here = workbench.render(workbench.load_scene("whitted"), "phong", width=W, height=H).image
    assert np.abs(cli - here).max() <= 1e-6
    assert np.abs(api - here).max() <= 1e-6
    assert here.mean() > 0.1  # a lit scene, not an empty frame
    # the installed `workbench` script (its shebang is this interpreter) and the bundled scenes
    stdout, _ = _run([str(site / "bin" / "workbench"), "scenes"], env, work)
    assert "whitted" in stdout and "cornell" in stdout
    # the example shading models are installed too, and a bare name finds them
    stdout, _ = _run([sys.executable, "-m", "workbench", "methods"], env, work)
    assert f"glsl:toon = {site.resolve() / 'workbench' / '_data' / 'examples' / 'shading' / 'toon.glsl'}" in stdout


@pytest.mark.slow  # the installed copy has its own numba cache: the cold JIT compile takes 30-70 s
def test_wheel_renders_raycast_from_another_folder(wheel_site):
    site, env, work = wheel_site
    cli, api, info = _render_both_ways("raycast", site, env, work)
    assert Path(info["file"]).is_relative_to(site)
    here = workbench.render(workbench.load_scene("whitted"), "raycast", width=W, height=H).image
    assert np.abs(cli - here).max() <= 1e-6
    assert np.abs(api - here).max() <= 1e-6
