"""Ray-cast rows for matrix-free progressive refinement (Wallace et al. 1989): the numba
kernel against a readable numpy reference, the unoccluded case against the exact
point-to-polygon factor, occlusion, and the Cornell box solved by shooting them."""
from __future__ import annotations

import numpy as np
import pytest

from radiosity_shapes import grid

import workbench
from workbench.core.tol import tol
from workbench.renderers.radiosity.formfactors import point_polygon
from workbench.renderers.radiosity.geometry import geometry_from_polygons
from workbench.renderers.radiosity.raycast import RayRows


def _blocked_scene():
    emit = grid([0, 0, 0], [1, 0, 0], [0, 1, 0], 3)
    recv = grid([0, 0, 1], [0, 1, 0], [1, 0, 0], 3)
    up = grid([0.3, 0.3, 0.5], [0, 0.4, 0], [0.4, 0, 0], 1)          # faces -z
    dn = grid([0.3, 0.3, 0.5], [0.4, 0, 0], [0, 0.4, 0], 1)          # faces +z
    return geometry_from_polygons(emit + recv + up + dn)


def _reference_rows(rr: RayRows, shooters) -> np.ndarray:
    """The same rows, readably: Lambert's formula from each receiver centre, times the area
    fraction of the shooter's sample points that a segment reaches with no triangle crossing
    it (Moller-Trumbore against every triangle, numpy)."""
    g = rr.geom
    tris = g.tris
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    out = np.zeros((len(shooters), len(g)))
    for s, i in enumerate(shooters):
        pts = rr.samples[rr.sample_first[i]:rr.sample_first[i + 1]]
        w = rr.sample_w[rr.sample_first[i]:rr.sample_first[i + 1]]
        for j in range(len(g)):
            if j == i or g.areas[j] <= 0:
                continue
            f = point_polygon(g.centres[j:j + 1], g.normals[j:j + 1], g.polygons[i])[0]
            if f <= 0:
                continue
            o = g.centres[j] + rr.offset * g.normals[j]
            seen = 0.0
            for y, wk in zip(pts, w):
                d = y - o
                p = np.cross(d, e2)
                det = (e1 * p).sum(1)
                ok = det != 0
                inv = np.divide(1.0, det, out=np.zeros_like(det), where=ok)
                q = o - tris[:, 0]
                u = (q * p).sum(1) * inv
                r = np.cross(q, e1)
                v = (r * d).sum(1) * inv
                t = (r * e2).sum(1) * inv
                hit = ok & (u >= 0) & (u <= 1) & (v >= 0) & (u + v <= 1) & (t > tol.t_min) & (t < 1 - tol.t_min)
                seen += 0.0 if hit.any() else wk
            out[s, j] = f * seen / w.sum() * g.areas[j] / g.areas[i]
    return out


@pytest.mark.parametrize("level", [0, 1])
def test_kernel_matches_the_readable_reference(level):
    g = _blocked_scene()
    rr = RayRows(g, level)
    shooters = np.array([0, 4, 8, 13, 18])
    ref = _reference_rows(rr, shooters)
    assert np.allclose(rr.rows(shooters), ref, rtol=1e-9, atol=1e-15)
    assert (ref[:3, 9:18] > 0).any() and (ref[:3, 9:18] == 0).sum() < ref[:3, 9:18].size


def test_unoccluded_rows_are_the_exact_receiver_factors():
    """Two parallel unit squares 1 apart, 2 x 2 each: row i holds F(centre of j -> i) A_j / A_i."""
    polys = grid([0, 0, 0], [1, 0, 0], [0, 1, 0], 2) + grid([0, 0, 1], [0, 1, 0], [1, 0, 0], 2)
    g = geometry_from_polygons(polys)
    rows = RayRows(g).rows(np.arange(4))
    for i in range(4):
        exact = point_polygon(g.centres[4:], g.normals[4:], g.polygons[i])
        assert rows[i, 4:] == pytest.approx(exact * g.areas[4:] / g.areas[i], rel=1e-12)
        assert (rows[i, :4] == 0).all()                  # coplanar


def test_blocker_hides_the_receivers_behind_it():
    g = _blocked_scene()
    rows = RayRows(g, 2).rows([4])[0]         # the emitter's centre patch, under the blocker
    recv = slice(9, 18)
    assert rows[13] == 0                      # straight above, behind the blocker
    unocc = point_polygon(g.centres[recv], g.normals[recv], g.polygons[4]) * g.areas[recv] / g.areas[4]
    assert (rows[recv] <= unocc * (1 + 1e-12)).all() and (rows[recv] < unocc).sum() >= 5
    assert rows[18] > 0 and rows[19] == 0     # the blocker: its face towards the emitter sees it, the other not


def test_cornell_progressive_with_raycast_rows(gl_ctx):
    """Shooting ray-cast rows solves the gathering system: the Cornell box's radiosity is
    within a few % of the hemicube matrix's direct solution, converged by the bound."""
    from workbench.renderers.radiosity.method import RadiosityRenderer, solve_scene
    scene = workbench.load_scene("cornell")
    opts = {k: v.default for k, v in RadiosityRenderer.options.items()}
    opts.update(patch_size=0.1, hemicube_resolution=64, tol=1e-3)
    ray = solve_scene(scene, dict(opts, solver="progressive", shot_rows="raycast"), "radiosity")
    direct = solve_scene(scene, dict(opts, solver="direct"), "radiosity")
    assert ray.stats["converged"] and ray.stats["shot_rows"] == "raycast"
    assert not ray.stats["matrix_stored"] and ray.stats["visibility_rays"] > 0
    a = ray.patches.areas[:, None]
    refl = ray.patches.emission.max(1) == 0
    d = (ray.radiance - direct.radiance)[refl]
    rms = np.sqrt((a[refl] * d * d).sum() / (a[refl] * direct.radiance[refl] ** 2).sum())
    assert rms < 0.05
