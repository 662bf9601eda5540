"""Every object kind can be an emitter in the path tracer: an emissive object of each kind
renders (no IndexError from the emitter table, no NaN), its pixels show its emission, and
``workbench compare`` (which renders the path-traced reference) runs on such a scene."""
from __future__ import annotations

import dataclasses
import subprocess

import numpy as np
import pytest

import workbench
from ui_command import WORKBENCH
from workbench.scene.io import load_scene
from workbench.scene.kinds import KINDS, kind_of

GLOW = (2.0, 2.0, 2.0)


def _glowing(kind: str):
    """The first bundled scene with an object of ``kind`` (a box, which none has, added to
    whitted's at its camera's target), every material made emissive (CSG leaves included)."""
    from workbench.scene import model as m
    from workbench.scene.library import bundled
    if kind == "box":
        scene = load_scene("whitted")
        c = np.asarray(scene.camera.look_at, float)
        box = m.Box(material=next(iter(scene.materials)), min=tuple(c - 0.3), max=tuple(c + 0.3))
        scene = dataclasses.replace(scene, objects=type(scene.objects)([*scene.objects, box]))
    else:
        scene = next((s for s in map(load_scene, bundled())
                      if any(kind_of(o).TYPE == kind for o in s.objects)), None)
        assert scene is not None, f"no bundled scene has a {kind}"
    mats = {k: dataclasses.replace(v, emission=GLOW) for k, v in scene.materials.items()}
    return dataclasses.replace(scene, materials=mats)


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_an_emissive_object_of_every_kind_renders_in_the_path_tracer(kind):
    scene = _glowing(kind)
    r = workbench.render(scene, "pathtrace", width=24, height=18, spp=4, seed=1)
    assert np.isfinite(r.image).all()
    # some pixel sees the emitter directly: at least its emission there (its own light plus
    # whatever it reflects)
    assert r.image.max() >= min(GLOW) - 1e-6, kind


def test_compare_runs_on_a_scene_with_an_emissive_blob(tmp_path):
    """The case found by hand: ``workbench compare`` on the kinds scene with the blob's material
    (coral) emissive."""
    src = workbench.scene.library.resolve("kinds").read_text()
    assert "[materials.coral]" in src and 'material = "coral"' in src
    path = tmp_path / "glow.toml"
    path.write_text(src.replace("[materials.coral]\n", "[materials.coral]\nemission = [1.0, 1.0, 1.0]\n", 1))
    p = subprocess.run([WORKBENCH, "compare", str(path), "--methods", "phong", "--size", "16x12",
                        "--out", str(tmp_path / "report")], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    assert (tmp_path / "report" / "report.json").stat().st_size > 0
