"""``workbench study`` on a scene with hypertextures: a method that declares ``step_scale`` (the
ray marchers) or ``volume_resolution`` (the raster's 3D texture) is swept along it instead of
its knob (the texture's resolution first when it has both), and its references take the finest
values; a method without either keeps its knob.
The renderers here are stubs declaring those options, so the test holds whether or not the
real methods have them yet."""
from __future__ import annotations

import numpy as np

import compare_fakes
import workbench
from workbench.compare.reference import MEDIUM_KNOBS, finest_options
from workbench.compare.study import study, study_plan
from workbench.renderers import base
from workbench.renderers.base import Knob, Option, RenderResult
from workbench.renderers.support import declare


class Stub:
    """A method with a knob and, optionally, medium options; renders a grey image whose level is
    the step multiplier (or else the texture resolution), so that each point differs."""

    support = declare()
    memory_options = ()

    def __init__(self, name: str, knob: Knob, extra: dict[str, Option]):
        self.name, self.knob = name, knob
        self.options = {knob.name: Option(type(knob.default), knob.default, "knob"), **extra}

    def estimate_bytes(self, scene, width, height, **opts):
        return 1

    def render(self, scene, width, height, **opts):
        level = float(opts.get("step_scale", opts.get("volume_resolution", 1.0)))
        return RenderResult(self.name, np.full((height, width, 3), 0.01 * level, np.float32),
                            timings={"compile": 0.0}, stats={}, features_used=[], left_out=[])


def _install(monkeypatch):
    stubs = [Stub("marcher", Knob("spp", (1, 2, 4), 1), {"step_scale": Option(float, 1.0, "march step x")}),
             Stub("texturer", Knob("tessellation", (1, 2, 4), 2), {"volume_resolution": Option(int, 64, "3D texture"),
                                                                  "step_scale": Option(float, 1.0, "march step x")}),
             Stub("plain", Knob("spp", (2, 4, 16), 4), {})]
    compare_fakes.install(monkeypatch, {s.name: "compare_fakes:Facets" for s in stubs})
    for s in stubs:
        base._instances[s.name] = s
    return [s.name for s in stubs]


def _sweeps(plan):
    out = {}
    for m, option, value, why in plan:
        assert why == ""
        out.setdefault(m, (option, []))[1].append(value)
    return {m: (o, tuple(v)) for m, (o, v) in out.items()}


def test_hypertexture_scene_sweeps_the_declared_medium_options(monkeypatch):
    names = _install(monkeypatch)
    fire = workbench.load_scene("fire")
    media = dict(MEDIUM_KNOBS)
    got = _sweeps(study_plan(fire, names, {}, quick=False))
    assert got == {"marcher": ("step_scale", media["step_scale"]),
                   "texturer": ("volume_resolution", media["volume_resolution"]),
                   "plain": ("spp", (2, 4, 16))}
    assert media["step_scale"][0] > media["step_scale"][-1]          # cheapest (coarsest step) first
    assert media["volume_resolution"][0] < media["volume_resolution"][-1]
    quick = _sweeps(study_plan(fire, names, {}, quick=True))["marcher"][1]
    assert len(quick) == 4 and quick[0] == 4.0 and quick[-1] == 0.25
    # a given --sweep wins; a scene without a medium keeps the knobs
    assert _sweeps(study_plan(fire, ["marcher"], {"marcher": ("spp", ["1", "2"])}, False)) == \
        {"marcher": ("spp", ("1", "2"))}
    ball = compare_fakes.sphere_scene()
    assert _sweeps(study_plan(ball, names, {}, False)) == {
        "marcher": ("spp", (1, 2, 4)), "texturer": ("tessellation", (1, 2, 4)), "plain": ("spp", (2, 4, 16))}


def test_references_take_the_finest_medium_setting(monkeypatch):
    _install(monkeypatch)
    fire, ball = workbench.load_scene("fire"), compare_fakes.sphere_scene()
    assert finest_options("marcher", fire) == {"spp": 4, "step_scale": 0.25}
    assert finest_options("texturer", fire) == {"tessellation": 4, "volume_resolution": 128, "step_scale": 0.25}
    assert finest_options("marcher", ball) == finest_options("marcher") == {"spp": 4}


def test_study_of_a_hypertexture_scene_records_the_step(monkeypatch, tmp_path):
    _install(monkeypatch)
    fire = workbench.load_scene("fire")
    ref = np.zeros((12, 16, 3), np.float32)
    res = study(fire, tmp_path / "st", methods=["marcher", "plain"], reference_image=(ref, "black"),
                repeat=1, progress=False)
    pts = [(p["method"], p["knob"], p["value"], p["status"]) for p in res["points"]]
    assert [p[:3] for p in pts if p[0] == "marcher"] == [("marcher", "step_scale", v) for v in (4.0, 2.0, 1.0, 0.5, 0.25)]
    assert {p[1] for p in pts if p[0] == "plain"} == {"spp"}
    assert all(p[3] == "ok" for p in pts), pts
    rmse = [p["rmse"] for p in res["points"] if p["method"] == "marcher"]
    assert np.allclose(rmse, [0.04, 0.02, 0.01, 0.005, 0.0025], rtol=1e-5)   # the stub's level 0.01 x step_scale
