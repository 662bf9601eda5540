"""Shared fixtures: the headless GL context with an error-state check around each GL test, and
the private X server (Xvfb) of the UI tests; on a cold numba cache, the kernels' warm-up beside
a full run (``tests/warm_kernels.py``)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

os.environ.setdefault("NUMBA_CACHE_DIR", str(Path(__file__).resolve().parents[1] / ".numba_cache"))


@pytest.fixture(scope="session", autouse=True)
def reference_cache(tmp_path_factory):
    """One reference cache for the whole run (warm within it, nothing left in ~/.cache)."""
    with pytest.MonkeyPatch.context() as mp:
        folder = tmp_path_factory.mktemp("reference-cache")
        mp.setenv("WORKBENCH_REFERENCE_CACHE", str(folder))
        yield folder


@pytest.fixture(scope="session", autouse=True)
def config_dir(tmp_path_factory):
    """The window's remembered size (``workbench.app.ui.window_size``) kept in a folder of the
    run, not in ~/.config; removed after each test (:func:`fresh_window_size`), so a window
    closed at one size does not open the next test's at it."""
    with pytest.MonkeyPatch.context() as mp:
        folder = tmp_path_factory.mktemp("config")
        mp.setenv("WORKBENCH_CONFIG_DIR", str(folder))
        yield folder


@pytest.fixture(autouse=True)
def fresh_window_size(config_dir):
    yield
    (config_dir / "window.json").unlink(missing_ok=True)


@pytest.fixture(scope="session")
def built_wheel(tmp_path_factory):
    """(output of ``pip wheel``, path of the wheel): built once per run (``wheel_build``)."""
    from wheel_build import build_wheel
    return build_wheel(tmp_path_factory.mktemp("wheel_build"))


@pytest.fixture(scope="session")
def installed_wheel(built_wheel, tmp_path_factory):
    """(site folder, environment, working folder) of the wheel installed (``wheel_build``)."""
    from wheel_build import install_wheel
    return install_wheel(built_wheel[1], tmp_path_factory.mktemp("wheel_site"))


@pytest.fixture
def gl_ctx():
    """The thread's moderngl context; asserts the GL error flag is clear before and after."""
    from workbench.renderers import gl
    ctx = gl.context()
    assert ctx.error == "GL_NO_ERROR", "GL error flag set before the test"
    yield ctx
    assert ctx.error == "GL_NO_ERROR", "the test left a GL error"


class _WindowContext:
    """A headless context standing in for the window's: its ``screen`` a 1 x 1 framebuffer.
    Its state (viewport, depth_func, blend_func...) is the context's: read and set through."""

    def __init__(self, ctx):
        object.__setattr__(self, "_ctx", ctx)
        object.__setattr__(self, "screen", ctx.simple_framebuffer((1, 1)))

    def __getattr__(self, name):
        return getattr(self._ctx, name)

    def __setattr__(self, name, value):
        setattr(self._ctx, name, value)


@pytest.fixture
def window_ctx(gl_ctx):
    """The thread's context in the role of the UI window's (``AppState.ctx``) without a
    window: UI frame functions run in-process."""
    from workbench.renderers import gl
    ctx = _WindowContext(gl_ctx)
    yield ctx
    gl.release_framebuffer(ctx.screen)  # not left bound (the next test's first FBO failed)


@pytest.fixture(scope="session")
def xvfb():
    """A private X server (Xvfb) for the UI tests; its display name (\":N\").  Xvfb picks the
    free display number itself (``-displayfd``: it takes the number's lock file, then writes
    the number when it accepts connections), so the servers of two test processes started at
    once (``pytest -n 2``) never share a number."""
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb not installed")
    read, write = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "1920x1080x24",
                             "-nolisten", "tcp"], pass_fds=(write,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as f:
        number = f.readline().strip()   # empty if Xvfb exited without a display
    if not number:
        proc.wait(10)
        pytest.fail(f"Xvfb did not start (exit status {proc.returncode})")
    yield f":{number}"
    proc.terminate()
    proc.wait(10)


PARALLEL_FIRST = (
    # in-process renders of every bundled scene: they compile most kind-set variants
    "tests/app/test_every_command.py",
    "tests/renderers/pathtrace/test_pathtrace.py",
    "tests/renderers/test_objects_seen.py",
    "tests/renderers/raytrace/test_raytrace_render.py",
    # a window session of at least 150 s whatever the cache: not left for the end
    "tests/app/ui/test_ui_idle.py",
    # child processes (windows, bench scripts) over every scene: they load the kernels the
    # files above compiled rather than compile them again, and do not run last
    "tests/app/ui/test_ui_screens.py",
    "tests/app/ui/test_ui_command.py",
    "tests/project/test_bench_smoke.py",
)
"""Test files a run on several processes (``pytest -n``, ``--dist loadfile``) hands out
first, in this order (measured on a cold cache: each takes minutes); the rest follow in
collection order."""


def pytest_collection_modifyitems(config, items):
    """Under ``pytest -n``: :data:`PARALLEL_FIRST`'s files first (a stable sort: every worker
    collects the same order, as pytest-xdist requires)."""
    if "PYTEST_XDIST_WORKER" not in os.environ:
        return
    rank = {f: i for i, f in enumerate(PARALLEL_FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(rank)))


WARM_MIN_ITEMS = 200
"""A run of at least this many tests starts the kernel warm-up (a single file's run does not)."""
WARM_CACHED_FILES = 60
"""Fewer cached functions (``*.nbi``) than this for the current code: the cache counts as cold
(a full run leaves about 95)."""
_WARMER = pytest.StashKey()


def pytest_collection_finish(session):
    """On a cold numba cache, compile the kernels in a niced process beside a run in one
    process (``tests/warm_kernels.py``); ``WORKBENCH_TEST_WARM=0`` turns it off.  A run on
    several processes (``pytest -n``, as ``bash workbench.sh test``) has no idle core for it."""
    if (os.environ.get("WORKBENCH_TEST_WARM", "1") == "0" or len(session.items) < WARM_MIN_ITEMS
            or "PYTEST_XDIST_WORKER" in os.environ):
        return
    from workbench.core.jit_cache import use_code_keyed_cache
    if sum(1 for _ in use_code_keyed_cache().rglob("*.nbi")) >= WARM_CACHED_FILES:
        return
    root = Path(__file__).resolve().parents[1]
    # the sources the tests import (numba names its cache folders by the source file's path)
    path = os.pathsep.join([str(root)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    session.config.stash[_WARMER] = subprocess.Popen(
        [sys.executable, str(root / "tests" / "warm_kernels.py")], cwd=root,
        env={**os.environ, "PYTHONPATH": path}, stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL, preexec_fn=lambda: os.nice(10))


def pytest_sessionfinish(session):
    proc = session.config.stash.get(_WARMER, None)
    if proc is not None and proc.poll() is None:
        proc.terminate()  # numba renames each cache file into place: nothing is left half-written
        proc.wait(30)
