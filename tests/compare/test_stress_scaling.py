"""The stress catalogue's scale cases scale every kind whole: each object's world bounds, the
camera and the lights are multiplied by the factor (lathe, prism and isosurface parameters were
left unscaled when lengths were found by key name)."""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

from workbench.compare.stress import scale_scene_dict
from workbench.scene.io import scene_from_dict
from workbench.scene.kinds import KINDS, kind_of, world_bounds
from workbench.scene.library import bundled

BOX = {"type": "box", "name": "added box", "min": [-0.5, 0.0, -0.5], "max": [0.5, 1.0, 0.5],
       "transform": {"translate": [0.3, 0.0, -0.2], "rotate": [0.0, 30.0, 0.0], "scale": 1.5}}


def _dict_with(kind: str) -> tuple[dict, object]:
    """(scene table, its folder) of the first bundled scene with a ``kind`` (whitted's with a
    box added: no bundled scene has one)."""
    for path in bundled():
        d = tomllib.loads(path.read_text())
        if any(o.get("type") == kind for o in d.get("objects", [])):
            return d, path.parent
    assert kind == "box", f"no bundled scene has a {kind}"
    path = next(p for p in bundled() if p.stem == "whitted")
    d = tomllib.loads(path.read_text())
    d["objects"].append({**BOX, "material": d["objects"][0]["material"]})
    return d, path.parent


@pytest.mark.parametrize("factor", [1e-6, 1e6])
@pytest.mark.parametrize("kind", sorted(KINDS))
def test_scaling_a_scene_scales_every_object_of_every_kind(kind, factor):
    d, folder = _dict_with(kind)
    a = scene_from_dict(d, base_dir=folder)
    b = scene_from_dict(scale_scene_dict(d, factor), base_dir=folder)
    assert any(kind_of(o).TYPE == kind for o in a.objects)
    for oa, ob in zip(a.objects, b.objects, strict=True):
        lo_a, hi_a = world_bounds(oa, np.eye(4))
        lo_b, hi_b = world_bounds(ob, np.eye(4))
        finite = np.isfinite(lo_a) & np.isfinite(hi_a)  # a plane is unbounded along itself
        span = float(np.max(hi_a[finite] - lo_a[finite])) if finite.any() else 1.0
        for x, y in ((lo_a, lo_b), (hi_a, hi_b)):
            assert np.allclose(y[finite], factor * x[finite], rtol=1e-9, atol=1e-9 * factor * span), \
                (kind_of(oa).TYPE, x, y)
    assert np.allclose(b.camera.position, factor * np.asarray(a.camera.position), rtol=1e-12)
    for la, lb in zip(a.lights, b.lights, strict=True):
        if hasattr(la, "position"):
            assert np.allclose(lb.position, factor * np.asarray(la.position), rtol=1e-12)
