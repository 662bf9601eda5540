"""BVH build: complete on degenerate input; the 4-wide tree of the ray tracer holds every
triangle once, inside its boxes, and its traversal equals brute force."""
from __future__ import annotations

import numpy as np
import pytest


def test_a_degenerate_tree_stops_at_max_depth_and_is_traversed_exactly(bvh_hit):
    # triangles at x = 100 * 2^-k: every SAH split peels one off; the tree stops at MAX_DEPTH
    # with a large leaf, so that no traversal stack ever overflows, and every hit is found
    from workbench.renderers.kernels import walks
    from workbench.renderers.raytrace import shapes
    from workbench.renderers.raytrace.bvh import MAX_DEPTH, build_bvh, build_bvh4
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
    assert depth.max() == MAX_DEPTH
    assert np.array_equal(np.sort(order), np.arange(n))
    assert meta[meta[:, 2] == -1, 1].sum() == n
    order, bvh = build_bvh4(tri.reshape(n, 9))
    tvo = np.ascontiguousarray(tri.reshape(n, 9)[order])
    stack = np.empty((walks.BVH_STACK, 2))
    arrays = (bvh.node, bvh.child, bvh.leaf, bvh.first, bvh.tv4)
    for k in (0, 5, 59, 61, 300, 1000):  # along the x axis through the triangles, from afar
        o = np.array([-1.0, 2e-4, 2e-4])
        d = np.array([1.0, 0.0, 0.0])
        tb = shapes.triangles(tvo.reshape(-1, 3, 3), o, d)[0]
        t = bvh_hit(arrays, *o, *d, x[k] + 1.0 - 1e-12, np.inf, np.bool_(False), stack)[0]
        expected = np.where(tb > x[k] + 1.0 - 1e-12, tb, np.inf).min()
        assert t == pytest.approx(expected, rel=1e-12)


def _soup(seed, n):
    """``n`` random triangles plus eight copies of one (same centroid: a leaf the SAH cannot
    split, more than one group of four, its last group full of the same triangle)."""
    rng = np.random.default_rng(seed)
    c = rng.uniform(-5, 5, size=(n, 1, 3))
    tri = c + rng.normal(scale=0.4, size=(n, 3, 3))
    same = np.repeat(np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]), 8, axis=0)
    return np.concatenate([tri, same]).reshape(-1, 9)


def _subtree(bvh, leaves, code):
    """Triangles (BVH order) under child code ``code`` of the 4-wide tree; ``leaves``: the
    collapse's (first, count) of each leaf."""
    if code == -1:
        return []
    if code < -1:
        first, count = leaves[-2 - code]
        return list(range(first, first + count))
    return [t for j in range(4) for t in _subtree(bvh, leaves, bvh.child[code, j])]


