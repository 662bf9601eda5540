"""A user's shading model added from the window's file picker (issue #16 item 3, the UI part):
a ``*.glsl`` file becomes a GL method panel (``glsl:FILE``) drawing the CLI's image; a file
that cannot be used changes nothing and says why in one line; a model that does not compile
shows its one-line message (the user's file and line) under the picker and in its panel, and
is not compiled again every frame."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import workbench
from workbench.app.ui.file_browser import add_model, listing
from workbench.app.ui.panel_gpu import release_gl
from workbench.app.ui.panel_refresh import update_images
from workbench.app.ui.state import new_state, short_name
from workbench.renderers import raster

ROOT = Path(__file__).resolve().parents[3]
TOON = ROOT / "examples" / "shading" / "toon.glsl"


def test_the_picker_lists_shading_models():
    state = new_state("whitted", ["phong"])
    dirs, files = listing(TOON.parent, state.shading_browser.pattern)
    assert [p.name for p in files] == ["oren_nayar.glsl", "toon.glsl"]


@pytest.mark.gl
def test_a_picked_model_becomes_a_panel_and_a_compile_error_one_line(window_ctx, tmp_path, monkeypatch):
    bad = tmp_path / "bad_model.glsl"
    bad.write_text(TOON.read_text().replace("float level = ", "float level = undefined_thing + "))
    line = 1 + TOON.read_text().splitlines().index(next(x for x in TOON.read_text().splitlines()
                                                       if "float level = " in x))
    state = new_state("whitted", ["phong"], panel_size=32)
    state.ctx = window_ctx
    built, init = [], raster.RasterSession.__init__

    def counted(self, *args, **kwargs):
        built.append(args[1])
        init(self, *args, **kwargs)

    monkeypatch.setattr(raster.RasterSession, "__init__", counted)
    try:
        # not a shading model: nothing changes, one line naming the file
        junk = tmp_path / "junk.glsl"
        junk.write_text("void main() {}\n")
        assert not add_model(state, junk)
        msg = state.shading_browser.message
        assert state.shading_browser.failed and str(junk) in msg and "\n" not in msg
        assert state.methods == ["phong"] and state.user_methods == []
        # does not compile: a panel whose message is the user's file and line, tried once
        assert add_model(state, bad)
        m_bad = f"glsl:{bad}"
        assert state.methods == ["phong", m_bad] and short_name(m_bad) == "glsl:bad_model.glsl"
        for _ in range(3):
            update_images(state)
        message = state.panel_errors[m_bad][1]
        assert message.startswith(f"{bad}:{line}:") and "undefined_thing" in message and "\n" not in message
        assert state.status[m_bad] == message and m_bad not in state.images
        assert built == ["phong", "phong"]  # Phong, then the bad model once (not every frame)
        # a good model: its panel is the CLI's image of the same camera
        assert add_model(state, TOON)
        m = f"glsl:{TOON}"
        assert state.shading_browser.message == f"added {m}" and not state.shading_browser.failed
        update_images(state)
        cli = workbench.render(state.scene.with_camera(state.camera), m).image
        assert np.abs(state.images[m] - cli).max() < 1e-5
        assert len(np.unique(state.images[m].reshape(-1, 3), axis=0)) > 2
    finally:
        release_gl(state)
