"""Shared fixtures: the headless GL context with an error-state check around each GL test."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

os.environ.setdefault("NUMBA_CACHE_DIR", str(Path(__file__).resolve().parents[1] / ".numba_cache"))


@pytest.fixture
def gl_ctx():
    """The thread's moderngl context; asserts the GL error flag is clear before and after."""
    from workbench.renderers import gl
    ctx = gl.context()
    assert ctx.error == "GL_NO_ERROR", "GL error flag set before the test"
    yield ctx
    assert ctx.error == "GL_NO_ERROR", "the test left a GL error"
