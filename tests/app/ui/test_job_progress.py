"""Every long job of the window says how far it is (issue #29, item 2): the hybrid's job
reports the rows of its ray-tracing pass like the ray tracer's, and a job that has reported
nothing yet, or whose method reports nothing (POV-Ray, Mitsuba: one piece in a child
process), shows its elapsed time and says which."""
from __future__ import annotations

from workbench.app.ui.jobs import JobBoard
from workbench.app.ui.panel_refresh import tiled, waiting_text
from workbench.scene.io import load_scene
from workbench.scene.library import resolve


def test_the_hybrid_job_reports_the_rows_of_its_ray_trace():
    scene = load_scene(resolve("cornell"))
    cam = scene.camera.with_resolution(16, 12)
    board = JobBoard()
    try:
        assert tiled("hybrid") and tiled("raytrace")
        job = board.request(scene, cam, "hybrid", {"patch_size": 0.5}, tiled=tiled("hybrid"))
        assert waiting_text("hybrid", job).endswith("elapsed, no rows yet") or job.meter.first
        job.thread.join(600)
        assert job.done and job.error is None
        assert job.meter.unit == "rows" and job.meter.done == cam.height and job.meter.fraction == 1.0
    finally:
        board.keep_only([])


def test_a_method_without_progress_says_so_with_its_elapsed_time():
    assert not tiled("povray") and not tiled("mitsuba")

    class Silent:  # what waiting_text reads of a job whose method reports nothing
        meter = None
        begun = 0.0

    text = waiting_text("povray", Silent())
    assert text.startswith("rendering, ") and "elapsed (povray reports no progress" in text
