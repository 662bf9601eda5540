"""The radiosity image's near plane comes from the surfaces, not their patch corners: a camera
close to a surface cut into large patches sees it (found by the generated furnaces of
``test_properties``: a camera 0.125 above the floor of the unit furnace lost the bottom row,
its near plane half the nearest corner's depth, 0.25, beyond the floor's 0.24).  A blob's
coarse patches once lay outside its fine raster mesh (marching cubes' linear interpolation of
its falloff overshoots), so that a camera 0.01 in front of the one was inside the other: the
vertices now lie on the surface (``marching_cubes.edge_roots``)."""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import find, settings

import generators as g
import workbench


def _scene(obj: dict, position, look_at):
    d = {"scene": {"background": [0.0, 0.0, 0.0], "ambient": [0.0, 0.0, 0.0]},
         "camera": {"position": list(position), "look_at": list(look_at), "fov_y": 50.0, "resolution": [24, 18]},
         "materials": {k: dict(v) for k, v in g.MATERIALS.items()}, "lights": [],
         "objects": [{**obj, "material": "emissive"}]}
    with tempfile.TemporaryDirectory() as folder:
        return workbench.load_scene(g.write_scene(d, Path(folder)))


@pytest.mark.gl
@pytest.mark.parametrize("kind", g.KIND_NAMES)
def test_a_surface_nearer_than_its_patch_corners_is_drawn(kind, gl_ctx):
    """The simplest generated object of ``kind``, emissive, seen from 0.01 in front of the
    surface under the image centre (found by the Phong raster from 5 away: its tessellation,
    which the patches are cut from, not the exact surface the camera could be inside of), with patches half the
    scene's diagonal: the radiosity image shows the emitter wherever the Phong raster sees it
    (up to 3 % of the pixels: the two tessellations' silhouettes)."""
    obj = find(g.shapes(kind), lambda _: True, settings=SIMPLEST)
    _check_near_plane(obj)


SIMPLEST = settings(database=None, derandomize=True)
"""``find``'s simplest example, the same on every machine: with hypothesis's example database
(``.hypothesis/`` in the working folder, filled by other tests' ``find``) it may replay another."""

LATHE_DEFECT = {"type": "lathe", "points": [[0.0, 1.0], [0.0, -0.8], [0.6, -0.7], [0.3, -0.2], [0.8, 0.4],
                                            [0.4, 0.8], [0.0, 0.6], [0.0, -1.0]], "spline": "cubic"}
"""A lathe the example database once replayed here: seen from 0.01 in front, its radiosity image
is black on 89 of the 432 pixels the Phong raster sees (known defect, not yet understood)."""


@pytest.mark.gl
@pytest.mark.xfail(strict=True, reason="known defect: radiosity loses 89 of 432 pixels of this lathe "
                                       "seen from 0.01 (found 2026-12-04, not yet fixed)")
def test_the_lathe_the_database_replayed(gl_ctx):
    _check_near_plane(LATHE_DEFECT)


def _check_near_plane(obj: dict):
    far = np.array([0.3, 0.4, 5.0])
    r = workbench.render(_scene(obj, far, (0.0, 0.0, 0.0)), "phong", width=25, height=19)
    t = float(r.depth[9, 12])
    assert np.isfinite(t), "the centre ray misses the object"
    toward = -far / np.linalg.norm(far)
    hit = far + t * toward  # the centre pixel's ray is the view axis: its depth is its distance
    near = _scene(obj, hit - 0.01 * toward, hit)
    seen = np.isfinite(workbench.render(near, "phong", width=24, height=18).depth)
    rad = workbench.render(near, "radiosity", width=24, height=18, patch_size=0.5).image
    assert seen.sum() > 100
    lost = (seen & (rad.max(-1) <= 0.0)).sum()
    assert lost <= 0.03 * seen.sum(), (obj["type"], int(lost), int(seen.sum()))
