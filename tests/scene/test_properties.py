"""Property-based tests (Hypothesis) over generated scenes (:mod:`generators`): every object
kind, CSG combinations, materials, camera placements and scales 1e-6 .. 1e6, with the
invariants that hold by hand:

* the CLI: ``workbench render`` exits 0 with its image, or 2 with exactly one
  ``workbench: error:`` line and no traceback (radiosity refusing a camera inside a closed
  object is such a line; an object may be given a broken key);
* no NaN or Inf in any image (API);
* objects seen by the ray caster are seen by the Phong raster (IoU >= 0.97, as
  ``test_objects_seen``);
* scale invariance of the ray methods (the scene scaled by 10^k renders the same image);
* furnaces: radiosity's closed emitting cube gives B = E / (1 - rho) at every pixel, and the
  path tracer's black emitting cube with a lossless mirror of any kind inside gives E.

The default run is bounded (``derandomize=True``: the same examples every run, so it cannot
fail at random) and a larger budget runs under ``-m slow``.
"""
from __future__ import annotations

import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import generators as g
import workbench
from seen_pixels import coverage, iou
from ui_command import WORKBENCH
from workbench.core.errors import NotApplicable

QUICK = settings(max_examples=4, deadline=None, derandomize=True, database=None,
                 suppress_health_check=list(HealthCheck))
"""The default run: a few fixed examples."""

MORE = settings(QUICK, max_examples=60)
"""The slow run's budget (``-m slow``)."""

RAY_METHODS = ("raycast", "raytrace")


def _scene(d: dict):
    with tempfile.TemporaryDirectory() as folder:
        return workbench.load_scene(g.write_scene(d, Path(folder)))


# -- the CLI: exit 0, or exit 2 with one error line -------------------------------------------

CLI_METHODS = {"raycast": [], "raytrace": [], "phong": [], "pathtrace": ["--set", "spp=2"],
               "radiosity": ["--set", "patch_size=0.6"]}

BAD = [("radius", -1.0), ("material", "nosuch"), ("transform", {"scale": 0.0}), ("type", "teapot"),
       ("vertices", [[0.0, 0.0, 0.0]]), ("points", "oops"), ("components", []), ("function", "x +* y")]
"""Broken keys an object may be given (the CLI must then name what is wrong in one line)."""


def check_cli(d: dict, method: str, bad) -> None:
    with tempfile.TemporaryDirectory() as folder:
        if bad is not None:
            d["objects"][0][bad[0]] = bad[1]
        path, out = g.write_scene(d, Path(folder)), Path(folder) / "out.png"
        p = subprocess.run([WORKBENCH, "render", str(path), "-m", method, "--size", "24x18", "-o", str(out),
                            *CLI_METHODS[method]], capture_output=True, text=True, timeout=600)
        assert "Traceback" not in p.stderr, p.stderr[-3000:]
        if p.returncode == 0:
            assert out.stat().st_size > 0
            return
        errors = [ln for ln in p.stderr.splitlines() if ln.startswith("workbench: error:")]
        assert p.returncode == 2 and len(errors) == 1, (p.returncode, p.stderr[-3000:])
        assert not out.exists(), "an error left a half-written output"


cli_cases = st.tuples(st.tuples(g.scenes(), g.scales).map(lambda a: g.scaled(*a)),
                      st.sampled_from(sorted(CLI_METHODS)), st.none() | st.sampled_from(BAD))


@pytest.mark.gl
@settings(QUICK, max_examples=2)  # a subprocess each (interpreter, numba cache): tens of seconds
@given(case=cli_cases)
def test_cli_exits_0_or_one_error_line(case):
    check_cli(*case)


@pytest.mark.slow
@pytest.mark.gl
@MORE
@given(case=cli_cases)
def test_cli_exits_0_or_one_error_line_more(case):
    check_cli(*case)


# -- no NaN or Inf -----------------------------------------------------------------------------

API_METHODS = {  # radiosity's patch_size: a fraction of the scene's diagonal
    "raycast": {}, "raytrace": {}, "phong": {}, "flat": {}, "pathtrace": {"spp": 2},
               "radiosity": {"patch_size": 0.6}}


def check_finite(d: dict, s: float, method: str) -> None:
    sc = _scene(g.scaled(d, s))
    try:
        r = workbench.render(sc, method, width=24, height=18, **API_METHODS[method])
    except NotApplicable:  # radiosity: no emitter, or the camera inside a closed object
        assert method == "radiosity"
        return
    assert np.isfinite(r.image).all(), (method, s)


finite_cases = st.tuples(g.scenes(), g.scales, st.sampled_from(sorted(API_METHODS)))


@pytest.mark.gl
@QUICK
@given(case=finite_cases)
def test_images_are_finite(case):
    check_finite(*case)


@pytest.mark.slow
@pytest.mark.gl
@MORE
@given(case=finite_cases)
def test_images_are_finite_more(case):
    check_finite(*case)


# -- objects seen alike by the ray caster and the raster ---------------------------------------

def check_seen(d: dict, s: float) -> None:
    """At 64 x 48 (``test_objects_seen``'s size and bound: a silhouette moves by up to a pixel
    between an analytic surface and its tessellation)."""
    sc = _scene(g.scaled(d, s))
    ray, ras = coverage(sc, "raycast", 64, 48), coverage(sc, "phong", 64, 48)
    if ray.sum() < 100:
        return  # too few pixels for a 3 % bound to mean anything
    assert iou(ray, ras) >= 0.97, (iou(ray, ras), int(ray.sum()), int(ras.sum()))


