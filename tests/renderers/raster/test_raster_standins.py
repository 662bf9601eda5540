"""The raster family's stand-ins for global effects (workbench/renderers/raster_standins.py):
environment maps reflect what the ray tracer reflects, shadow maps darken what its shadow
feelers darken, blending tints by the material's colour, and the error against the Whitted reference drops with
each stand-in (``standins="off"``, the bare local model, is pinned by test_raster_golden)."""
from __future__ import annotations


import numpy as np
import pytest

import workbench
from workbench.core.errors import WorkbenchError
from workbench.renderers.base import check_memory, get_renderer
from workbench.renderers.raster import RasterSession, session_for
from workbench.scene.tessellate import DEFAULT_LEVEL
from workbench.renderers import raster_standins as sti
from workbench.scene.io import scene_from_dict



def _mirror_scene(**mirror):
    """A mirror sphere at the origin seen from +z; an emissive red wall behind the camera, an
    emissive green floor below; white background above."""
    mat = {"color": [1.0, 1.0, 1.0], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kr": 0.9}
    mat.update(mirror)
    return scene_from_dict({
        "scene": {"background": [1.0, 1.0, 1.0], "ambient": [0.0, 0.0, 0.0]},
        "camera": {"position": [0.0, 0.0, 4.0], "look_at": [0.0, 0.0, 0.0], "fov_y": 40.0,
                   "resolution": [64, 64]},
        "materials": {"mirror": mat,
                      "red": {"color": [0.0, 0.0, 0.0], "ka": 0.0, "kd": 0.0, "ks": 0.0, "emission": [1.0, 0.0, 0.0]},
                      "green": {"color": [0.0, 0.0, 0.0], "ka": 0.0, "kd": 0.0, "ks": 0.0, "emission": [0.0, 1.0, 0.0]}},
        "objects": [{"type": "sphere", "name": "ball", "material": "mirror", "center": [0.0, 0.0, 0.0], "radius": 1.0},
                    {"type": "polygon", "name": "wall", "material": "red",
                     "vertices": [[-20, -20, 8], [20, -20, 8], [20, 20, 8], [-20, 20, 8]]},
                    {"type": "polygon", "name": "floor", "material": "green",
                     "vertices": [[-20, -3, -20], [-20, -3, 20], [20, -3, 20], [20, -3, -20]]}]})


def _pixel(scene, point):
    """(row, column) of a world point."""
    xy, _ = scene.camera.project(np.asarray([point], dtype=np.float64))
    return int(xy[0, 1]), int(xy[0, 0])


@pytest.mark.parametrize("method", ["phong", "gouraud"])
def test_mirror_sphere_reflects_the_walls_where_expected(gl_ctx, method):
    scene = _mirror_scene()
    on = workbench.render(scene, method, tessellation=12).image
    off = workbench.render(scene, method, tessellation=12, standins="off").image
    # centre: the ray reflects straight back, onto the red wall behind the camera
    c = _pixel(scene, (0.0, 0.0, 1.0))
    assert np.allclose(on[c], (0.9, 0.0, 0.0), atol=0.03), on[c]
    assert np.abs(off[c]).max() < 1e-6  # the bare local model: a black ball
    # lower part (normal 50 degrees down): reflected downwards onto the green floor
    n = np.array([0.0, -np.sin(np.radians(50)), np.cos(np.radians(50))])
    lo = _pixel(scene, n)
    assert on[lo][1] > 0.8 and on[lo][0] < 0.05, on[lo]
    # upper part: the reflected ray leaves upwards, the white background
    hi = _pixel(scene, n * (1.0, -1.0, 1.0))
    assert np.allclose(on[hi], 0.9, atol=0.03), on[hi]
    assert np.isfinite(on).all()


def test_glass_blending_tints_the_background_by_its_colour(gl_ctx):
    d = {"scene": {"background": [1.0, 1.0, 1.0], "ambient": [0.0, 0.0, 0.0]},
         "camera": {"position": [0.0, 0.0, 4.0], "look_at": [0.0, 0.0, 0.0], "fov_y": 40.0, "resolution": [32, 32]},
         "materials": {"glass": {"color": [0.2, 1.0, 0.3], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kt": 0.8, "ior": 1.5}},
         "objects": [{"type": "polygon", "name": "pane", "material": "glass",
                      "vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]}]}
    scene = scene_from_dict(d)
    on = workbench.render(scene, "phong").image
    off = workbench.render(scene, "phong", standins="off").image
    assert np.allclose(on[16, 16], (0.16, 0.8, 0.24), atol=1e-3), on[16, 16]   # kt C x background
    assert np.allclose(on[0, 0], 1.0) and np.abs(off[16, 16]).max() < 1e-6       # outside; bare: opaque black


def _whitted_floor_shadows(scene):
    """Floor pixels of ``whitted`` (seen, not behind a sphere) and whether a shadow feeler from
    their floor point to some light hits a sphere (the ray tracer's shadow test)."""
    o, d = scene.camera.rays()
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    spheres = [(np.asarray(x.center), x.radius) for x in scene.objects if x.kind == "sphere"]

    def sphere_t(orig, dirn):
        t_best = np.full(len(orig), np.inf)
        for c, r in spheres:
            oc = orig - c
            b = np.sum(dirn * oc, -1)
            disc = b * b - (np.sum(oc * oc, -1) - r * r)
            t = -b - np.sqrt(np.maximum(disc, 0.0))
            t_best = np.where((disc > 0) & (t > 1e-6), np.minimum(t_best, t), t_best)
        return t_best

    t_floor = -o[:, 1] / np.where(d[:, 1] < 0, d[:, 1], -1.0)
    P = o + t_floor[:, None] * d
    floor = (d[:, 1] < 0) & (np.abs(P[:, 0] - 0.0) < 8) & (np.abs(P[:, 2] - 2.0) < 8) & (sphere_t(o, d) > t_floor)
    shadowed = np.zeros(len(o), bool)
    for light in scene.point_lights():
        L = np.asarray(light.position) - P
        dist = np.linalg.norm(L, axis=-1)
        shadowed |= sphere_t(P, L / dist[:, None]) < dist
    H, W = scene.camera.height, scene.camera.width
    return floor.reshape(H, W), shadowed.reshape(H, W)


@pytest.mark.parametrize("method", ["phong", pytest.param("gouraud", marks=pytest.mark.slow)])
def test_shadow_maps_darken_the_pixels_the_ray_tracer_shadows(gl_ctx, method):
    scene = workbench.load_scene("whitted")
    scene = scene.with_camera(scene.camera.with_resolution(160, 120))
    floor, truth = _whitted_floor_shadows(scene)
    on = workbench.render(scene, method, standins="shadows").image
    off = workbench.render(scene, method, standins="off").image
    darker = (off - on).max(-1) > 0.02
    # one pixel in from the true shadow's outline (the map's texels and the pixel centres differ there)
    edge = truth != np.roll(truth, 1, 0)
    edge |= truth != np.roll(truth, -1, 0)
    edge |= truth != np.roll(truth, 1, 1)
    edge |= truth != np.roll(truth, -1, 1)
    judged = floor & ~edge
    agree = float((darker[judged] == truth[judged]).mean())
    assert truth[judged].sum() > 500 and agree > 0.99, agree
    # a bias of zero: the floor shadows itself (acne) where it is lit
    acne = workbench.render(scene, method, standins="shadows", shadow_bias=0.0).image
    assert ((off - acne).max(-1) > 0.02)[judged & ~truth].mean() > 0.05


def test_rmse_against_the_whitted_reference_drops_with_each_standin(gl_ctx):
    from workbench.compare.metrics import metrics
    from workbench.compare.reference import choose_reference
    scene = workbench.load_scene("whitted")
    ref = choose_reference(scene, 64, 48)
    assert ref.method == "raytrace"
    err = {s: metrics(workbench.render(scene, "phong", width=64, height=48, standins=s).image, ref.image)["rmse"]
           for s in ("off", "envmap", "shadows", "on")}
    assert err["envmap"] < 0.7 * err["off"] and err["shadows"] < err["off"], err
    assert err["on"] < 0.5 * err["off"] and err["on"] < min(err["envmap"], err["shadows"]), err


def test_nothing_is_built_that_the_scene_does_not_need(gl_ctx):
    one = scene_from_dict({
        "camera": {"position": [0.0, 0.0, 4.0], "look_at": [0.0, 0.0, 0.0], "resolution": [16, 16]},
        "lights": [{"type": "point", "position": [2.0, 3.0, 4.0]}],
        "materials": {"m": {"color": [0.8, 0.3, 0.2], "ks": 0.5}},
        "objects": [{"type": "sphere", "material": "m", "center": [0.0, 0.0, 0.0], "radius": 1.0}]})
    s = RasterSession(one, "phong", standins=sti.StandinOptions())
    assert s.env_maps == {} and s.shadow_atlas is None and not s.plan.any
    assert sti.standin_bytes(one, sti.StandinOptions(), "phong") == 0
    # whitted: two mapped spheres (mirror, glass), one atlas of 2 point lights x 6 faces (the
    # session render() uses by default, shared with the other tests)
    w = workbench.load_scene("whitted")
    s, _ = session_for(w, "phong", DEFAULT_LEVEL, False, 24, None, standins=sti.StandinOptions())
    assert set(s.env_maps) == {"mirror", "glass"} and s.shadow_layout.tiles == 12
    assert sti.standin_bytes(w, sti.StandinOptions(envmap_resolution=16, shadow_resolution=32), "phong") \
        == 2 * 6 * 16 ** 2 * 20 + 4 * 3 * 32 ** 2 * 4
    flat = workbench.render(w, "flat", width=16, height=12)
    assert any(x.feature == "shadows" and "flat" in x.reason for x in flat.left_out) and flat.stats["standins"] == {}


def test_memory_is_estimated_before_the_maps_are_made():
    w = workbench.load_scene("whitted")
    r = get_renderer("phong")
    off = r.estimate_bytes(w, 64, 48, standins="off")
    on = r.estimate_bytes(w, 64, 48, shadow_resolution=8192)
    assert on - off == sti.standin_bytes(w, sti.StandinOptions(shadow_resolution=8192), "phong") > 3 * 2 ** 30
    with pytest.raises(WorkbenchError, match="memory"):
        check_memory(r, w, 64, 48, {"tessellation": 6, "envmap_resolution": 128, "shadow_resolution": 8192},
                     max_memory=2 ** 30)


@pytest.mark.parametrize("opts", [{"standins": "maybe"}, {"standins": "envmap,mirrors"},
                                  {"envmap_resolution": 4}, {"shadow_resolution": 10 ** 6},
                                  {"shadow_bias": -0.1}, {"envmap_iterations": 99}])
def test_bad_standin_options_are_one_line_errors(opts):
    with pytest.raises((WorkbenchError, ValueError)) as e:
        workbench.render(workbench.load_scene("whitted"), "phong", width=16, height=12, **opts)
    assert "\n" not in str(e.value)


def test_a_moved_light_redraws_the_shadow_maps_in_the_same_session(gl_ctx):
    """A light's move is a live edit (it used to ask for a new session): the shadow maps are
    redrawn from the new position (read by the live programs from uniforms, SHADOW_LIVE; the
    image against a new session's: test_ui_standins), a colour edit keeps them."""
    from dataclasses import replace
    w = workbench.load_scene("whitted")
    cam = w.camera.with_resolution(32, 24)
    s = RasterSession(w, "phong", standins=sti.StandinOptions(envmap_resolution=16, shadow_resolution=32))
    before = s.draw(cam)
    light = w.lights[0]
    coloured = replace(w, lights=[replace(light, color=(1.0, 0.5, 0.5))] + list(w.lights[1:]))
    assert s.update(coloured) and s.live
    s.draw(cam)
    assert s.maps_drawn == {"shadow": 1, "environment": 2}
    moved = replace(w, lights=[replace(light, position=(-2.0, 6.0, -3.0))] + list(w.lights[1:]))
    assert s.update(moved)
    image = s.draw(cam)
    assert s.maps_drawn == {"shadow": 2, "environment": 3}
    assert s.shadow_atlas.layout.pos[0] == (-2.0, 6.0, -3.0)
    assert np.abs(image - before).max() > 0.1  # the shadows moved
    s.release()


@pytest.mark.parametrize("light", [{"type": "directional", "direction": [0.3, -1.0, 0.2]},
                                   {"type": "area", "vertices": [[-0.5, 6, -0.5], [0.5, 6, -0.5], [0.5, 6, 0.5],
                                                                 [-0.5, 6, 0.5]], "stand_in": 2}])
def test_directional_and_area_light_shadows_fall_where_the_light_points(gl_ctx, light):
    """A sphere over a floor: its shadow map darkens the floor point the light's ray through
    the sphere's centre reaches (orthographic map; an area light's 4 stand-in point lights), and
    not a floor point off to the side."""
    d = {"camera": {"position": [0.0, 5.0, 8.0], "look_at": [0.0, 0.0, 0.0], "fov_y": 40.0, "resolution": [64, 48]},
         "scene": {"ambient": [0.0, 0.0, 0.0]},
         "lights": [dict(light, intensity=1.0 if light["type"] == "directional" else 40.0)],
         "materials": {"m": {"color": [0.8, 0.8, 0.8], "kd": 0.8}},
         "objects": [{"type": "sphere", "name": "ball", "material": "m", "center": [0.0, 1.5, 0.0], "radius": 0.7},
                     {"type": "plane", "name": "floor", "material": "m", "point": [0.0, 0.0, 0.0],
                      "normal": [0.0, 1.0, 0.0], "size": [12.0, 12.0]}]}
    scene = scene_from_dict(d)
    on = workbench.render(scene, "phong").image
    off = workbench.render(scene, "phong", standins="off").image
    down = np.array(light.get("direction", [0.0, -1.0, 0.0]), dtype=np.float64)
    under = np.array([0.0, 1.5, 0.0]) + down * (1.5 / -down[1])    # the centre's shadow on the floor
    row, col = _pixel(scene, under)
    assert off[row, col].max() > 0.05 and on[row, col].max() < 0.5 * off[row, col].max(), (on[row, col], off[row, col])
    row, col = _pixel(scene, (3.0, 0.0, 2.0))
    assert np.allclose(on[row, col], off[row, col], atol=1e-4)
