"""Radiosity's ``on_pass``: each round of progressive refinement's shots (Cohen et al. 1988)
reported with its image, the unshot share of the emitted power and the way done to the
stopping rule (what the window shows as the rounds land)."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.renderers.radiosity.solvers import shooting_progress, unshot_fraction

pytestmark = pytest.mark.gl


def test_unshot_fraction_is_the_area_weighted_unshot_power_over_the_emitted():
    areas = np.array([2.0, 1.0, 1.0])
    E = np.array([[1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert unshot_fraction(E, E, areas) == 1.0
    # after shots: the emitter shot everything, the receivers hold unshot radiosity of both signs
    dB = np.array([[0.0, 0.0, 0.0], [0.3, 0.3, 0.3], [-0.1, 0.0, 0.1]])
    assert unshot_fraction(dB, E, areas) == pytest.approx((0.9 + 0.2) / 6.0)
    assert unshot_fraction(dB, np.zeros_like(E), areas) == 0.0


def test_shooting_progress_runs_from_0_to_1_in_log_scale():
    B = np.ones((2, 3))
    assert shooting_progress(B, B.copy(), 1e-4) == 0.0
    assert shooting_progress(B, 1e-2 * B, 1e-4) == pytest.approx(0.5)
    assert shooting_progress(B, 1e-5 * B, 1e-4) == 1.0


def test_each_round_is_reported_and_the_last_is_the_image(gl_ctx):
    scene = workbench.load_scene("cornell")
    rounds = []

    def on_pass(shots, image, unshot, progress):
        assert image.shape == (24, 24, 3) and np.isfinite(image).all()
        rounds.append((shots, image.copy(), unshot, progress))

    r = workbench.render(scene, "radiosity", width=24, height=24, patch_size=0.1,
                         solver="progressive", on_pass=on_pass, pass_seconds=0.0)
    assert len(rounds) >= 3
    shots, _, unshot, progress = map(list, zip(*[(s, None, u, p) for s, _, u, p in rounds]))
    assert shots == sorted(set(shots)) and shots[-1] == r.stats["iterations"]
    assert unshot[0] > 0.3 and unshot[-1] < 0.1 * unshot[0]
    assert progress[-1] == 1.0 and progress[0] < 0.5
    assert np.array_equal(rounds[-1][1], r.image)  # the last round shows the final image
    assert np.abs(rounds[0][1] - r.image).max() > 1e-2
    # another solver never calls it
    workbench.render(scene, "radiosity", width=24, height=24, patch_size=0.1, solver="direct",
                     on_pass=lambda *a: pytest.fail("on_pass called by the direct solver"))


def test_rounds_closer_than_pass_seconds_are_not_drawn_but_the_last_is_reported(gl_ctx):
    scene = workbench.load_scene("cornell")
    rounds = []
    r = workbench.render(scene, "radiosity", width=24, height=24, patch_size=0.1,
                         solver="progressive", pass_seconds=1e9,
                         on_pass=lambda shots, image, unshot, progress: rounds.append((shots, image)))
    # the first round (nothing shown yet) and, though within the interval, the last one
    assert len(rounds) == 2 and rounds[0][0] < rounds[1][0] == r.stats["iterations"]
    assert np.array_equal(rounds[1][1], r.image)
