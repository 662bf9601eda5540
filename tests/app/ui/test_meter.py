"""The long jobs' meter (:mod:`workbench.app.ui.meter`): fraction, text and time left."""
from __future__ import annotations

import pytest

from workbench.app.ui.meter import Meter, clock_text


def test_time_left_extrapolates_the_rate_since_the_first_report():
    m = Meter("spp", 256)
    m.update(32, now=100.0)  # after a long set-up (compile): not part of the rate
    assert m.seconds_left() is None and m.text() == "32/256 spp"
    m.update(96, detail="noise 0.03", now=110.0)  # 64 spp in 10 s: 160 spp left take 25 s
    assert m.fraction == pytest.approx(96 / 256)
    assert m.seconds_left() == pytest.approx(25.0)
    assert m.text() == "96/256 spp, noise 0.03, 0:25 left"
    m.update(256, now=135.0)
    assert m.fraction == 1.0 and m.text() == "256/256 spp"


def test_a_meter_without_target_takes_the_jobs_fraction():
    m = Meter("shots")
    m.update(16, 0.2, "unshot 40 %", now=0.0)
    m.update(48, 0.6, "unshot 9 %", now=4.0)  # 0.4 in 4 s: 0.4 left take 4 s
    assert m.seconds_left() == pytest.approx(4.0)
    assert m.text() == "48 shots, unshot 9 %, 0:04 left"
    m.update(64, 1.7, now=5.0)
    assert m.fraction == 1.0


def test_a_phase_not_measured_shows_the_time_elapsed_and_an_indeterminate_bar():
    m = Meter("", None, phase="radiosity solve (direct: no progress reported)", started=10.0)
    m.update(0, now=10.5)
    assert not m.measured and m.bar(3.0) == -3.0  # imgui's moving indeterminate bar
    assert m.seconds_left() is None
    assert m.text(now=75.0) == "radiosity solve (direct: no progress reported): 1:05 elapsed"
    shots = Meter("shots", None, phase="radiosity shooting", started=0.0)
    shots.update(48, now=4.0)
    assert not shots.measured and shots.text(now=4.0) == "radiosity shooting: 48 shots, 0:04 elapsed"


def test_a_measured_phase_shows_the_time_elapsed_until_its_rate_is_known():
    m = Meter("rows", 64, phase="ray trace", started=0.0)
    m.update(0, now=1.0)
    assert m.measured and m.text(now=2.0) == "ray trace: 0/64 rows, 0:02 elapsed"
    m.update(32, now=3.0)  # half the rows in 2 s: 2 s left
    assert m.bar(9.0) == 0.5 and m.text() == "ray trace: 32/64 rows, 0:02 left"
    m.update(64, now=5.0)
    assert m.text(now=6.0) == "ray trace: 64/64 rows"


def test_clock_text():
    assert clock_text(0.6) == "0:01" and clock_text(0.4) == "0:00" and clock_text(75) == "1:15" and clock_text(3725) == "1:02:05"
