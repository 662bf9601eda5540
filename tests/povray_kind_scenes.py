"""Scenes that put each new object kind (blob, isosurface, lathe, prism) in front of POV-Ray
and the ray tracer at the same camera, and the per-object masks compared (test and bench
helper: ``tests/renderers/test_povray_kinds.py``, ``bench/povray_kinds.py``).

Masks: an "ID" copy of a scene gives every top-level object (with all its CSG operands) a
material of its own that only reflects the ambient light (``ka = 1``, ``kd = ks = kr = kt =
0``) in a colour of its own, under ambient light 1, no lights and a black background, so that
each pixel's colour names the object its primary ray hit, in both programs.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

import workbench
from workbench.scene import model as m

ID_COLOURS = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0],
                       [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.5, 0.0, 0.0]])
"""One colour per object (the background is black); labels are the nearest colour."""

_TORUS = {"type": "isosurface", "name": "torus", "material": "jade", "function": "(sqrt(x^2 + z^2) - 1)^2 + y^2",
          "threshold": 0.09, "max_gradient": 4.0, "bounds": {"min": [-1.5, -0.5, -1.5], "max": [1.5, 0.5, 1.5]},
          "transform": {"rotate": [30.0, 0.0, 0.0], "translate": [-2.0, 1.0, 0.0]}}
_VASE = {"type": "lathe", "name": "open_vase", "material": "gold",
         "points": [[0.5, 0.0], [0.8, 0.5], [0.4, 1.2], [0.6, 1.7]], "transform": {"translate": [1.5, 0.0, 0.0]}}
_SPLINES = [  # one smooth lathe per POV-Ray spline, beside each other
    {"type": "lathe", "name": "quadratic_cup", "material": "gold", "spline": "quadratic",
     "points": [[0.2, -0.3], [0.5, 0.0], [0.8, 0.6], [0.5, 1.3], [0.7, 1.6]],
     "transform": {"translate": [-1.8, 0.0, 0.0]}},
    {"type": "lathe", "name": "bezier_bulb", "material": "coral", "spline": "bezier",
     "points": [[0.0, 0.0], [1.2, 0.0], [0.9, 1.2], [0.3, 1.4], [0.3, 1.4], [0.1, 1.5], [0.4, 1.8], [0.0, 1.9]],
     "transform": {"translate": [0.2, 0.0, 0.0]}},
]
_CSG = [
    {"type": "csg", "name": "prism_minus_blob", "material": "violet", "op": "difference",
     "transform": {"translate": [-1.6, 0.0, 0.5]},
     "left": {"type": "prism", "polygon": [[-1, -1], [1, -1], [1, 1], [0, 0.3], [-1, 1]], "heights": [0.0, 1.2]},
     "right": {"type": "blob", "threshold": 0.3, "material": "coral",
               "components": [{"center": [0.6, 1.2, 0.0], "radius": 0.9}, {"center": [-0.5, 1.2, 0.3], "radius": 0.7}]}},
    {"type": "csg", "name": "goblet_and_gyroid", "material": "gold", "op": "intersection",
     "transform": {"translate": [1.4, 0.0, 0.3]},
     "left": {"type": "lathe", "points": [[0.0, 0.0], [1.0, 0.0], [1.0, 1.6], [0.0, 1.6]]},
     "right": {"type": "isosurface", "material": "jade", "function": "sin(3*x)*cos(3*y) + sin(3*y)*cos(3*z) + sin(3*z)*cos(3*x)",
               "threshold": 0.2, "max_gradient": 7.5, "bounds": {"min": [-1.1, -0.1, -1.1], "max": [1.1, 1.7, 1.1]}}},
]


def kind_scenes() -> dict[str, m.Scene]:
    """``kinds`` (the bundled scene), each of its four new objects alone on its floor, an
    isosurface torus, an open lathe (a sheet) and the new kinds as CSG operands (a prism
    minus a blob; a closed lathe intersected with a gyroid), all at the ``kinds`` camera."""
    from workbench.scene.io import scene_from_dict
    import tomllib
    from pathlib import Path
    base = workbench.load_scene("kinds")
    out = {"kinds": base}
    floor = base.objects[0]
    for o in base.objects[1:]:
        out[o.kind] = replace(base, objects=(floor, o))
    data = tomllib.loads((Path(__file__).resolve().parents[1] / "scenes" / "kinds.toml").read_text())
    for name, objs in (("isosurface_torus", [_TORUS]), ("lathe_open", [_VASE]), ("lathe_splines", _SPLINES),
                       ("csg_new_kinds", _CSG)):
        out[name] = scene_from_dict({**data, "objects": [data["objects"][0], *objs]})
    return out


def _recolour(o: m.SceneObject, material: str) -> m.SceneObject:
    if o.kind == "csg":
        return replace(o, material=material, left=_recolour(o.left, material), right=_recolour(o.right, material))
    return replace(o, material=material)


def id_scene(scene: m.Scene) -> m.Scene:
    """The scene's "ID" copy (module docstring)."""
    if len(scene.objects) > len(ID_COLOURS):
        raise ValueError(f"at most {len(ID_COLOURS)} objects, got {len(scene.objects)}")
    mats = {f"id{i}": m.Material(f"id{i}", color=tuple(ID_COLOURS[i]), ka=1.0, kd=0.0, ks=0.0)
            for i in range(len(scene.objects))}
    return replace(scene, materials=mats, lights=(), ambient=(1.0, 1.0, 1.0), background=(0.0, 0.0, 0.0),
                   environment=None, objects=tuple(_recolour(o, f"id{i}") for i, o in enumerate(scene.objects)))


def labels(image: np.ndarray) -> np.ndarray:
    """(H, W) int: the object each pixel of an ID image shows (index into the scene's
    objects), -1 for the background."""
    pal = np.vstack([np.zeros(3), ID_COLOURS])
    d = ((np.asarray(image, dtype=np.float64)[..., None, :] - pal) ** 2).sum(-1)
    return d.argmin(-1) - 1


def object_ious(a: np.ndarray, b: np.ndarray, n: int) -> list[float]:
    """Intersection over union of each object's pixels in two label images (1 when neither
    shows it)."""
    out = []
    for i in range(n):
        union = ((a == i) | (b == i)).sum()
        out.append(1.0 if union == 0 else float(((a == i) & (b == i)).sum() / union))
    return out
