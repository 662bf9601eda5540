"""The built wheel works on its own: its data folders (shaders, scenes, stress catalogue) are
inside the package, and it renders from a folder outside the checkout, through ``python -m
workbench``, the ``workbench`` script and the Python API.

The wheel is the one ``tests/wheel_build.py`` builds (from a copy of the project's files) and
installs with ``pip install --no-deps --target SITE`` once per run; it is run with this interpreter (for the
dependencies) and ``PYTHONPATH=SITE`` from a temporary working folder; every run checks that
``workbench`` was imported from SITE, not from the checkout.
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import workbench

W, H = 64, 48


@pytest.fixture(scope="module")
def wheel_site(installed_wheel):
    """(site dir, environment, working folder) of the built and installed wheel (``wheel_build``)."""
    return installed_wheel


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