seen_cases = st.tuples(g.scenes(materials=("diffuse",), placements=("outside",), floor=False), g.scales)


@pytest.mark.gl
@QUICK
@given(case=seen_cases)
def test_objects_seen_alike(case, gl_ctx):
    check_seen(*case)


@pytest.mark.slow
@pytest.mark.gl
@MORE
@given(case=seen_cases)
def test_objects_seen_alike_more(case, gl_ctx):
    check_seen(*case)


# -- scale invariance of the ray methods -------------------------------------------------------

def check_scale(d: dict, s: float, method: str) -> None:
    """The image of scale ``s`` is that of scale 1: at most 1 % of the pixels differ by more
    than 0.02 (as ``test_objects_seen.test_scale_invariance``)."""
    ref = workbench.render(_scene(g.scaled(d, 1.0)), method, width=24, height=18).image
    img = workbench.render(_scene(g.scaled(d, s)), method, width=24, height=18).image
    assert np.isfinite(img).all()
    bad = (np.abs(img - ref).max(-1) > 0.02).mean()
    assert bad <= 0.01, (method, s, bad)


scale_cases = st.tuples(g.scenes(placements=("outside", "inside")), g.scales, st.sampled_from(RAY_METHODS))


@QUICK
@given(case=scale_cases)
def test_ray_methods_are_scale_invariant(case):
    check_scale(*case)


@pytest.mark.slow
@MORE
@given(case=scale_cases)
def test_ray_methods_are_scale_invariant_more(case):
    check_scale(*case)


# -- furnaces ----------------------------------------------------------------------------------

def furnace(E: float, rho: float, camera) -> dict:
    """The unit cube of six inward-facing emitting walls (``scenes/furnace.toml``), emission
    ``E``, reflectance ``rho``, the camera at ``camera`` (inside) looking at +z."""
    c = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0], [0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]]
    walls = [(0, 1, 2, 3), (4, 5, 6, 7), (0, 4, 7, 1), (3, 2, 6, 5), (1, 7, 6, 2), (0, 3, 5, 4)]
    return {"scene": {"background": [0.0, 0.0, 0.0], "ambient": [0.0, 0.0, 0.0]},
            "camera": {"position": camera, "look_at": [camera[0], camera[1], camera[2] + 1.0], "fov_y": 60.0,
                       "resolution": [16, 16]},
            "materials": {"wall": {"color": [1.0, 1.0, 1.0], "ka": 0.0, "kd": rho, "emission": [E, E, E]},
                          **{k: dict(v) for k, v in g.MATERIALS.items()}},
            "lights": [], "objects": [{"type": "polygon", "material": "wall", "vertices": [c[i] for i in w]}
                                      for w in walls]}


def check_radiosity_furnace(E: float, rho: float, camera, s: float) -> None:
    """Every pixel B = E / (1 - rho), at any scale (delta form factors normalised, direct solve)."""
    sc = _scene(g.scaled(furnace(E, rho, camera), s))
    r = workbench.render(sc, "radiosity", width=12, height=12, patch_size=0.34, solver="direct",
                         hemicube_normalize=True)
    assert np.abs(r.image / (E / (1.0 - rho)) - 1.0).max() < 1e-4, (E, rho, s)


inside_cube = st.lists(st.floats(0.1, 0.9), min_size=3, max_size=3)
radiosity_furnaces = st.tuples(st.floats(0.05, 2.0), st.floats(0.0, 0.95), inside_cube, g.scales)


@pytest.mark.gl
@QUICK
@given(case=radiosity_furnaces)
@example(case=(1.0, 0.0, [0.5, 0.125, 0.5], 1.0))  # found: the floor below the camera was clipped
def test_radiosity_furnace(case, gl_ctx):
    check_radiosity_furnace(*case)


@pytest.mark.slow
@pytest.mark.gl
@MORE
@given(case=radiosity_furnaces)
def test_radiosity_furnace_more(case, gl_ctx):
    check_radiosity_furnace(*case)


def check_mirror_furnace(E: float, obj: dict, s: float) -> None:
    """Black walls (kd = 0) emitting ``E`` with a lossless mirror (kr = 1) of any kind inside:
    every path ends on a wall after bounces of weight 1, so every sample, hence every pixel, is
    exactly E (zero variance: no noise band needed; roulette starts after max_bounces)."""
    d = furnace(E, 0.0, [0.5, 0.5, 0.02])
    d["materials"]["lossless"] = {"color": [1.0, 1.0, 1.0], "ka": 0.0, "kd": 0.0, "kr": 1.0}
    d["objects"].append({**obj, "material": "lossless",
                         "transform": {**obj["transform"], "scale": 0.2, "translate": [0.5, 0.5, 0.6]}})
    r = workbench.render(_scene(g.scaled(d, s)), "pathtrace", width=8, height=8, spp=2, seed=1,
                         rr_start=64, max_bounces=64)
    assert np.abs(r.image / E - 1.0).max() < 1e-4, (obj["type"], s, r.image.min(), r.image.max())


mirror_furnaces = st.tuples(st.floats(0.05, 2.0), g.objects(materials=("mirror",)), g.scales)


@QUICK
@given(case=mirror_furnaces)
def test_path_traced_furnace_with_a_mirror_of_any_kind(case):
    check_mirror_furnace(*case)


@pytest.mark.slow
@MORE
@given(case=mirror_furnaces)
def test_path_traced_furnace_with_a_mirror_of_any_kind_more(case):
    check_mirror_furnace(*case)
