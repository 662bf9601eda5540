"""``workbench compare``: the report's files exist and parse, its numbers are those of the saved
images, methods that do not apply or fail are listed, and a failed write leaves nothing half done."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

import compare_fakes
from workbench.compare import report as report_mod
from workbench.compare.metrics import metrics


def _check_numbers(out, rep):
    """Every method's metrics in report.json equal a recomputation from the saved .npy files."""
    ref = np.load(out / rep["reference"]["files"]["npy"])
    checked = 0
    for e in rep["methods"]:
        if e["status"] != "ok":
            continue
        img = np.load(out / e["files"]["npy"])
        again = metrics(img, ref)
        assert e["metrics"]["rmse"] == pytest.approx(again["rmse"], rel=1e-9, abs=1e-12)
        assert e["metrics"]["flip"] == pytest.approx(again["flip"], rel=1e-6, abs=1e-9)
        psnr = e["metrics"]["psnr"]
        assert (psnr == "inf" and again["psnr"] == np.inf) or psnr == pytest.approx(again["psnr"], rel=1e-9)
        checked += 1
    return checked


def test_report_files_parse_and_numbers_match_saved_images(tmp_path, monkeypatch):
    compare_fakes.install(monkeypatch)
    out = tmp_path / "rep"
    rep = report_mod.compare(compare_fakes.sphere_scene(), out, size=(48, 36), repeat=1)
    on_disk = json.loads((out / "report.json").read_text())  # strict JSON (no NaN tokens)
    assert on_disk["methods"] == rep["methods"]
    assert _check_numbers(out, on_disk) == 1
    # the fake's facets make a real error; the reference is the fake at its finest knob value
    facets = next(e for e in on_disk["methods"] if e["method"] == "facets")
    assert on_disk["reference"]["method"] == "facets" and on_disk["reference"]["options"] == {"n": 64}
    assert facets["metrics"]["rmse"] > 1e-3
    assert facets["left_out"] == ["shadows: not computed by this fake"]
    assert facets["compile_s"] >= 0 and len(facets["warm_s"]) == 1
    # a method that does not apply is listed with its reason, not dropped
    never = next(e for e in on_disk["methods"] if e["method"] == "never")
    assert never["status"] == "not_applicable" and "applies to no scene" in never["reason"]
    from PIL import Image
    for rel in ("grid.png", facets["files"]["heat_flip"], facets["files"]["heat_abs"], facets["files"]["png"]):
        with Image.open(out / rel) as im:
            assert im.size[0] >= 48
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == 3  # grid + 2 heat maps and "applies to no scene" in html
    assert "shadows: not computed by this fake" in html and "facets" in html
    assert not list(out.glob(".staging-*"))
    assert on_disk["machine"]["cpu_count"] >= 1 and "GL_RENDERER" in on_disk["machine"]


class Broken:
    name = "broken"
    knob = compare_fakes.Facets.knob
    options = compare_fakes.Facets.options
    memory_options = compare_fakes.Facets.memory_options
    estimate_bytes = compare_fakes.Facets.estimate_bytes

    def render(self, scene, width, height, n=8):
        raise RuntimeError("kaboom")


def test_a_failing_method_is_reported_and_a_failed_write_leaves_the_old_report(tmp_path, monkeypatch):
    compare_fakes.install(monkeypatch, {"broken": "test_compare_report:Broken"})
    out = tmp_path / "rep"
    rep = report_mod.compare(compare_fakes.sphere_scene(), out, size=(48, 36), repeat=0)
    broken = next(e for e in rep["methods"] if e["method"] == "broken")
    assert broken["status"] == "failed" and "kaboom" in broken["reason"]
    before = (out / "report.json").read_text()

    def boom(*a, **k):
        raise OSError("disk full")
    monkeypatch.setattr(report_mod.figures, "grid", boom)
    with pytest.raises(OSError):
        report_mod.compare(compare_fakes.sphere_scene(), out, size=(48, 36), repeat=0)
    assert (out / "report.json").read_text() == before
    assert not list(out.glob(".staging-*"))


def test_unknown_method_is_a_clear_cli_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "workbench.app.cli", "compare", "whitted", "--methods", "phong,nope",
                        "--out", str(tmp_path / "o")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "unknown method(s) nope" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o" / "report.json").exists()


@pytest.mark.gl
def test_real_methods_against_the_ray_tracer(tmp_path):
    out = tmp_path / "rep"
    rep = report_mod.compare(compare_fakes.sphere_scene(), out, methods=["flat", "phong", "raytrace"],
                             size=(48, 36), repeat=0)
    assert rep["reference"]["method"] == "raytrace"  # the rule: no emitters, ray tracer registered
    assert _check_numbers(out, rep) == 3
    m = {e["method"]: e["metrics"]["rmse"] for e in rep["methods"]}
    assert m["raytrace"] < m["phong"] < m["flat"]  # same local model; flat is the coarsest
    # the reference is the box-filtered image (16 stratified samples): the ray tracer's
    # pixel-centre image differs only at edges, and equals its matched reference (pixel centres)
    assert rep["reference"]["options"]["spp"] == 16 and 0 < m["raytrace"] < 0.05
    matched = {e["method"]: e["matched"] for e in rep["methods"]}
    assert matched["raytrace"]["metrics"]["rmse"] == 0.0
    assert matched["phong"]["reference"]["options"] == {"shadows": False, "spp": 1}
    assert rep["reference"]["noise_rmse"] > 0 and "samples per pixel" in rep["reference"]["noise_note"]
