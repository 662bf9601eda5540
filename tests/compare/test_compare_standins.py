"""The comparison report shows by how much each raster stand-in reduces the error (issue 15,
item 4): the run rendered again with none, then adding them one at a time."""
from __future__ import annotations

import numpy as np

import workbench
from workbench.compare.metrics import metrics
from workbench.compare.report import compare


def test_report_ladder_of_the_stand_ins(tmp_path):
    scene = workbench.load_scene("whitted")
    rep = compare(scene, tmp_path / "c", methods=["flat", "phong"], size=(64, 48), repeat=0)
    by = {e["method"]: e for e in rep["methods"]}
    assert "standins_ladder" not in by["flat"]                       # flat draws no stand-in
    ladder = by["phong"]["standins_ladder"]
    assert [s["standins"] for s in ladder] == ["off", "envmap", "envmap,blend", "envmap,blend,shadows"]
    assert np.isclose(ladder[-1]["rmse"], by["phong"]["metrics"]["rmse"])  # the last step is the run
    ref = np.load(tmp_path / "c" / "images" / "reference.npy")
    bare = workbench.render(scene, "phong", width=64, height=48, standins="off").image
    assert np.isclose(ladder[0]["rmse"], metrics(bare, ref)["rmse"])
    assert ladder[-1]["rmse"] < 0.6 * ladder[0]["rmse"]             # on whitted they halve it
    html = (tmp_path / "c" / "report.html").read_text()
    assert "Stand-ins: how much each reduces the error" in html and "envmap,blend" in html


def test_no_ladder_without_stand_ins_drawn():
    from workbench.compare.report import _standin_ladder
    from workbench.compare.runs import timed_run
    scene = workbench.load_scene("whitted")
    ref = np.zeros((24, 32, 3), np.float32)
    off = timed_run(scene, "phong", 32, 24, options={"standins": "off"})
    assert off.status == "ok" and _standin_ladder(scene, off, 32, 24, ref) == []
    subset = timed_run(scene, "phong", 32, 24, options={"standins": "shadows,envmap"})
    assert [s["standins"] for s in _standin_ladder(scene, subset, 32, 24, ref)] == ["off", "envmap", "envmap,shadows"]
