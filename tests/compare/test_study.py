"""``workbench study``: error falls monotonically along knobs where theory says it must, the
Pareto front is exactly the non-dominated set, and the CSV / JSON / plot agree."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import compare_fakes
from workbench.compare.analytic import sphere_image
from workbench.compare.study import pareto, study, sweep_values
from workbench.renderers.base import available


def _errors(res, method, key="rmse"):
    pts = [p for p in res["points"] if p["method"] == method]
    assert all(p["status"] == "ok" for p in pts), pts
    return [p["value"] for p in pts], [p[key] for p in pts]


def test_fake_facets_error_falls_with_n_and_files_agree(tmp_path, monkeypatch):
    """Flat facets of angular size pi/n: the shading error must fall as n grows."""
    compare_fakes.install(monkeypatch)
    scene = compare_fakes.sphere_scene()
    out = tmp_path / "st"
    res = study(scene, out, reference_image=(sphere_image(scene), "analytic sphere"), repeat=2, progress=False)
    values, rmse = _errors(res, "facets")
    assert values == [4, 8, 16, 32, 64]
    assert all(b < a for a, b in zip(rmse, rmse[1:])), rmse
    never = [p for p in res["points"] if p["method"] == "never"]
    assert never and all(p["status"] == "not_applicable" for p in never)
    # CSV and JSON hold the same numbers; the plot exists
    rows = list(csv.DictReader((out / "study.csv").open()))
    js = json.loads((out / "study.json").read_text())
    assert len(rows) == len(js["points"]) == len(res["points"])
    for row, p in zip(rows, js["points"]):
        if p["status"] == "ok":
            assert float(row["rmse"]) == pytest.approx(p["rmse"], rel=1e-12)
            assert float(row["time_s"]) == pytest.approx(np.median(p["warm_s"]), rel=1e-12)
            assert len(p["warm_s"]) == 2
    from PIL import Image
    with Image.open(out / "study.png") as im:
        assert im.size[0] > 400
    html = (out / "study.html").read_text()
    assert "data:image/png;base64," in html and "shadows: not computed by this fake" in html


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(1e-4, 10.0), st.floats(1e-6, 1.0)), min_size=1, max_size=25))
def test_pareto_front_is_exactly_the_non_dominated_points(pts):
    t, e = [p[0] for p in pts], [p[1] for p in pts]
    front = pareto(t, e)
    for i in range(len(pts)):
        dominated = any(t[j] <= t[i] and e[j] <= e[i] and (t[j] < t[i] or e[j] < e[i]) for j in range(len(pts)))
        assert front[i] == (not dominated)
    assert any(front)  # the fastest of the most accurate is always on it


def test_quick_sweep_keeps_both_ends():
    assert sweep_values((1, 2, 3, 4, 6, 8, 12, 16, 24, 32), quick=True) == [1, 4, 12, 32]
    assert sweep_values((1, 2, 3), quick=True) == [1, 2, 3]


@pytest.mark.gl
def test_phong_error_falls_with_tessellation_on_a_sphere(tmp_path):
    """Phong on a finer tessellation converges to the analytic sphere (same local model)."""
    scene = compare_fakes.sphere_scene()
    res = study(scene, tmp_path, methods=["phong"], reference_image=(sphere_image(scene), "analytic sphere"),
                repeat=1, sweeps={"phong": ("tessellation", [1, 2, 4, 8, 16, 32])}, progress=False)
    _, rmse = _errors(res, "phong")
    assert all(b < a for a, b in zip(rmse, rmse[1:])), rmse
    assert rmse[-1] < 0.01 * rmse[0]


@pytest.mark.gl
def test_radiosity_error_falls_with_hemicube_resolution_on_parallel_squares(tmp_path):
    """Two parallel squares (an emitter over a receiver): the hemicube's delta form factors
    converge as the resolution grows (errata 6), so the image error must fall."""
    from workbench.renderers.base import render
    from workbench.scene.io import scene_from_dict
    scene = scene_from_dict({
        "scene": {"name": "squares", "background": [0, 0, 0], "ambient": [0, 0, 0]},
        "camera": {"position": [0.5, 0.9, -1.2], "look_at": [0.5, 0.3, 0.5], "fov_y": 50, "resolution": [48, 36]},
        "materials": {"lamp": {"color": [1, 1, 1], "kd": 0.0, "ka": 0.0, "emission": [1, 1, 1]},
                      "white": {"color": [1, 1, 1], "kd": 0.8, "ka": 0.0}},
        "objects": [
            {"type": "polygon", "name": "lamp", "material": "lamp", "vertices": [[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]]},
            {"type": "polygon", "name": "floor", "material": "white", "vertices": [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]}]})
    ref = render(scene, "radiosity", hemicube_resolution=256).image
    res = study(scene, tmp_path, methods=["radiosity"], reference_image=(ref, "hemicube 256"), repeat=1,
                sweeps={"radiosity": ("hemicube_resolution", [4, 8, 16, 32])}, progress=False)
    _, rmse = _errors(res, "radiosity")
    assert all(b < a for a, b in zip(rmse, rmse[1:])), rmse


def test_parallel_error_evaluation_gives_the_same_numbers():
    from workbench.compare.study import evaluate
    rng = np.random.default_rng(1)
    ref = rng.random((24, 32, 3)).astype(np.float32)
    images = [np.clip(ref + s * rng.standard_normal(ref.shape), 0, 1).astype(np.float32) for s in (0.01, 0.1, 0.3)]
    assert evaluate(images, ref, jobs=2) == evaluate(images, ref, jobs=1)


def test_reference_rule_order():
    """Emitters first go to the path tracer (ground truth), otherwise the Whitted ray tracer."""
    from workbench.compare.reference import candidates
    from workbench.scene.io import load_scene
    regs = set(available())
    cornell = [m for m, _ in candidates(load_scene("cornell"))]
    whitted = [m for m, _ in candidates(load_scene("whitted"))]
    assert {"pathtrace", "raytrace"} <= regs    # an unregistered method fails here
    assert cornell[0] == "pathtrace"
    assert whitted[0] == "raytrace"
    assert set(whitted) <= regs and set(cornell) <= regs
