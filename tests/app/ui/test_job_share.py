"""Job boards sharing a request (issue #29, item 2: no job renders what is already rendered):
the error plot's reference board takes the panel's job of the same request, and the panel
moving on to another request leaves that job running for the reference instead of cancelling
it (the reference would start again from nothing)."""
from __future__ import annotations

import threading

import numpy as np
import pytest

from workbench.app.ui.jobs import JobBoard
from workbench.renderers import base, registry
from workbench.scene.io import load_scene
from workbench.scene.library import resolve


class Gate:
    """A CPU method whose render waits for the test (``release``) and counts its renders."""

    name = "gate"
    ui_kind = "cpu"
    knob = base.Knob("level", (1, 2), 1)
    options = {"level": base.Option(int, 1)}
    memory_options = ()
    release = threading.Event()
    renders: list = []

    def estimate_bytes(self, scene, width, height, **options):
        return 64 * width * height + 1

    def render(self, scene, width, height, level=1):
        self.renders.append(level)
        assert self.release.wait(60)
        return base.RenderResult(self.name, np.full((height, width, 3), 0.1 * level, np.float32))


@pytest.fixture
def gate(monkeypatch):
    monkeypatch.setitem(registry.BUILTIN, "gate", f"{__name__}:Gate")
    monkeypatch.setattr(Gate, "release", threading.Event())
    monkeypatch.setattr(Gate, "renders", [])
    yield Gate
    Gate.release.set()
    base._instances.pop("gate", None)


def test_a_shared_job_runs_on_for_the_reference_when_the_panel_moves_on(gate):
    scene = load_scene(resolve("whitted"))
    cam = scene.camera.with_resolution(8, 6)
    panels, refs = JobBoard(), JobBoard(cached=True, share=None)
    refs.share = panels
    try:
        mine = panels.request(scene, cam, "gate", {"level": 2}, tiled=False)
        theirs = refs.request(scene, cam, "gate", {"level": 2}, tiled=False)
        assert theirs is mine and refs.count == 0  # shared, no second render
        other = panels.request(scene, cam, "gate", {"level": 1}, tiled=False)
        assert other is not mine and not mine.cancelled.is_set()  # left running for refs
        panels.keep_only([])  # the panel removed: its own job goes, not the shared one
        assert other.cancelled.is_set() and not mine.cancelled.is_set()
        gate.release.set()
        mine.thread.join(30)
        other.thread.join(30)  # its render may not have begun yet: counted once it has ended
        assert refs.request(scene, cam, "gate", {"level": 2}, tiled=False) is mine
        assert np.all(mine.image == np.float32(0.2)) and sorted(gate.renders) == [1, 2]
    finally:
        gate.release.set()
        panels.join_all(30)
        refs.join_all(30)


def test_a_job_only_one_board_holds_is_cancelled_when_it_moves_on(gate):
    scene = load_scene(resolve("whitted"))
    cam = scene.camera.with_resolution(8, 6)
    panels = JobBoard()
    try:
        first = panels.request(scene, cam, "gate", {"level": 2}, tiled=False)
        panels.request(scene, cam, "gate", {"level": 1}, tiled=False)
        assert first.cancelled.is_set()
    finally:
        gate.release.set()
        panels.join_all(30)


def test_a_panel_takes_the_reference_job_that_started_first(gate):
    """Issue #29: the reference could take a panel's job, but a panel asking for the request
    the reference was already rendering started it again (two renders of one image)."""
    scene = load_scene(resolve("whitted"))
    cam = scene.camera.with_resolution(8, 6)
    refs = JobBoard(cached=True)
    woken = []
    panels = JobBoard(notify=lambda: woken.append(1), share=lambda: [refs])
    refs.share = panels
    try:
        theirs = refs.request(scene, cam, "gate", {"level": 2}, tiled=False)
        mine = panels.request(scene, cam, "gate", {"level": 2}, tiled=False)
        assert mine is theirs and panels.count == 0 and refs.count == 1  # taken, not started
        assert panels.busy() and panels.current["gate"] is theirs
        # the reference moving on (the camera moved for it only) leaves the panel's job running
        moved = refs.request(scene, cam, "gate", {"level": 1}, tiled=False)
        assert moved is not mine and not mine.cancelled.is_set()
        gate.release.set()
        mine.thread.join(30)
        moved.thread.join(30)
        assert np.all(mine.image == np.float32(0.2)) and woken  # the panel's window was woken
        assert panels.request(scene, cam, "gate", {"level": 2}, tiled=False) is mine
        assert sorted(gate.renders) == [1, 2]  # level 2 rendered once, for both boards
    finally:
        gate.release.set()
        panels.join_all(30)
        refs.join_all(30)


def test_a_panel_does_not_take_a_cancelled_reference_job(gate):
    scene = load_scene(resolve("whitted"))
    cam = scene.camera.with_resolution(8, 6)
    refs = JobBoard(cached=True)
    panels = JobBoard(share=lambda: [refs])
    try:
        theirs = refs.request(scene, cam, "gate", {"level": 2}, tiled=False)
        theirs.cancelled.set()  # the plot's key changed: it is ending
        mine = panels.request(scene, cam, "gate", {"level": 2}, tiled=False)
        assert mine is not theirs and panels.count == 1
    finally:
        gate.release.set()
        panels.join_all(30)
        refs.join_all(30)
