"""Radiosity is scale-invariant for curved kinds (issue 26, item 4): a furnace (a closed box
of walls emitting E = 0.25 with rho = 0.8) holding one non-emitting grey object of each curved
kind (tessellated into triangle patches), scaled by 1e-6, gives the radiosity of scale 1 patch
by patch and the same image.

At scale 1e-6 the patches' areas are about 1e-15: the area-weighted means that divided by
``max(area, tol.zero)`` (an absolute 1e-12) shrank the patch centres (where the hemicubes
stand) and the vertex colours of the Gouraud display, so the image came out nearly black.
The bound: the same hemicube sees the same scaled picture, so the per-patch radiosity agrees
to rounding; 1e-3 relative (the solver's tolerance) leaves room for a pixel's rasterisation
flipping under float32 rounding.
"""
from __future__ import annotations

import copy

import numpy as np
import pytest

from workbench.compare.stress import scale_scene_dict
from workbench.renderers.base import render
from workbench.renderers.radiosity.method import common_options, solve_scene
from workbench.scene.io import scene_from_dict

CURVED = {
    "sphere": {"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 0.12},
    "quadric": {"type": "quadric", "shape": "ellipsoid", "radii": [0.14, 0.1, 0.12]},
    "blob": {"type": "blob", "threshold": 0.3, "components": [{"center": [-0.05, 0, 0], "radius": 0.15},
                                                              {"center": [0.05, 0, 0], "radius": 0.15}]},
    "isosurface": {"type": "isosurface", "function": "x^2 + y^2 + z^2", "threshold": 0.0144, "max_gradient": 0.6,
                   "bounds": {"min": [-0.15, -0.15, -0.15], "max": [0.15, 0.15, 0.15]}},
    "lathe": {"type": "lathe", "points": [[0.0, -0.12], [0.12, -0.1], [0.08, 0.05], [0.0, 0.12]]},
    "prism": {"type": "prism", "polygon": [[0.12, 0.0], [-0.06, 0.1], [-0.06, -0.1]], "heights": [-0.1, 0.1]},
    "mesh": {"type": "mesh", "generate": {"kind": "icosphere", "subdivisions": 2, "radius": 0.12}},
    "csg": {"type": "csg", "op": "difference", "left": {"type": "sphere", "center": [0, 0, 0], "radius": 0.12},
            "right": {"type": "box", "min": [0.0, 0.0, -0.2], "max": [0.2, 0.2, 0.2]}},
}
WALLS = [[[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]], [[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]],
         [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]], [[1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]],
         [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]], [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]]
OPTIONS = {"patch_size": 0.25, "hemicube_resolution": 32}


def _furnace(kinds) -> dict:
    """The furnace holding one object of each of ``kinds`` (names in :data:`CURVED`)."""
    objects = [{"type": "polygon", "material": "wall", "vertices": v} for v in WALLS]
    for i, (kind, obj) in enumerate((k, copy.deepcopy(CURVED[k])) for k in kinds):
        o = {**obj, "material": "grey", "transform": {"translate": [0.2 + 0.3 * (i % 3), 0.25 + 0.25 * (i // 3), 0.6]}}
        if kind == "csg":
            o["left"], o["right"] = {**o["left"], "material": "grey"}, {**o["right"], "material": "grey"}
        objects.append(o)
    return {"scene": {"name": "furnace_curved", "background": [0, 0, 0], "ambient": [0, 0, 0]},
            "camera": {"position": [0.5, 0.5, 0.02], "look_at": [0.5, 0.45, 1.0], "fov_y": 70.0, "resolution": [32, 32]},
            "materials": {"wall": {"color": [1, 1, 1], "ka": 0.0, "kd": 0.8, "emission": [0.25, 0.25, 0.25]},
                          "grey": {"color": [1, 1, 1], "ka": 0.0, "kd": 0.5}},
            "objects": objects}


def _solutions(kinds):
    opts = {**{k: o.default for k, o in common_options().items()}, **OPTIONS}
    scenes = {f: scene_from_dict(scale_scene_dict(_furnace(kinds), f), source="furnace_curved")
              for f in (1.0, 1e-6)}
    return scenes, {f: solve_scene(sc, opts, "radiosity") for f, sc in scenes.items()}


def _worst(sol) -> tuple[float, str]:
    """Largest relative difference of a patch's radiosity between the scales (a patch no light
    reaches is compared with the brightest), and its surface."""
    p, b1, b6 = sol[1.0].patches, sol[1.0].radiance, sol[1e-6].radiance
    assert b1.shape == b6.shape
    rel = (np.abs(b6 - b1) / np.maximum(b1, 1e-6 * b1.max())).max(1)
    return float(rel.max()), p.surface_names[p.surface[int(np.argmax(rel))]]


@pytest.mark.slow  # about a minute: two solves of 2400 patches
@pytest.mark.gl
def test_radiosity_of_curved_kinds_does_not_change_with_scale(gl_ctx):
    kinds = sorted(k for k in CURVED if k != "csg")
    scenes, sol = _solutions(kinds)
    p = sol[1.0].patches
    assert not [s for s in sol[1.0].left_out if "not cut" in s.reason], sol[1.0].left_out
    seen = {p.surface_objects[s].kind for s in np.unique(p.surface[p.reflectance[:, 0] < 0.6])}
    assert seen == {CURVED[k]["type"] for k in kinds}, seen  # every kind cut into patches
    worst = _worst(sol)
    assert worst[0] <= 1e-3, worst
    img = {f: render(sc, "radiosity", **OPTIONS).image.astype(np.float64) for f, sc in scenes.items()}
    assert np.isfinite(img[1e-6]).all()
    assert abs(img[1e-6].mean() / img[1.0].mean() - 1.0) <= 1e-2, (img[1e-6].mean(), img[1.0].mean())


@pytest.mark.slow  # about 40 s
@pytest.mark.gl
def test_radiosity_of_csg_does_not_change_with_scale(gl_ctx):
    """The boolean's triangles, one patch each, come in an order of manifold3d's that changed
    with the scale (the solutions agreed, permuted): csg._canonical_order sorts them."""
    _, sol = _solutions(["csg"])
    worst = _worst(sol)
    assert worst[0] <= 1e-3, worst
