"""Defects of issue 17 where an object vanished or was drawn wrong, each pinned by a test that
failed before its fix."""
from __future__ import annotations

import numpy as np
import pytest

from seen_pixels import coverage, iou, scene_dict
from workbench.scene.io import scene_from_dict
from workbench.scene.polygon_pieces import convex_pieces, ear_triangles

L_SHAPE = [[-1, -1, 0], [1, -1, 0], [1, 0, 0], [0, 0, 0], [0, 1, 0], [-1, 1, 0]]
U_SHAPE = [[-1.5, -1, 0], [1.5, -1, 0], [1.5, 1, 0], [0.7, 1, 0], [0.7, -0.2, 0], [-0.7, -0.2, 0],
           [-0.7, 1, 0], [-1.5, 1, 0]]
STAR = [[1.5 * (1.0 if k % 2 == 0 else 0.4) * np.cos(np.pi / 2 + k * np.pi / 5),
         1.5 * (1.0 if k % 2 == 0 else 0.4) * np.sin(np.pi / 2 + k * np.pi / 5), 0.0] for k in range(10)]


def _area(v):
    v = np.asarray(v, dtype=np.float64)
    return 0.5 * np.linalg.norm(np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0))


@pytest.mark.parametrize("verts", [L_SHAPE, U_SHAPE, STAR], ids=["L", "U", "star"])
def test_ear_clipping_covers_the_polygon_exactly(verts):
    tris = ear_triangles(np.asarray(verts, dtype=np.float64))
    assert len(tris) == len(verts) - 2
    total = sum(_area(np.asarray(verts, dtype=np.float64)[t]) for t in tris)
    assert abs(total - _area(verts)) <= 1e-12 * _area(verts)
    n = np.cross(np.subtract(verts[1], verts[0]), np.subtract(verts[2], verts[0]))
    for t in tris:  # every triangle wound like the polygon (its normal +z)
        a, b, c = np.asarray(verts, dtype=np.float64)[t]
        assert np.cross(b - a, c - a)[2] > 0.0
    assert len(convex_pieces(verts)) == len(verts) - 2
    assert len(convex_pieces(L_SHAPE[:3] + [[-1, 1, 0]])) == 1  # a convex quad stays whole


@pytest.mark.gl
@pytest.mark.parametrize("verts", [L_SHAPE, U_SHAPE, STAR], ids=["L", "U", "star"])
def test_concave_polygon_same_coverage_in_ray_caster_and_raster(verts, gl_ctx):
    sc = scene_from_dict(scene_dict([{"type": "polygon", "vertices": verts, "material": "m"}]))
    ray, ras = coverage(sc, "raycast", 64, 48), coverage(sc, "phong", 64, 48)
    assert ray.sum() > 0.3 * ras.sum()
    assert iou(ray, ras) >= 0.97, iou(ray, ras)
    # the polygon's own area, seen head on: the pixel count matches it (edges within a pixel)
    th = np.tan(np.radians(20.0))
    px_area = (2 * 6 * th / 48) ** 2
    perimeter_px = sum(np.linalg.norm(np.subtract(a, b)) for a, b in zip(verts, np.roll(verts, -1, 0))) / np.sqrt(px_area)
    assert abs(ray.sum() - _area(verts) / px_area) <= perimeter_px, (ray.sum(), _area(verts) / px_area)


def test_concave_polygon_radiosity_patches_cover_its_area():
    from workbench.renderers.radiosity.patches import patches_from_scene
    sc = scene_from_dict(scene_dict([{"type": "polygon", "vertices": STAR, "material": "m"}]))
    ps, _ = patches_from_scene(sc, 0.2)
    assert abs(ps.areas.sum() - _area(STAR)) <= 1e-9 * _area(STAR)
