"""Snapshot tests of rendered images in a user's own test suite.

With pytest (the ``snapshot`` fixture; this module is a pytest plugin, registered through the
``pytest11`` entry point of the installed package, or named in a ``conftest.py`` with
``pytest_plugins = ["workbench.testing"]``)::

    def test_my_model(snapshot):
        snapshot.check("whitted", "glsl:shading/my_model.glsl", size=(160, 120), metric="flip",
                       tolerance=0.02, roughness=0.4)

Snapshots live in ``snapshots/`` next to the test file (``STEM.npy`` linear float32, the value
compared, and ``STEM.png`` its preview: :mod:`workbench.compare.snapshot`).  A failing check
fails the test with one line naming scene, method, metric, value and tolerance, and writes the
difference image and heat map next to the stored image; a missing snapshot fails too, saying
how to record it.  ``pytest --snapshot-update`` (or ``WORKBENCH_SNAPSHOT_UPDATE=1``) records the
missing ones and rewrites the failing ones.

Without pytest: ``assert_snapshot(scene, method, directory, ...)`` raises
:class:`SnapshotMismatch` (an ``AssertionError``) with the same message.
"""
from __future__ import annotations

import os
from pathlib import Path

UPDATE_ENV = "WORKBENCH_SNAPSHOT_UPDATE"
UPDATE_OPTION = "--snapshot-update"


class SnapshotMismatch(AssertionError):
    """A snapshot check failed or its stored image is missing (one-line message)."""


def update_requested() -> bool:
    """True when ``WORKBENCH_SNAPSHOT_UPDATE`` is 1, true, yes or on."""
    return os.environ.get(UPDATE_ENV, "").strip().lower() in ("1", "true", "yes", "on")


def assert_snapshot(scene, method: str, directory: str | Path, *, size: tuple[int, int] | None = None,
                    metric: str = "rmse", tolerance: float | None = None, update: bool | None = None,
                    name: str | None = None, record_hint: str = "", **options):
    """Render ``scene`` (a :class:`~workbench.scene.model.Scene`, a scene file or a bundled
    scene's name) with ``method`` and compare it with the snapshot in ``directory``.

    Parameters
    ----------
    size : (width, height); default the stored image's (the scene camera's when recording).
    metric : ``"rmse"`` or ``"flip"``; tolerance: largest accepted value (default 0.005 for
        RMSE, 0.02 for FLIP).
    update : rewrite a failing or missing snapshot (default: :func:`update_requested`).
    name : the snapshot's file stem (default ``<scene name>.<method>``), e.g. to keep several
        option settings of one method apart.
    **options : the method's options.

    Returns
    -------
    The :class:`workbench.compare.snapshot.Outcome` (status passed, updated).

    Raises
    ------
    SnapshotMismatch
        The check failed (difference image and heat map written) or no snapshot is stored.
    """
    from .compare.snapshot import check
    from .scene.io import load_scene
    from .scene.model import Scene
    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    hint = record_hint or f"{UPDATE_ENV}=1 (or pytest {UPDATE_OPTION})"
    out = check(scene, method, directory, size=size, metric=metric, tolerance=tolerance,
                update=update_requested() if update is None else update, name=name, options=options,
                record_hint=hint)
    if not out.ok:
        raise SnapshotMismatch(out.message)
    return out


class Snapshots:
    """What the ``snapshot`` fixture gives a test: :meth:`check` against ``directory``."""

    def __init__(self, directory: Path, update: bool):
        self.directory, self.update = Path(directory), update

    def check(self, scene, method: str, **kwargs):
        """:func:`assert_snapshot` in this test's snapshot folder; a mismatch fails the test
        with its one-line message (no traceback into the workbench)."""
        import pytest
        try:
            return assert_snapshot(scene, method, self.directory, update=self.update,
                                   record_hint=f"pytest {UPDATE_OPTION} (or {UPDATE_ENV}=1)", **kwargs)
        except SnapshotMismatch as e:
            pytest.fail(str(e), pytrace=False)


try:
    import pytest as _pytest
except ImportError:  # assert_snapshot works without pytest
    _pytest = None

if _pytest is not None:
    def pytest_addoption(parser):
        parser.getgroup("workbench").addoption(
            UPDATE_OPTION, action="store_true", default=False,
            help=f"record missing workbench snapshots and rewrite failing ones (or {UPDATE_ENV}=1)")

    @_pytest.fixture
    def snapshot(request) -> Snapshots:
        """Snapshot checks of rendered images, stored in ``snapshots/`` next to the test file."""
        update = bool(request.config.getoption(UPDATE_OPTION, default=False)) or update_requested()
        return Snapshots(Path(request.path).parent / "snapshots", update)
