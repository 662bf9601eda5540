"""What the window shows first and how its panels are laid out, without a window: the first
view's methods, the panels' resolution at the scene camera's aspect, the grid of panels that
fits the window, the refused seventh panel."""
from __future__ import annotations

import pytest

from workbench.app.ui.placement import PANEL_GAP, panel_grid
from workbench.app.ui.state import (MAX_PANELS, choosable_methods, new_state, panel_camera,
                                    set_scene, toggle_method)


def test_first_view_compares_a_raster_method_with_the_ray_tracer():
    """Before: flat, Gouraud and Phong (three nearly identical images)."""
    state = new_state("whitted")
    assert state.methods == ["phong", "raytrace"]
    assert state.diff_pair == ("phong", "raytrace")


def test_first_view_of_an_emitter_scene_adds_radiosity_and_follows_scene_switches():
    allowed = choosable_methods()
    state = new_state("cornell")
    assert state.methods[:3] == ["phong", "raytrace", "radiosity"]
    assert ("pathtrace" in state.methods) == ("pathtrace" in allowed)
    set_scene(state, "whitted")  # the first view, untouched: the new scene's first view
    assert state.methods == ["phong", "raytrace"]
    toggle_method(state, "flat", True)
    set_scene(state, "cornell")  # an edited list is the user's: kept
    assert state.methods == ["phong", "raytrace", "flat"]


def test_panels_keep_the_scene_cameras_aspect():
    """Before: always square (256 x 256), cropping whitted's 480 x 360 view."""
    state = new_state("whitted", ["phong"], 256)
    assert (state.camera.width, state.camera.height) == (256, 192)
    tall = panel_camera(state.scene.camera.with_resolution(300, 600), 128)
    assert (tall.width, tall.height) == (64, 128)
    set_scene(state, "cornell")  # square camera
    assert (state.camera.width, state.camera.height) == (256, 256)


@pytest.mark.parametrize("n", range(1, MAX_PANELS + 1))
def test_panel_grid_fits_the_region_and_wraps(n):
    aspect, chrome = 4 / 3, 70.0
    for avail_w, avail_h in ((1280, 420), (1900, 700), (1024, 300), (600, 900)):
        cols, w, h = panel_grid(n, avail_w, avail_h, aspect, chrome)
        rows = -(-n // cols)
        assert 1 <= cols <= n
        assert abs(w / h - aspect) < 0.02
        if w > 32:  # fits both ways (32 px is the floor below which the window scrolls)
            assert cols * w + (cols - 1) * PANEL_GAP <= avail_w
            assert rows * (h + chrome) + (rows - 1) * PANEL_GAP <= avail_h + 1
        # no other number of columns gives larger images
        for c in range(1, n + 1):
            r = -(-n // c)
            other = min((avail_w - (c - 1) * PANEL_GAP) / c,
                        ((avail_h - (r - 1) * PANEL_GAP) / r - chrome) * aspect)
            assert other <= w + 1


def test_panels_grow_with_the_window():
    small = panel_grid(3, 1280, 420, 4 / 3, 70.0)
    big = panel_grid(3, 1900, 700, 4 / 3, 70.0)
    assert big[1] > small[1] * 1.3


def test_a_seventh_panel_is_refused_with_a_message():
    """Before: the checkbox did nothing and said nothing."""
    state = new_state("whitted", choosable_methods()[:MAX_PANELS])
    extra = choosable_methods()[MAX_PANELS]
    assert not toggle_method(state, extra, True)
    assert extra not in state.methods and len(state.methods) == MAX_PANELS
    assert f"at most {MAX_PANELS}" in state.status["methods"]
    assert toggle_method(state, state.methods[0], False)
    assert "methods" not in state.status
    assert toggle_method(state, extra, True) and state.methods[-1] == extra
    one = new_state("whitted", ["phong"])
    assert not toggle_method(one, "phong", False) and one.methods == ["phong"]
    assert "at least one" in one.status["methods"]


def test_a_scene_switch_leaves_nothing_of_the_old_scene():
    """Before: the ray tree, the picked patch, the run times and the browser's "opened" line
    still showed the previous scene."""
    from workbench.app.ui.file_browser import open_scene
    from workbench.scene.library import resolve
    state = new_state("whitted", ["phong", "raytrace"])
    assert open_scene(state, resolve("whitted")) and "whitted" in state.browser.message
    state.ray_tree, state.patch_pick = {"pixel": [1, 2], "tree": {}}, object()
    state.timings.update(phong=0.01, raytrace=2.0)
    state.status["patch pick"] = "pixel (1, 2) shows no patch"
    set_scene(state, "csg")
    assert state.ray_tree is None and state.patch_pick is None
    assert state.timings == {} and "patch pick" not in state.status
    assert state.browser.message == ""


def test_plot_header_legend_and_markers():
    """Before: the header was a cut Python dict, a removed panel stayed in the legend and
    markers cycled through shapes from frame to frame."""
    from workbench.app.ui.plot import MARKERS, ErrorPlot, marker_of, options_text, plotted_lines
    assert options_text({"max_depth": 12}) == "max_depth=12"
    assert options_text({"patch_size": 0.05, "spp": 4}) == "patch_size=0.05, spp=4"
    plot = ErrorPlot()
    pt = {"seconds": 0.5, "rmse": 0.1, "flip": 0.2}
    plot.points = {"phong": {(("tessellation", 6),): pt}, "flat": {(("tessellation", 6),): pt}}
    lines = plotted_lines(plot, ["phong", "raytrace"], "rmse")
    assert list(lines) == ["phong"]  # flat was removed from the panels: not in the legend
    assert lines["phong"][0].tolist() == [500.0]
    shapes = [marker_of(m) for m in choosable_methods()]
    assert shapes == [marker_of(m) for m in choosable_methods()]  # the same every call
    assert len(set(shapes[:len(MARKERS)])) == min(len(shapes), len(MARKERS))
