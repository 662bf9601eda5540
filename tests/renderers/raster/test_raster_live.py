"""Live programs of the raster sessions (``RasterSession.update`` / ``settle``): while a material
or light slider moves, the edited values are drawn by programs that read them from uniforms
(``LIVE_MATERIAL`` / ``LIVE_LIGHTS``) instead of literals.  The image must be the literal
program's (a fresh session of the edited scene), a second edit must compile nothing, and
``settle`` must give back exactly the literal image."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import workbench
from workbench.core.imageio import to_srgb8
from workbench.renderers.raster import RasterSession
from workbench.scene.model import AREA_LIGHT_PREFIX, AreaLight, DirectionalLight, PointLight

pytestmark = pytest.mark.gl
MODES = ("flat", "gouraud", "phong")
SIZE = 96


def _edited(scene, k: int, materials=None, lights=True):
    """``scene`` with the values of ``materials`` (names; default: all) and of every point and
    directional light changed (step ``k`` of a drag)."""
    mats = dict(scene.materials)
    for name in (materials if materials is not None else list(mats)):
        m = mats[name]
        mats[name] = replace(m, ka=0.05 + 0.05 * k, kd=0.3 + 0.1 * k, ks=0.2 + 0.15 * k,
                             shininess=8.0 + 10.0 * k, kr=0.1 * k,
                             color=tuple(min(1.0, c * (0.7 + 0.1 * k)) for c in m.color))
    out = list(scene.lights)
    if lights:
        for i, light in enumerate(out):
            if isinstance(light, PointLight):
                out[i] = replace(light, position=tuple(np.asarray(light.position) + [0.4 * k, -0.2 * k, 0.3]),
                                 intensity=light.intensity * (0.8 + 0.2 * k), color=(1.0, 0.9, 0.8 - 0.1 * k))
            elif isinstance(light, DirectionalLight):
                out[i] = replace(light, direction=tuple(np.asarray(light.direction) + [0.1 * k, 0.0, 0.05]),
                                 intensity=light.intensity * (0.9 + 0.1 * k))
    return replace(scene, materials=mats, lights=tuple(out))


def _programs(session) -> list[str]:
    return [" ".join(k for k, _ in key[1]) for key in session.programs.programs]


@pytest.mark.parametrize("scene_name", ["globe", "whitted", "envmap"])
@pytest.mark.parametrize("mode", MODES)
def test_live_variant_draws_the_literal_image(gl_ctx, scene_name, mode):
    """globe: an image-textured and two checker materials, a directional and a point light;
    whitted: a procedural texture, two point lights; envmap: environment-mapped materials."""
    scene = workbench.load_scene(scene_name)
    cam = scene.camera.with_resolution(SIZE, SIZE)
    session = RasterSession(scene, mode)
    before = session.draw(cam)
    compiled = None
    for k in (1, 2, 3):
        edited = _edited(scene, k)
        assert session.update(edited)
        assert session.live and session.live_lights
        assert all(d.variant == (True, True) for d in session.draws)
        live = session.draw(cam)
        if compiled is None:
            compiled = session.programs.compiles  # the live programs, once
        assert session.programs.compiles == compiled, "a value edit compiled a program"
        literal = RasterSession(edited, mode).draw(cam)
        assert np.abs(literal - before).max() > 0.05  # the edit shows
        assert np.abs(live - literal).max() <= 1e-4  # float32 rounding (measured <= 4e-5)
        assert np.abs(to_srgb8(live).astype(int) - to_srgb8(literal).astype(int)).max() <= 1
    assert any("LIVE_MATERIAL" in p and "LIVE_LIGHTS" in p for p in _programs(session))
    steps = 0
    while True:  # one program per call, as the UI settles
        before_step = session.programs.compiles
        done = session.settle(budget=1)
        assert session.programs.compiles - before_step <= 1
        steps += 1
        if done:
            break
        session.draw(cam)
    assert steps >= 2 and not session.live
    assert np.array_equal(session.draw(cam), literal)  # the literal programs again, exactly
    used = {id(d.prog) for d in session.draws}
    literal_left = [p for key, p in session.programs.programs.items()
                    if key[0] == "raster" and not any(k.startswith("LIVE") for k, _ in key[1])]
    assert all(id(p) in used for p in literal_left)  # stale literal programs released
    session.release()


@pytest.mark.parametrize("mode", MODES)
def test_one_material_edit_keeps_the_other_draws_literal(gl_ctx, mode):
    scene = workbench.load_scene("globe")
    cam = scene.camera.with_resolution(SIZE, SIZE)
    name = next(n for n, m in scene.materials.items() if m.texture is not None and m.texture.kind == "image")
    session = RasterSession(scene, mode)
    for k in (1, 2):
        edited = _edited(scene, k, materials=[name], lights=False)
        assert session.update(edited)
        assert session.live_materials == {name} and not session.live_lights
        assert {d.variant for d in session.draws if d.name == name} == {(True, False)}
        assert {d.variant for d in session.draws if d.name != name} == {(False, False)}
        live = session.draw(cam)
        assert np.abs(live - RasterSession(edited, mode).draw(cam)).max() <= 1e-4


def test_many_stand_in_lights_and_blinn(gl_ctx):
    """cornell: area-light stand-ins (inverse square, cosine lobes); a material edit only (the
    area light itself is geometry: not a live edit)."""
    scene = workbench.load_scene("cornell")
    cam = scene.camera.with_resolution(SIZE, SIZE)
    name = list(scene.materials)[0]
    session = RasterSession(scene, "phong", blinn=True)
    edited = _edited(scene, 2, materials=[name], lights=False)
    assert session.update(edited)
    live = session.draw(cam)
    assert np.abs(live - RasterSession(edited, "phong", blinn=True).draw(cam)).max() <= 1e-4


def test_structural_changes_need_a_new_session(gl_ctx):
    scene = workbench.load_scene("cornell")
    session = RasterSession(scene, "gouraud")
    area = next(i for i, light in enumerate(scene.lights) if isinstance(light, AreaLight))
    lights = list(scene.lights)
    lights[area] = replace(lights[area], vertices=lights[area].vertices + [0.0, -0.1, 0.0])
    assert not session.update(replace(scene, lights=tuple(lights)))  # an emitter polygon moved
    assert not session.update(replace(scene, objects=scene.objects[:-1]))
    assert not session.update(replace(scene, ambient=(0.5, 0.5, 0.5)))
    name = list(scene.materials)[0]
    mats = {**scene.materials, name: replace(scene.materials[name], environment=True)}
    assert not session.update(replace(scene, materials=mats))
    assert session.scene is scene and not session.live  # nothing changed
    session.release()


@pytest.mark.parametrize("mode", MODES)
def test_area_light_colour_and_intensity_are_uniforms(gl_ctx, mode):
    """cornell's area light: its colour and intensity are values (its stand-ins' uniforms and
    its polygon's emission), not geometry.  Before: every edit of them (the UI's intensity
    drag) built a new session, 4-6 fps."""
    scene = workbench.load_scene("cornell")
    cam = scene.camera.with_resolution(SIZE, SIZE)
    area = next(i for i, light in enumerate(scene.lights) if isinstance(light, AreaLight))
    session = RasterSession(scene, mode)
    before = session.draw(cam)
    compiled = None
    for k in (1, 2, 3):
        lights = list(scene.lights)
        lights[area] = replace(lights[area], intensity=lights[area].intensity * (0.4 + 0.5 * k),
                               color=(1.0, 0.8, 0.5 + 0.1 * k))
        edited = replace(scene, lights=tuple(lights))
        assert session.update(edited)
        assert session.live_lights and session.live_areas == {f"{AREA_LIGHT_PREFIX}{area}"}
        live = session.draw(cam)
        if compiled is None:
            compiled = session.programs.compiles
        assert session.programs.compiles == compiled, "an intensity edit compiled a program"
        literal = RasterSession(edited, mode).draw(cam)
        assert np.abs(literal - before).max() > 0.05
        assert np.abs(live - literal).max() <= 1e-4
    while not session.settle(budget=1):
        session.draw(cam)
    assert np.array_equal(session.draw(cam), literal)
    session.release()
