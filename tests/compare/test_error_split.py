"""The error split (DESIGN "Ground truth and the error split"): each method's error against the
full reference (total) and against its matched reference (discretisation), the references'
own noise, the disk cache of references, and the Pareto front's zero-error points."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.compare import reference as R
from workbench.compare.study import pareto, study
from workbench.scene.io import load_scene


@pytest.mark.gl
def test_raster_curves_fall_against_their_matched_reference_on_whitted(tmp_path):
    """On Whitted's scene flat shading misses reflection, refraction and shadows: its total
    error stays high at every tessellation, while its error against the matched reference (the
    same local model ray-cast without shadows) falls with the tessellation.  Phong draws the
    stand-ins for them by default (renderers/raster_standins.py): its matched reference is the
    Whitted ray tracer at pixel centres, and its total error is far below flat's."""
    res = study(load_scene("whitted"), tmp_path, methods=["flat", "phong"], size=(64, 48), quick=True,
                repeat=1, progress=False)
    assert res["reference"]["method"] == "raytrace"
    pts = {m: [p for p in res["points"] if p["method"] == m and p["status"] == "ok"] for m in ("flat", "phong")}
    total = [p["rmse"] for p in pts["flat"]]
    matched = [p["rmse_matched"] for p in pts["flat"]]
    assert len(pts["flat"]) == 4 and all(p["matched_reference"].startswith("raycast") for p in pts["flat"])
    assert matched[-1] < 0.6 * matched[0], matched
    # the missing physics dominates: the total error hardly moves and stays far above
    assert min(total) > 2 * matched[-1] and max(total) - min(total) < matched[0] - matched[-1] + 0.02
    assert len(pts["phong"]) == 4 and all(p["matched_reference"].startswith("raytrace") for p in pts["phong"])
    assert max(p["rmse"] for p in pts["phong"]) < 0.5 * min(total), [p["rmse"] for p in pts["phong"]]
    js = (tmp_path / "study.json").read_text()
    assert "rmse_matched" in (tmp_path / "study.csv").read_text().splitlines()[0] and "matched_references" in js


def test_pareto_counts_zero_error_points():
    """A zero error is a point on the front (it was dropped before); a negative or non-finite
    one, or a non-positive time, is not."""
    times = [1.0, 2.0, 3.0, 0.5, 1.5]
    errors = [0.1, 0.0, 0.0, float("nan"), -1.0]
    assert pareto(times, errors) == [True, True, False, False, False]


def test_display_noise_of_clipped_and_noisy_pixels():
    img = np.array([[[5.0, 0.5, 0.5]]])
    se = np.array([[[0.5, 0.1, 3.0]]])
    # the 5.0 channel is clipped whatever its noise; the others count min(se, 1)
    assert R.display_noise(se, img) == pytest.approx(np.sqrt((0.0 + 0.01 + 1.0) / 3))
    assert R.display_noise(None, img) == 0.0


def test_matched_specs_name_existing_options():
    """Every matched reference names a registered method and only options it accepts (a
    missing mode gives None, never a render with an unknown option)."""
    from workbench.renderers.base import available, get_renderer
    for method in available():
        spec = R.matched_spec(method)
        if spec is None:
            assert method in R.OUTSIDE or method not in R.MATCHED or R.MATCHED[method][0] in available()
            continue
        m, opts, what = spec
        assert m in available() and set(opts) <= set(get_renderer(m).options) and what
    assert R.matched_spec("glsl:anything.glsl") is None and "user" in R.matched_reason("glsl:x.glsl")


@pytest.mark.gl
def test_emitter_scene_reference_is_the_converged_path_tracer_and_is_cached(tmp_path):
    scene = load_scene("cornell")
    a = R.choose_reference(scene, 24, 24)
    assert a.method == "pathtrace" and a.run.status == "ok"
    # sampled until the target noise or the budget: the noise is stated either way
    assert 0 < a.noise and (a.noise <= R.TARGET_NOISE or a.options["spp"] > R.PILOT_SPP)
    assert a.options["spp"] >= R.PILOT_SPP and np.isfinite(a.image).all()
    b = R.choose_reference(scene, 24, 24)
    assert b.run.result.stats["cache"] == "hit" and np.array_equal(a.image, b.image)
    assert b.describe()["noise_rmse"] == pytest.approx(a.noise)


def test_matched_reference_follows_the_stand_ins_a_run_draws():
    """Phong's matched reference on whitted (reflection, refraction, shadows): the Whitted tracer
    with its default stand-ins, the bare local model's ray caster with ``standins=off``, the ray
    caster with shadows when only shadow maps are drawn."""
    whitted = load_scene("whitted")
    assert R.matched_spec("phong", whitted)[0] == "raytrace"
    assert R.matched_spec("phong", whitted, {"standins": "envmap"})[0] == "raytrace"
    assert R.matched_spec("phong", whitted, {"standins": "off"}) == R.matched_spec("phong")
    bare = R.matched_spec("phong")
    assert bare[0] == "raycast" and bare[1].get("shadows") is False
    shadows = R.matched_spec("gouraud", whitted, {"standins": "shadows"})
    assert shadows[0] == "raycast" and shadows[1]["shadows"] is True
    assert R.matched_spec("flat", whitted, {"standins": "on"}) == R.matched_spec("flat")
