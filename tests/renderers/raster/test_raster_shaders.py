"""Shader plumbing: includes and define injection, the define builder (only what the scene
needs), the program cache, left_out, options, and RasterSession for per-frame draws."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import workbench
from workbench.core.errors import WorkbenchError
from workbench.renderers.raster import RasterSession
from workbench.renderers.raster_shaders import ProgramCache, build_source, material_defines


def test_defines_follow_version_then_line_and_includes_are_resolved():
    src = build_source("raster.frag", {"MODE_PHONG": "", "N_LIGHTS": 2, "TOL_ZERO": "1e-12",
                                       "TOL_NORMAL_CANCEL": "1e-6", "TOL_BUMP_STEP": "1e-3"})
    lines = src.splitlines()
    assert lines[0].startswith("#version")
    assert lines[1:6] == sorted(lines[1:6]) and all(x.startswith("#define ") for x in lines[1:6])
    assert lines[6] == "#line 2 0"
    assert "#include" not in src
    assert src.count("vec3 safe_normalize(") == 1  # common.glsl included once
    assert "void local_terms(" in src and "float value_noise(" in src


def test_material_defines_only_what_is_needed():
    whitted = workbench.load_scene("whitted")
    kw = dict(n_lights=2, has_uv=False, blinn=False, depth_bits=24, allow_bump=True)
    checker = material_defines(whitted, whitted.materials["checker"], "phong", **kw)
    assert checker["TEX_KIND"] == 1 and checker["TEX_PROJ"] == 1 and "MODE_PHONG" in checker
    matte = material_defines(whitted, whitted.materials["matte"], "gouraud", **kw)
    assert not any(k.startswith(("TEX_", "BUMP_", "OPACITY_", "ENV_")) for k in matte)
    assert "SPECULAR" in matte and "BLINN" not in matte
    bricks = workbench.load_scene("bricks")
    wall = bricks.materials["wall"]
    assert "BUMP_KIND" in material_defines(bricks, wall, "phong", **kw)
    assert "BUMP_KIND" not in material_defines(bricks, wall, "gouraud", **{**kw, "allow_bump": False})
    env = workbench.load_scene("envmap")
    chrome = material_defines(env, env.materials["chrome"], "phong", **kw)
    assert "ENV_MAP" in chrome and chrome["ENV_KIND"] == 2
    assert material_defines(env, env.materials["grid"], "phong", **kw)["OPACITY_KIND"] == 5
    assert "DEPTH_LEVELS" in material_defines(env, env.materials["grid"], "phong", **{**kw, "depth_bits": 16})


def test_program_cache_keys_on_defines(gl_ctx):
    cache = ProgramCache(gl_ctx)
    scene = workbench.load_scene("whitted")
    kw = dict(n_lights=2, has_uv=False, blinn=False, depth_bits=24, allow_bump=True)
    matte = scene.materials["matte"]
    d1 = material_defines(scene, matte, "phong", **kw)
    # a material of another name with the same constants: same defines, one program
    d2 = material_defines(scene, replace(matte, name="matte copy"), "phong", **kw)
    # the material's constants are compiled in: another kd is another program
    d3 = material_defines(scene, replace(matte, kd=matte.kd / 2), "phong", **kw)
    assert d2 == d1 and d3["MAT_KD"] != d1["MAT_KD"]
    assert cache.get("raster", d1) is cache.get("raster", d2)
    assert cache.get("raster", d3) is not cache.get("raster", d1)
    assert len(cache.programs) == 2 and cache.compile_seconds > 0


def test_left_out_and_features(gl_ctx):
    r = workbench.render(workbench.load_scene("whitted"), "gouraud", width=32, height=24, standins="off")
    left = " ".join(map(str, r.left_out))
    for f in ("bump: not needed", "opacity: not needed", "environment: not needed", "shadows:", "refraction:"):
        assert f in left
    assert "textures" in r.features_used and r.stats["gl_renderer"].startswith("llvmpipe")
    rb = workbench.render(workbench.load_scene("bricks"), "flat", width=32, height=24)
    assert any(str(x).startswith("bump: flat") for x in rb.left_out)
    assert "bump" in workbench.render(workbench.load_scene("bricks"), "phong", width=32, height=24).features_used


@pytest.mark.parametrize("opts", [{"depth_bits": 8}, {"view": "normals"}, {"tessellation": 0},
                                  {"near": 2.0, "far": 1.0}, {"blinn": "maybe"}, {"msaa": 4}])
def test_bad_options_are_clear_errors(opts):
    with pytest.raises(WorkbenchError):
        workbench.render(workbench.load_scene("whitted"), "phong", width=16, height=12, **opts)


def test_session_draws_other_cameras_without_rebuilding(gl_ctx):
    scene = workbench.load_scene("whitted")
    s = RasterSession(scene, "phong")
    cam = replace(scene.camera, position=(2.0, 2.0, -5.0), width=40, height=30)
    img = s.draw(cam)
    ref = workbench.render(scene.with_camera(cam), "phong", standins="off").image
    assert np.allclose(img, ref, atol=1e-6)
    assert not np.allclose(img, s.draw(scene.camera.with_resolution(40, 30)), atol=1e-3)
    # render() reuses its session for the same scene content
    r1 = workbench.render(scene, "flat", width=40, height=30)
    r2 = workbench.render(scene, "flat", width=40, height=30)
    assert r2.stats["session_reused"] and r2.timings["compile"] == 0.0
    assert np.array_equal(r1.image, r2.image)


def test_evicted_sessions_are_released(gl_ctx):
    from workbench.renderers import raster
    scene = workbench.load_scene("whitted")
    first, _ = raster.session_for(scene, "flat", 1, False, 24)
    for level in range(2, 2 + raster._MAX_SESSIONS):
        raster.session_for(scene, "flat", level, False, 24)
    assert first.draws == [] and first._gl_objects == []
    # a fresh session for the same key works after the eviction
    again, created = raster.session_for(scene, "flat", 1, False, 24)
    assert created and again.draw(scene.camera.with_resolution(16, 12)).shape == (12, 16, 3)
