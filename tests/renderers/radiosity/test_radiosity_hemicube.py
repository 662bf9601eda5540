"""The hemicube's item buffer drawn with bilinear-grid blocks (a few quads per surface, the
patch found per pixel) against the readable reference (two triangles per patch), and the
numba accumulation of item buffers into rows against np.bincount."""
from __future__ import annotations

import numpy as np

import workbench
from workbench.renderers.radiosity.hemicube import Hemicube, delta_form_factors, grid_regions
from workbench.renderers.radiosity.kernels import accumulate_items
from workbench.renderers.radiosity.patches import _assemble, patch_size_for_count, patches_from_scene


def _agree(geom, patches, res):
    """Pixel agreement and L1 row differences of the two ways of drawing."""
    fast, ref = Hemicube(geom, res), Hemicube(geom, res, regions=False)
    try:
        a, b = fast.item_buffers(patches), ref.item_buffers(patches)
        d = np.abs(fast.rows(patches) - ref.rows(patches)).sum(1)
        return fast.blocks, (a == b).mean(), d
    finally:
        fast.release()
        ref.release()


def test_cornell_blocks_give_the_patch_triangles_item_buffer(gl_ctx):
    """The Cornell box (16 quads, the red wall 0.2 % off plane): blocks and per-patch
    triangles see the same patch in >= 99.9 % of the pixels, including from patches ON the
    warped wall (whose own block is not drawn) and beside it; the differences are ties on cell
    boundaries (aliasing), a few 1e-3 of a row."""
    scene = workbench.load_scene("cornell")
    p, _ = patches_from_scene(scene, patch_size_for_count(scene, 600))
    g = p.geometry()
    _, _, blocks = grid_regions(g)
    assert len(blocks.cells) < 100 < len(g.tris)          # far fewer triangles to draw
    per_grid = [((blocks.cells[:, 0] >= gr.first) & (blocks.cells[:, 0] < gr.first + gr.nu * gr.nv)).sum()
                for gr in g.grids]
    warped = [gr for gr, k in zip(g.grids, per_grid) if k > 1]
    assert len(warped) == 1 and per_grid.count(1) == len(g.grids) - 1   # only the red wall
    on_warped = np.arange(warped[0].first, warped[0].first + warped[0].nu * warped[0].nv)
    sample = np.unique(np.concatenate([np.arange(0, len(p), 17), on_warped[::9]]))
    nblocks, agree, d = _agree(g, sample, 64)
    assert nblocks == len(blocks.cells)
    assert agree >= 0.999
    assert d.mean() < 3e-3 and d.max() < 0.03


def test_trapezoid_grid_inverse_bilinear(gl_ctx):
    """A strongly non-parallelogram convex quad cut 7 x 6, seen by a small patch facing it
    beside a pentagon (cut into triangle fans, drawn as its patches' own triangles in the same
    draw): the fragment shader's inverse bilinear map finds the same cells as the rasterised
    cells, and every cell is seen."""
    quad = np.array([[0, 0, 0], [3, 0, 0], [2.2, 1.7, 0], [0.4, 2.5, 0]], float)
    ang = np.linspace(0, 2 * np.pi, 5, endpoint=False)
    penta = np.stack([3.6 + 0.5 * np.cos(ang), 1.0 + 0.5 * np.sin(ang), 0.2 + 0 * ang], 1)
    eye = np.array([[1.2, 1.0, 1.5], [1.3, 1.0, 1.5], [1.3, 1.1, 1.5], [1.2, 1.1, 1.5]])[::-1]
    surfaces = [("polygon", quad, np.full(3, 0.5), np.zeros(3), None, "trapezoid"),
                ("polygon", penta, np.full(3, 0.5), np.zeros(3), None, "pentagon"),
                ("polygon", eye, np.full(3, 0.5), np.ones(3), None, "eye")]
    ps = _assemble(surfaces, 0.45)
    g = ps.geometry()
    assert (g.grids[0].nu, g.grids[0].nv) == (7, 6) and len(g.grids) == 2    # quad, eye
    viewer = np.array([len(ps) - 1])
    nblocks, agree, d = _agree(g, viewer, 128)
    assert nblocks == 1 and agree >= 0.999 and d.max() < 5e-3
    row = Hemicube(g, 128)
    try:
        r = row.rows(viewer)[0]
    finally:
        row.release()
    assert (r[:42] > 0).all() and r[42:-1].sum() > 0     # every cell, and the pentagon


def test_accumulate_items_is_bincount():
    rng = np.random.default_rng(0)
    P, res = 50, 8
    ids = rng.integers(0, P + 1, (3, res, 3 * res)).astype(np.uint32)
    w = delta_form_factors(res)
    out = np.zeros((3, P))
    accumulate_items(ids, w, out)
    for b in range(3):
        ref = np.bincount(ids[b].ravel(), weights=w.ravel(), minlength=P + 1)[1:]
        assert np.allclose(out[b], ref, rtol=1e-12, atol=0)
