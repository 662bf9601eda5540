"""Every long job of the window says how far it is (issue #29, item 2): the hybrid's job ends
with the rows of its ray-tracing pass all reported, and a job that has reported nothing yet
shows its elapsed time (and, when its method has no way to report progress, says so)."""
from __future__ import annotations

import time

from workbench.app.ui.jobs import JobBoard
from workbench.app.ui.panel_refresh import tiled, waiting_text
from workbench.scene.io import load_scene
from workbench.scene.library import resolve


def test_the_hybrid_job_reports_the_rows_of_its_ray_trace():
    scene = load_scene(resolve("cornell"))
    cam = scene.camera.with_resolution(16, 12)
    board = JobBoard()
    try:
        job = board.request(scene, cam, "hybrid", {"patch_size": 0.5}, tiled=tiled("hybrid"))
        job.thread.join(600)
        assert job.done and job.error is None
        assert job.meter.unit == "rows" and job.meter.done == cam.height and job.meter.fraction == 1.0
    finally:
        board.keep_only([])


def test_a_job_without_a_report_shows_its_elapsed_time():
    class Job:  # what waiting_text reads of a job
        meter = None
        begun = time.perf_counter() - 75.0

    assert waiting_text("zbuffer", Job()) == "rendering, 1:15 elapsed (zbuffer reports no progress)"
    Job.meter = object()
    assert waiting_text("raytrace", Job()) == "rendering, 1:15 elapsed"
