"""The ui package as a one-way street (issue #18 item 8): no import cycle among its modules
(function-level imports included: an import inside a function is still a dependency), and
methods that the window learns about from their renderers (``ui_kind``), so a method
registered at test time shows in the window's method list and panels without any UI edit."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

import workbench
from import_graph import cycles, import_graph
from workbench.renderers import registry
from workbench.renderers.base import UI_KINDS, RenderResult, available, get_renderer

ROOT = Path(__file__).resolve().parents[3]


def test_ui_package_has_no_importcycles():
    """The whole package's circles are checked in test_lint; here the ui's own shape: views
    depend on the state, and the state (plain data) imports no view."""
    graph = import_graph()
    ui = {n: {m for m in t if m.startswith("workbench.app.ui.")} for n, t in graph.items()
          if n.startswith("workbench.app.ui.")}
    assert len(ui) >= 15 and "workbench.app.ui.state" in ui["workbench.app.ui.panels"]
    assert not cycles(ui), cycles(ui)
    # plain containers only: the panels' images, the job boards, the bounded caches, the drag's
    # resolution controller
    assert ui["workbench.app.ui.state"] <= {"workbench.app.ui.images", "workbench.app.ui.jobs",
                                            "workbench.app.ui.bounded", "workbench.app.ui.drag_resolution"}


def test_every_registered_method_says_what_it_is_to_the_window():
    for m in available():
        assert get_renderer(m).ui_kind in UI_KINDS, m
    assert get_renderer("phong").ui_kind == "gl" and get_renderer("pyrender").ui_kind == "child"
    assert get_renderer("pathtrace").ui_kind == "progressive"
    glsl = ROOT / "examples" / "shading" / "toon.glsl"
    assert get_renderer(f"glsl:{glsl}").ui_kind == "gl"


class DummyCpu:
    """A method registered by the test: a CPU job whose image is one colour."""

    name = "dummy_cpu"
    ui_kind = "cpu"
    knob = workbench.renderers.base.Knob("level", (1, 2), 1)
    options = {"level": workbench.renderers.base.Option(int, 1)}
    memory_options = ()

    def estimate_bytes(self, scene, width, height, **options):
        return 64 * width * height + 1

    def render(self, scene, width, height, level=1):
        return RenderResult(self.name, np.full((height, width, 3), 0.25 * level, np.float32))


@pytest.fixture
def dummy_methods(monkeypatch):
    """``dummy_cpu`` (above) and ``dummy_gl`` (the flat method under another name) registered."""
    from workbench.renderers import base
    from workbench.renderers.raster import FlatRenderer

    class DummyGl(FlatRenderer):
        name = "dummy_gl"
        mode = "flat"

    monkeypatch.setitem(registry.BUILTIN, "dummy_cpu", f"{__name__}:DummyCpu")
    monkeypatch.setitem(registry.BUILTIN, "dummy_gl", f"{__name__}:DummyCpu")
    monkeypatch.setitem(base._instances, "dummy_gl", DummyGl())
    yield
    base._instances.pop("dummy_cpu", None)


@pytest.mark.gl
def test_a_method_registered_at_test_time_appears_in_the_window(dummy_methods, window_ctx):
    """Registered in the test, not in the UI: listed in the Methods window, accepted as a
    panel, rendered as its kind says (a GL panel drawn in the window's context, a CPU panel
    by a background job), and a point of the error plot once final."""
    from workbench.app.ui.panel_gpu import release_gl
    from workbench.app.ui.panel_refresh import update_images
    from workbench.app.ui.plot import _final_image
    from workbench.app.ui.state import choosable_methods, method_kind, new_state
    assert {"dummy_cpu", "dummy_gl"} <= set(choosable_methods())
    state = new_state("whitted", ["dummy_gl", "dummy_cpu"], panel_size=32)
    state.ctx = window_ctx
    assert method_kind(state, "dummy_gl") == "gl" and method_kind(state, "dummy_cpu") == "cpu"
    try:
        deadline = time.monotonic() + 30
        while _final_image(state, "dummy_cpu") is None and time.monotonic() < deadline:
            update_images(state)
            time.sleep(0.01)
        assert state.gpu.raster["dummy_gl"].draws == 1
        flat = workbench.render(state.scene.with_camera(state.camera), "flat").image
        assert np.abs(state.images["dummy_gl"] - flat).max() < 1e-5
        image, _ = _final_image(state, "dummy_cpu")
        assert image.shape == (state.camera.height, state.camera.width, 3)
        assert np.all(image == np.float32(0.25))
    finally:
        state.jobs.join_all(30)
        release_gl(state)
