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


def test_clock_text():
    assert clock_text(0.6) == "0:01" and clock_text(0.4) == "0:00" and clock_text(75) == "1:15" and clock_text(3725) == "1:02:05"
