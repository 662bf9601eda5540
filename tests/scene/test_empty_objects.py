"""An object with no surface (a blob whose threshold is above its field's maximum, an
isosurface whose field stays above its threshold (the solid is f < threshold), a CSG intersection of disjoint solids) gets
the same answer from every method: the scene as if it were not there, and the raster methods
say so in ``left_out`` (the raster crashed on a zero-size reduction, the ray methods dropped it
silently)."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.scene.library import resolve

DISJOINT = '''
[[objects]]
type = "csg"
name = "nothing"
material = "ivory"
op = "intersection"
left = { type = "sphere", center = [-3.0, 0.5, 0.0], radius = 0.4 }
right = { type = "sphere", center = [3.0, 0.5, 0.0], radius = 0.4 }
'''
CASES = {  # name -> (bundled scene, edit making one object empty, the object's name)
    "blob": ("kinds", lambda t: t.replace("threshold = 0.3", "threshold = 50.0", 1), "metaballs"),
    "isosurface": ("kinds", lambda t: t.replace("threshold = 0.0\nmax_gradient", "threshold = -100.0\nmax_gradient", 1),
                   "gyroid"),
    "csg": ("csg", lambda t: t + DISJOINT, "nothing"),
}
METHODS = ("flat", "phong", "zbuffer", "raycast", "raytrace")


def _scenes(tmp_path, kind):
    name, edit, obj = CASES[kind]
    text = resolve(name).read_text()
    edited = edit(text)
    assert edited != text
    path = tmp_path / f"{kind}.toml"
    path.write_text(edited)
    with_empty = workbench.load_scene(path)
    import dataclasses
    without = dataclasses.replace(with_empty, objects=type(with_empty.objects)(
        o for o in with_empty.objects if o.name != obj))
    assert len(without.objects) == len(with_empty.objects) - 1
    return with_empty, without, obj


@pytest.mark.gl
@pytest.mark.parametrize("kind", sorted(CASES))
def test_an_empty_object_renders_as_if_absent_in_every_method(kind, tmp_path):
    with_empty, without, obj = _scenes(tmp_path, kind)
    for m in METHODS:
        a = workbench.render(with_empty, m, width=32, height=24)
        b = workbench.render(without, m, width=32, height=24)
        assert np.isfinite(a.image).all(), m
        # the same image: an empty object's declared bounds widen neither the raster's depth
        # range nor its stand-ins' maps (they did: 4 % of the flat pixels moved)
        same = np.abs(a.image - b.image).max(-1) <= 1e-5
        assert same.all(), (m, same.mean())
        if m in ("flat", "phong"):
            assert any(obj in x.reason and "no triangle" in x.reason for x in a.left_out), (m, a.left_out)
