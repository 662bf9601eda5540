"""Radiosity and hybrid with the camera inside a closed object of any kind refuse with one line
(NotApplicable) instead of returning an all-black image with exit 0: their patches are lit on the
outer side only.  Open kinds (plane, polygon) have no inside to be in."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import workbench
from workbench.core.errors import NotApplicable
from workbench.scene import model as m
from workbench.scene.io import load_scene
from workbench.scene.kinds import KINDS, containing, is_solid, kind_of, world_bounds
from workbench.scene.library import bundled


def _with_kind(kind: str) -> tuple[m.Scene, m.SceneObject]:
    """A bundled scene with an object of ``kind`` (whitted's with a box added: none has one),
    every material emissive so that radiosity applies."""
    if kind == "box":
        scene = load_scene("whitted")
        obj = m.Box(material=next(iter(scene.materials)), name="added box", min=(-0.5, 0.2, -0.5), max=(0.5, 1.2, 0.5))
        scene = dataclasses.replace(scene, objects=type(scene.objects)([*scene.objects, obj]))
    else:
        scene = next(s for s in map(load_scene, bundled()) if any(kind_of(o).TYPE == kind for o in s.objects))
        obj = next(o for o in scene.objects if kind_of(o).TYPE == kind)
    mats = {k: dataclasses.replace(v, emission=(0.2, 0.2, 0.2)) for k, v in scene.materials.items()}
    return dataclasses.replace(scene, materials=mats), obj


def _inside_point(obj) -> np.ndarray | None:
    """A point inside ``obj`` found on a 15^3 grid over its world bounds, or None."""
    lo, hi = world_bounds(obj, np.eye(4))
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        return None
    t = (np.arange(15) + 0.5) / 15
    for x in lo[0] + t * (hi[0] - lo[0]):
        for y in lo[1] + t * (hi[1] - lo[1]):
            for z in lo[2] + t * (hi[2] - lo[2]):
                p = np.array([x, y, z])
                if containing(obj, np.eye(4), p) is not None:
                    return p
    return None


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_radiosity_and_hybrid_refuse_a_camera_inside_a_closed_object(kind):
    scene, obj = _with_kind(kind)
    p = _inside_point(obj)
    if not is_solid(obj):
        assert p is None, f"an open {kind} has an inside"
        return
    assert p is not None, f"no point inside the {kind} found"
    look = p + np.array([0.0, 0.0, 1.0])
    inside = dataclasses.replace(scene, camera=dataclasses.replace(
        scene.camera, position=tuple(p), look_at=tuple(look), up=(0.0, 1.0, 0.0)))
    for method in ("radiosity", "hybrid"):
        with pytest.raises(NotApplicable, match="camera is inside the closed object"):
            workbench.render(inside, method, width=8, height=8)
