"""BVH build: complete on degenerate input."""
from __future__ import annotations

import numpy as np


def test_a_degenerate_very_deep_tree_builds_completely():
    # triangles at x = 100 * 2^-k: every SAH split peels one off, a tree over 256 levels deep
    # (more than the build's first stack holds)
    from workbench.renderers.raytrace.bvh import build_bvh
    n = 1200
    x = 100.0 * 2.0 ** -np.arange(n)
    tri = np.zeros((n, 3, 3))
    tri[:, :, 0] = x[:, None]
    tri[:, 1, 1] = tri[:, 2, 2] = 1e-3
    order, box, meta = build_bvh(tri.reshape(n, 9))
    depth = np.zeros(len(box), dtype=int)
    for i in range(len(box)):
        if meta[i, 2] != -1:
            depth[i + 1] = depth[meta[i, 0]] = depth[i] + 1
    assert depth.max() > 256
    assert np.array_equal(np.sort(order), np.arange(n))
    assert meta[meta[:, 2] == -1, 1].sum() == n
