"""The registered radiosity method end to end: furnace scene (exact answer), Cornell box
(finite, colour bleeding), no emitters, progressive refinement without the matrix."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.core.errors import NotApplicable, WorkbenchError
from workbench.renderers.radiosity.method import solve_scene, RadiosityRenderer
from workbench.renderers.radiosity.patches import patches_from_scene
from workbench.scene.prepared import prepare


def _opts(**kw):
    o = {k: v.default for k, v in RadiosityRenderer.options.items()}
    o.update(kw)
    return o


@pytest.mark.parametrize("solver", ["direct", "jacobi", "gauss_seidel"])
def test_furnace_scene_image_is_exact(gl_ctx, solver):
    """Closed cube, E = 0.25, rho = 0.8: every pixel shows B = E / (1 - rho) = 1.25 (delta form
    factors normalised); with the raw ones, rows sum to 1 + 3.3e-5 at resolution 128 (errata 6)
    and B = E / (1 - rho (1 + 3.3e-5))."""
    scene = workbench.load_scene("furnace")
    for normalize in (True, False):
        r = workbench.render(scene, "radiosity", width=32, height=32, solver=solver,
                             patch_size=0.15, tol=1e-6, hemicube_normalize=normalize)
        assert r.stats["converged"] and r.stats["nonfinite_pixels"] == 0
        excess = r.stats["hemicube_weight_sum"] - 1.0
        assert (excess == pytest.approx(0, abs=1e-12)) if normalize else (0 < excess < 1e-4)
        assert np.abs(r.image - 0.25 / (1 - 0.8 * (1 + excess))).max() < 1e-5


def test_furnace_progressive_shows_the_hemicube_reciprocity_error(gl_ctx):
    """Shooting uses F_ji = F_ij A_i / A_j from the shooter's hemicube: the hemicube's
    reciprocity error (proximity of touching walls) shows as a few % off 1.25 (inherent to the
    hemicube, DESIGN errata 6), still within 5 %, and converged."""
    scene = workbench.load_scene("furnace")
    r = workbench.render(scene, "radiosity", width=16, height=16, solver="progressive",
                         patch_size=0.25, tol=1e-4, hemicube_resolution=64)
    assert r.stats["converged"] and not r.stats["matrix_stored"]
    assert np.abs(r.image / 1.25 - 1).max() < 0.05


def test_cornell_renders_with_colour_bleeding(gl_ctx):
    scene = workbench.load_scene("cornell")
    r = workbench.render(scene, "radiosity", width=48, height=48, patch_size=0.1,
                         hemicube_resolution=64)
    assert r.stats["nonfinite_pixels"] == 0 and np.isfinite(r.image).all()
    assert r.image.max() > 0 and r.stats["converged"]
    for key in ("patches", "iterations", "row_sum_max", "reciprocity_error", "gl_renderer"):
        assert key in r.stats
    assert "form_factors" in r.timings and "solve" in r.timings
    # patches of the floor: near the red wall (x = 556, image left) vs the green one (x = 0)
    sol = solve_scene(scene, _opts(patch_size=0.1, hemicube_resolution=64), "radiosity")
    p = sol.patches
    floor = np.array([p.surface_names[s] == "floor" for s in p.surface])
    x = p.centres[:, 0]
    redness = lambda sel: (sol.radiance[sel, 0] / sol.radiance[sel, 1]).mean()
    near_red, near_green = floor & (x > 450), floor & (x < 100)
    assert redness(near_red) > 1.05 * redness(near_green)
    # the same seen in the image: bottom rows, left (red side) vs right (green side)
    img = r.image[-6:-2]
    assert (img[:, 6:14, 0] / img[:, 6:14, 1]).mean() > (img[:, 34:42, 0] / img[:, 34:42, 1]).mean()


def test_no_emitters_is_not_applicable():
    scene = workbench.load_scene("whitted")
    with pytest.raises(NotApplicable, match="no emitters"):
        workbench.render(scene, "radiosity", width=8, height=8)


def test_bad_options():
    scene = workbench.load_scene("furnace")
    with pytest.raises(WorkbenchError, match="solver"):
        workbench.render(scene, "radiosity", width=8, height=8, solver="magic")
    with pytest.raises(WorkbenchError, match="resolution"):
        workbench.render(scene, "radiosity", width=8, height=8, hemicube_resolution=7)
    with pytest.raises(WorkbenchError, match="tol"):
        workbench.render(scene, "radiosity", width=8, height=8, tol=0.0)
    with pytest.raises(WorkbenchError, match="max_iterations"):
        workbench.render(scene, "radiosity", width=8, height=8, max_iterations=-1)
    with pytest.raises(WorkbenchError, match="patch_size"):
        workbench.render(scene, "radiosity", width=8, height=8, patch_size=0.0)


def test_patch_size_is_the_knob():
    scene = workbench.load_scene("cornell")
    ext = prepare(scene).extent
    counts = [len(patches_from_scene(scene, f * ext)[0]) for f in (0.2, 0.1, 0.05)]
    assert counts[0] < counts[1] < counts[2]
    p, _ = patches_from_scene(scene, 0.05 * ext)
    edges = np.linalg.norm(p.corners - np.roll(p.corners, 1, axis=1), axis=-1)
    assert edges.max() <= 0.05 * ext * (1 + 1e-9)
    # the patches tile every surface: total area is preserved (to 1e-6: the published red
    # wall is 0.2 % off planar, so its cells' areas do not add up exactly)
    p_whole, _ = patches_from_scene(scene, 1e9)
    assert p.areas.sum() == pytest.approx(p_whole.areas.sum(), rel=1e-6)


def test_progressive_does_not_build_the_matrix(gl_ctx):
    scene = workbench.load_scene("cornell")
    kw = dict(patch_size=0.2, solver="progressive", tol=1e-3, hemicube_resolution=32)
    plain = solve_scene(scene, _opts(row_cache_mb=0.0, **kw), "radiosity")
    assert plain.stats["matrix_stored"] is False and plain.stats["rows_cached"] == 0
    # one hemicube per shot, drawn 16 at a time (the last batch may not all shoot)
    it = plain.stats["iterations"]
    assert 0 < it <= plain.stats["hemicubes_drawn"] < it + 16
    # rows of patches that shoot again kept: fewer hemicubes, same answer (float32 rows)
    cached = solve_scene(scene, _opts(**kw), "radiosity")
    n = cached.stats["patches"]
    assert cached.stats["hemicubes_drawn"] < min(it, n + 16) and cached.stats["row_cache_hits"] > 0
    assert np.abs(cached.radiance - plain.radiance).max() <= 1e-5 * plain.radiance.max()
