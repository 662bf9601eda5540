"""The window's GL panels draw the raster's stand-ins (issue 15 item 4), in-process in the
window's role (``window_ctx``): a Gouraud or Phong panel is the CLI's image with the same
options (stand-ins on by default, ``standins=off`` the bare local model); a camera move draws
no stand-in map, a light's colour keeps the shadow maps and its move redraws them (no new
session either way); a panel whose estimate is over the memory limit says so in one line and
builds nothing; the error plot's matched reference follows the panel's stand-ins."""
from __future__ import annotations

import threading

import numpy as np
import pytest

import workbench
from workbench.app.ui import camera as cam
from workbench.app.ui.panel_gpu import release_gl
from workbench.app.ui.panel_refresh import update_images
from workbench.app.ui.state import new_state, set_light_value, set_material_value, set_option
from workbench.compare.metrics import metrics
from workbench.renderers.base import get_renderer

SIZE = 64
METHODS = ["gouraud", "phong"]


def _cli(state, method, **options):
    """``workbench.render`` of the panel's scene and camera with the panel's options."""
    scene = state.scene.with_camera(state.camera)
    return workbench.render(scene, method, **{**state.options[method], **options}).image


def _panels(ctx, methods):
    state = new_state("whitted", list(methods), panel_size=SIZE)
    state.ctx = ctx
    update_images(state)
    return state


@pytest.mark.gl
def test_panels_draw_the_cli_image_with_stand_ins_and_off_the_bare_model(window_ctx):
    state = _panels(window_ctx, METHODS)
    try:
        _check_cli_images(state)
    finally:
        release_gl(state)


def _check_cli_images(state):
    for m in METHODS:
        assert state.options[m]["standins"] == "on"
        assert "stand-ins envmap, blend, shadows" in state.status[m]
        assert np.abs(state.images[m] - _cli(state, m)).max() <= 1e-5, m
    on = np.array(state.images["phong"])
    set_option(state, "phong", "standins", "off")
    update_images(state)
    assert "bare local model" in state.status["phong"]
    assert np.abs(state.images["phong"] - _cli(state, "phong")).max() <= 1e-5
    # the stand-ins showed: the mirror and the glass ball were not black, shadows fell
    assert metrics(on, state.images["phong"])["rmse"] > 0.05


@pytest.mark.gl
def test_a_camera_move_draws_no_map_and_a_light_colour_keeps_the_shadow_maps(window_ctx):
    state = _panels(window_ctx, ["phong"])  # Gouraud's maps are the same code
    try:
        _check_maps(state, ["phong"])
    finally:
        release_gl(state)


def _check_maps(state, methods):
    g = state.gpu
    sessions = {m: g.raster[m].session for m in methods}
    maps = {m: dict(s.maps_drawn) for m, s in sessions.items()}
    assert all(v == {"shadow": 1, "environment": 1} for v in maps.values())
    draws = {m: g.raster[m].draws for m in methods}
    state.camera = cam.orbit(state.camera, 0.3, 0.1)
    update_images(state)
    for m in methods:
        assert g.raster[m].draws == draws[m] + 1 and sessions[m].maps_drawn == maps[m], m
    set_light_value(state, 0, "color", (1.0, 0.6, 0.4))
    update_images(state)
    for m in methods:
        s = g.raster[m].session
        assert s is sessions[m] and s.live, m  # the same session, live programs
        assert s.maps_drawn == {"shadow": 1, "environment": 2}, m  # the lit scene's maps only
        assert np.abs(state.images[m] - _cli(state, m)).max() <= 1e-4, m
    p = np.asarray(state.scene.lights[0].position)
    set_light_value(state, 0, "position", tuple(p + [0.8, 0.3, -0.2]))
    update_images(state)
    for m in methods:
        s = g.raster[m].session
        assert s is sessions[m] and s.maps_drawn == {"shadow": 2, "environment": 3}, m
        assert np.abs(state.images[m] - _cli(state, m)).max() <= 1e-4, m
    # the mirror's kr stays above 0 (its map stays): a live value too; from 0, a new session
    set_material_value(state, "mirror", "kr", 0.5)
    update_images(state)
    for m in methods:
        assert g.raster[m].session is sessions[m] and sessions[m].maps_drawn["environment"] == 4, m
    set_material_value(state, "matte", "kr", 0.3)
    update_images(state)
    for m in methods:
        assert g.raster[m].session is not sessions[m], m


@pytest.mark.gl
def test_a_panel_over_the_memory_limit_says_so_and_builds_nothing(window_ctx, monkeypatch):
    from workbench.renderers import raster
    state = new_state("whitted", ["phong"], panel_size=SIZE)
    state.ctx = window_ctx
    set_option(state, "phong", "envmap_resolution", 512)
    opts = state.options["phong"]
    est = get_renderer("phong").estimate_bytes(state.scene, state.camera.width, state.camera.height, **opts)
    bare = get_renderer("phong").estimate_bytes(state.scene, state.camera.width, state.camera.height,
                                                **{**opts, "standins": "off"})
    assert est - bare >= 2 * 6 * 512 ** 2 * 20  # two mapped spheres' cube maps
    monkeypatch.setenv("WORKBENCH_MAX_MEMORY", str(est - 1))
    built = []
    monkeypatch.setattr(raster.RasterSession, "__init__", lambda self, *a, **k: built.append(a))
    try:
        update_images(state)
        message = state.status["phong"]
        assert "\n" not in message and "memory" in message and "envmap_resolution=512" in message
        assert built == [] and "phong" not in state.gpu.raster and "phong" not in state.images
    finally:
        release_gl(state)


class _Board:
    """A job board that records requests and answers at once with a marker image."""

    def __init__(self):
        self.asked = []

    def request(self, scene, camera, method, options, tiled):
        self.asked.append((method, dict(options)))
        image = np.full((camera.height, camera.width, 3), len(self.asked), np.float32)
        return type("Job", (), {"cancelled": threading.Event(), "error": None, "image": image})()

    def nbytes(self):  # what the error plot's cache of matched boards weighs
        return 0


def test_the_matched_reference_follows_the_panels_stand_ins(monkeypatch):
    from workbench.app.ui import jobs, plot
    from workbench.compare.reference import matched_spec
    board = _Board()
    monkeypatch.setattr(jobs, "JobBoard", lambda *a, **k: board)
    state = new_state("whitted", ["phong"], panel_size=16)
    p = state.errors
    p.reference, p.ref_options = "none", {}
    spec = matched_spec("phong", state.scene, state.options["phong"])
    assert spec[0] == "raytrace"  # reflection and refraction: the Whitted ray tracer
    image, _ = plot._matched(state, p, "phong")
    assert board.asked[-1] == (spec[0], spec[1]) and image is not None
    set_option(state, "phong", "standins", "shadows")
    plot._matched(state, p, "phong")
    assert board.asked[-1] == ("raycast", {"shadows": True, "spp": 1})
    set_option(state, "phong", "standins", "off")
    plot._matched(state, p, "phong")
    bare = matched_spec("phong")
    assert board.asked[-1] == (bare[0], bare[1]) and not bare[1].get("shadows")
    assert plot._matched(state, p, "phong")[0] is p.matched["phong"] and len(board.asked) == 3
