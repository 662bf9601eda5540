"""The hybrid method: the diffuse surfaces show the radiosity solution (the ray tracer returns
the patch mesh's vertex emission, interpolated as Gouraud does), the mirror and glass spheres
show the room through the ray tracer's recursion.

The image tests are marked slow: they JIT-compile the ray tracer (about 100 s on this loaded
machine whenever its numba cache is stale); run them with ``-m slow``."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.core.errors import NotApplicable


@pytest.fixture(scope="module")
def pair():
    scene = workbench.load_scene("cornell_spheres")
    kw = dict(width=40, height=40, patch_size=0.2, hemicube_resolution=32)
    return (workbench.render(scene, "radiosity", **kw), workbench.render(scene, "hybrid", **kw))


@pytest.mark.slow
def test_hybrid_diffuse_pixels_are_the_radiosity(gl_ctx, pair):
    rad, hyb = pair
    assert hyb.stats["nonfinite_pixels"] == 0 and hyb.stats["objects_as_radiosity_meshes"] == 5
    # the upper half of the image is walls, ceiling and light only: same values in both
    top_r, top_h = rad.image[:16], hyb.image[:16]
    close = np.abs(top_h - top_r) <= 1e-3 * np.maximum(top_r, 1e-3) + 1e-4
    assert close.mean() > 0.9          # edges of polygons may fall on either side of a pixel


@pytest.mark.slow
def test_hybrid_spheres_reflect_the_room(pair):
    rad, hyb = pair
    # the spheres stand on the floor in the lower half: black occluders for radiosity (kd = 0),
    # mirrored / refracted room for the hybrid (the mirror also shows the box's open front,
    # which is black: not every sphere pixel lights up)
    dark_r = rad.image[24:38, 2:38].sum(-1) < 1e-6
    assert dark_r.sum() > 20
    lit = hyb.image[24:38, 2:38][dark_r].sum(-1) > 1e-3
    assert lit.mean() > 0.6
    assert "reflection" in hyb.features_used and "refraction" in hyb.features_used
    assert any(e.feature == "caustics" for e in hyb.left_out)


def test_hybrid_without_emitters_is_not_applicable():
    with pytest.raises(NotApplicable, match="no emitters"):
        workbench.render(workbench.load_scene("whitted"), "hybrid", width=8, height=8)


class Stop(Exception):
    """Raised by a progress callback: the render must end with it."""


def test_hybrid_reports_each_step_and_the_bands_of_its_image(gl_ctx):
    """The window's progress bar of the hybrid method (issue #29): the form factors' rows, the
    solve (no amount reported), the ray-trace pass's rows; its bands are the final image."""
    scene = workbench.load_scene("cornell_spheres")
    kw = dict(width=24, height=20, patch_size=0.2, hemicube_resolution=32)
    steps, image = [], np.zeros((20, 24, 3), np.float32)

    def band(y0, y1, x0, x1, tile):
        image[y0:y1, x0:x1] = tile
    res = workbench.render(scene, "hybrid", **kw, on_progress=lambda *a: steps.append(a), on_tile=band)
    assert np.array_equal(res.image, workbench.render(scene, "hybrid", **kw).image)
    assert np.array_equal(image, res.image)
    P = res.stats["patches"]
    rows = [s for s in steps if s[0] == "radiosity form factors"]
    assert rows[0] == ("radiosity form factors", 0, P, "patches") and rows[-1][1] == P
    assert all(b[1] > a[1] for a, b in zip(rows, rows[1:]))
    traced = [s for s in steps if s[0] == "ray trace"]
    assert traced[0] == ("ray trace", 0, 20, "rows") and traced[-1] == ("ray trace", 20, 20, "rows")
    solve = ("radiosity solve (direct: no progress reported)", 0, None, "")
    assert steps == [*rows, solve, *traced]  # one step after the other

    def stop(phase, *_):
        if phase.startswith("radiosity solve"):
            raise Stop
    with pytest.raises(Stop):
        workbench.render(scene, "hybrid", **kw, on_progress=stop)