@pytest.mark.parametrize("n", [2, 300])
def test_4wide_tree_holds_each_triangle_once_inside_its_boxes(n):
    from workbench.renderers.raytrace.bvh import _collapse, build_bvh, build_bvh4
    tv = _soup(1, n)
    order, bvh = build_bvh4(tv)
    leaves = _collapse(*build_bvh(tv)[1:])[2]
    assert np.array_equal(bvh.leaf[:, 1], (leaves[:, 1] + 3) // 4)  # groups of four per leaf
    tvo = tv[order]
    seen = []
    for q in range(len(bvh.child)):
        for j in range(4):
            code = bvh.child[q, j]
            lo, hi = bvh.node[q, :3, j], bvh.node[q, 3:, j]
            tris = _subtree(bvh, leaves, code)
            if code == -1:
                assert (lo == np.inf).all() and (hi == -np.inf).all()
                continue
            v = tvo[tris].reshape(-1, 3)
            assert (v >= lo).all() and (v <= hi).all()
            if code < -1:
                seen += tris
    assert sorted(seen) == list(range(len(tv)))
    # groups hold the BVH-ordered vertices, lanes side by side, a short group repeating its last
    for (first, count), (g0, ng) in zip(leaves, bvh.leaf):
        for g in range(g0, g0 + ng):
            lanes = [min(bvh.first[g] + j, first + count - 1) for j in range(4)]
            assert np.array_equal(bvh.tv4[g].T, tvo[lanes])
    assert np.array_equal(bvh.bounds, np.r_[tv.reshape(-1, 3).min(0), tv.reshape(-1, 3).max(0)])


def test_4wide_traversal_equals_brute_force_closest_and_any_hit(bvh_hit):
    from workbench.renderers.kernels import walks
    from workbench.renderers.raytrace import shapes
    from workbench.renderers.raytrace.bvh import build_bvh4
    tv = _soup(2, 400)
    order, bvh = build_bvh4(tv)
    tvo = np.ascontiguousarray(tv[order])
    rng = np.random.default_rng(3)
    O = rng.uniform(-8, 8, size=(300, 3))
    D = rng.uniform(-3, 3, size=(300, 3)) - O
    D[:20] = [0.1, 0.05, 1.0] - O[:20]  # at the eight stacked triangles
    stack = np.empty((walks.BVH_STACK, 2))
    arrays = (bvh.node, bvh.child, bvh.leaf, bvh.first, bvh.tv4)
    hits = 0
    for o, d in zip(O, D):
        tb, _, _ = shapes.triangles(tvo.reshape(-1, 3, 3), o, d)
        tb = np.where(tb > 1e-9, tb, np.inf)
        t, tri, b1, b2, _, _ = bvh_hit(arrays, *o, *d, 1e-9, np.inf, np.bool_(False), stack)
        if np.isfinite(tb.min()):
            hits += 1
            assert t == pytest.approx(tb.min(), rel=1e-9)
            assert tb[tri] == pytest.approx(t, rel=1e-9)  # the triangle it names is hit there
            p = o + t * d
            v = tvo[tri].reshape(3, 3)
            assert np.allclose((1 - b1 - b2) * v[0] + b1 * v[1] + b2 * v[2], p, atol=1e-9)
        else:
            assert tri == -1 and np.isinf(t)
        # any hit: some triangle within [tmin, tmax] iff brute force has one
        ta, tria, _, _, _, _ = bvh_hit(arrays, *o, *d, 1e-9, 0.5, np.bool_(True), stack)
        assert (tria >= 0) == bool((tb < 0.5).any())
        if tria >= 0:
            assert ta < 0.5 and tb[tria] == pytest.approx(ta, rel=1e-9)
    assert hits > 60


def _readable_sah(tri_v):
    """The binned SAH tree of :func:`.bvh.build_bvh` written plainly (recursion, numpy, every
    node's bounds rescanned): ``[(box, axis or -1, leaf triangle set or None), ...]`` in depth
    first order, left child first.  A node of ``n >= 2 BIN_SAMPLES`` triangles estimates the SAH
    from every ``(n // BIN_SAMPLES)``-th of them in the build's order (after its partitions'
    swaps): this plain build keeps the input order, so it is the same only where no node
    below the root is sampled (asserted).  A node of at most ``SMALL_NODE`` triangles uses
    ``SMALL_NODE_BINS`` bins."""
    from workbench.renderers.raytrace.bvh import (BIN_SAMPLES, GROUP, MAX_DEPTH, N_BINS, SMALL_NODE,
                                                  SMALL_NODE_BINS, TRAVERSAL_COST, TRI_LEAF)
    t = tri_v.reshape(-1, 3, 3)
    tb = np.concatenate([t.min(1), t.max(1)], 1)
    cen = 0.5 * (tb[:, :3] + tb[:, 3:])

    def area(b):
        d = b[3:] - b[:3]
        return 0.0 if d[0] < 0 else d[0] * d[1] + d[1] * d[2] + d[2] * d[0]

    def union(rows):
        return np.concatenate([rows[:, :3].min(0), rows[:, 3:].max(0)]) if len(rows) else np.r_[[np.inf] * 3, [-np.inf] * 3]

    def groups(n):  # the SAH's count of triangles: packed groups
        return -(-n // GROUP)

    out = []

    def node(ids, depth):
        assert depth == 0 or len(ids) < 2 * BIN_SAMPLES  # see the docstring
        box = union(tb[ids])
        cmin, ext = cen[ids].min(0), cen[ids].max(0) - cen[ids].min(0)
        rec = [box, -1, None]
        out.append(rec)
        if len(ids) <= TRI_LEAF or not ext.max() > 0.0 or depth >= MAX_DEPTH:
            rec[2] = set(ids.tolist())
            return
        best, best_b, axis = np.inf, -1, 0
        nbins = N_BINS if len(ids) > SMALL_NODE else SMALL_NODE_BINS
        for ax in range(3):
            if not ext[ax] > 0.0:
                continue
            smp = ids[::max(1, len(ids) // BIN_SAMPLES)]
            bins = ((cen[smp, ax] - cmin[ax]) * (nbins * (1.0 - 1e-9) / ext[ax])).astype(int)
            for b in range(nbins - 1):
                left, right = smp[bins <= b], smp[bins > b]
                if len(left) and len(right):
                    c = area(union(tb[left])) * groups(len(left)) + area(union(tb[right])) * groups(len(right))
                    if c < best:
                        best, best_b, axis = c, b, ax
        if best_b < 0 or (TRAVERSAL_COST + best / max(area(box), 1e-300) >= groups(len(ids))
                          and len(ids) <= 4 * TRI_LEAF):
            rec[2] = set(ids.tolist())
            return
        rec[1] = axis
        bins = ((cen[ids, axis] - cmin[axis]) * (nbins * (1.0 - 1e-9) / ext[axis])).astype(int)
        node(ids[bins <= best_b], depth + 1)
        node(ids[bins > best_b], depth + 1)

    node(np.arange(len(tb)), 0)
    return out


def test_the_fast_build_makes_the_readable_builds_tree():
    # the numba build keeps boxes and centroids in idx order, takes a node's bounds from its
    # parent's partition and bins three axes in one pass; the tree must be the plain one
    from workbench.renderers.raytrace.bvh import build_bvh
    from workbench.renderers.raytrace.bvh import BIN_SAMPLES
    for seed, n in ((1, 700), (2, 300), (3, 2 * BIN_SAMPLES + 100)):  # the last: its root is sampled
        tri = _soup(seed, n)
        order, box, meta = build_bvh(tri)
        ref = _readable_sah(tri)
        assert len(ref) == len(box)
        for i, (rbox, axis, leaf) in enumerate(ref):
            assert np.array_equal(box[i], rbox)
            assert meta[i, 2] == axis
            if leaf is not None:
                assert set(order[meta[i, 0]:meta[i, 0] + meta[i, 1]].tolist()) == leaf


def test_two_thread_build_is_the_one_thread_tree_node_for_node():
    """From ``PARALLEL_MIN`` items the root's subtrees are built by two threads and renumbered:
    the same order, boxes and meta as one depth-first pass over the whole range."""
    from workbench.renderers.raytrace import bvh as B
    rng = np.random.default_rng(5)
    c = np.concatenate([rng.normal(0, 1, (3 * B.PARALLEL_MIN, 3)), rng.normal(4, 0.1, (B.PARALLEL_MIN, 3))])
    h = rng.uniform(0.001, 0.05, c.shape)
    tb = np.concatenate([c - h, c + h], axis=1)
    one = tb.copy()
    idx = np.arange(len(one))
    box, meta, pending, _ = B._build_nodes(one, idx, 0, len(one), 0, B._root_bounds(one), 2 * len(one), B.MAX_LEAF, 1)
    assert len(pending) == 0
    order2, box2, meta2 = B._build(tb.copy())
    assert len(box) > 1000 and (meta[:, 2] == -1).sum() > 500  # a real tree, both subtrees deep
    assert np.array_equal(order2, idx) and np.array_equal(box2, box) and np.array_equal(meta2, meta)


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_a_tree_of_a_few_boxes_is_the_builders_tree(n):
    """At most ``MAX_LEAF`` boxes make one leaf at the root without the numba builder
    (``_root_leaf``): node for node the tree the builder makes of them."""
    from workbench.renderers.raytrace.bvh import MAX_LEAF, _build, _collapse, build_box_tree
    assert n <= MAX_LEAF
    rng = np.random.default_rng(n)
    lo = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-6, 7)
    boxes = np.concatenate([lo, lo + rng.random((n, 3))], axis=1)
    order, tree = build_box_tree(boxes)
    b_order, box, meta = _build(boxes.copy())
    for got, want in zip((order, *tree), (b_order, *_collapse(box, meta))):
        assert got.dtype == want.dtype and np.array_equal(got, want)


@pytest.mark.parametrize("n", [5, 37, 128])
def test_a_small_build_in_python_is_the_compiled_builds_tree(n, monkeypatch):
    """Up to ``SMALL_BUILD`` items the builder runs as Python (no compile on a cold cache):
    node for node, packed group for packed group, the tree of the compiled builder, for boxes
    (the analytic primitives' tree) and triangles."""
    from workbench.renderers.raytrace import bvh
    assert n <= bvh.SMALL_BUILD and max(n - 8, 1) + 8 <= bvh.SMALL_BUILD
    rng = np.random.default_rng(n)
    lo = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-6, 7)
    boxes = np.concatenate([lo, lo + rng.random((n, 3))], axis=1)
    tri = _soup(n, max(n - 8, 1))  # at most n triangles
    small = (bvh.build_box_tree(boxes.copy()), bvh.build_bvh4(tri))
    monkeypatch.setattr(bvh, "SMALL_BUILD", 0)
    compiled = (bvh.build_box_tree(boxes.copy()), bvh.build_bvh4(tri))
    for (o_s, t_s), (o_c, t_c) in zip(small, compiled):
        for got, want in zip((o_s, *t_s), (o_c, *t_c)):
            assert got.dtype == want.dtype and np.array_equal(got, want)
