"""Traversal statistics of the acceleration structures, the triangles' and the analytic
primitives' (option ``traversal_stats``):
nodes visited and primitives tested per camera ray, counted in a pass of their own by the
rendering kernels' walks with their counters switched on (switched off in a render, the
counting compiles away; the pass costs about one more trace of the pixel centres and is timed
apart, ``timings["traversal_stats"]``).

:func:`count_hit` is :func:`..kernels.walks.bvh_hit`'s own walk (:func:`..kernels.walks.bvh_walk`)
with its two counters switched on: the same box and triangle tests in the same order, so it
returns the same hit (tested) and its counts are the real traversal's; the analytic
primitives' tree is walked by :func:`..kernels.intersect.prim_tree_walk`, counting likewise.  Counting rules,
per ray and per structure (the triangles', the analytic primitives'):

* nodes: 1 for the structure's root box (:func:`..kernels.intersect.closest`'s bounds test), plus one
  per further 4-wide node whose children's boxes the ray tests (the root's own visit is the
  bounds test's: a ray that misses the root box visits 1 node, one that enters it visits the
  root and the nodes it goes on to).  Rays that meet no box are counted too.  A scene without
  triangles counts the triangles' 1; without a tree of analytic primitives (``accel=none``,
  or every primitive unbounded), nothing for it.
* triangle tests: four per leaf group tested (a group's lanes are tested side by side; a
  group of fewer than four triangles repeats its last one).
* analytic tests: one per primitive of the list (tested by every ray) and one per primitive
  of a leaf of the tree the ray visits (a primitive referenced by several octree cells is
  counted at each).
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba import prange

from ...core.tol import tol
from ..kernels.columns import TRAVERSAL_COUNTS, TraversalCount, WalkCount
from ..kernels.flags import NO_REFCOUNT
from ..kernels.intersect import nearer, prim_tree_walk, reach, row_hit, scratch
from ..kernels.walks import _bounds_hit, bvh_walk
from .kernels import CHUNK, _tasks

_TRI, _AN = int(TraversalCount.TRIANGLES), int(TraversalCount.ANALYTIC)
"""The first columns of the triangles' and the analytic primitives' :class:`WalkCount` pairs."""
TRI_NODES, TRI_TESTS = _TRI + WalkCount.NODES, _TRI + WalkCount.TESTS
AN_NODES, AN_TESTS = _AN + WalkCount.NODES, _AN + WalkCount.TESTS
_TRI_END, _AN_END = _TRI + TraversalCount.TRIANGLES.span, _AN + TraversalCount.ANALYTIC.span


@nb.njit(**NO_REFCOUNT)
def count_hit(bvh, ox, oy, oz, dx, dy, dz, tmin, tmax, stack, cnt):
    """:func:`..kernels.walks.bvh_hit`'s closest-hit traversal (:func:`..kernels.walks.bvh_walk`),
    adding the 4-wide nodes visited and the triangle tests to ``cnt``
    (:class:`..kernels.columns.WalkCount`).
    Returns ``(t, tri)``."""
    t, tri, _, _, _, _ = bvh_walk(bvh, ox, oy, oz, dx, dy, dz, tmin, tmax, False, stack, True, cnt)
    return t, tri


@nb.njit(**NO_REFCOUNT)
def _count_chunk(geo_analytic, bvh, bounds, has_tri, O, D, zero, rel_eps, extent, counts, i0, i1, scr):
    stack, st, sp_, sf, sn = scr
    free, pref, pbounds = geo_analytic.pfree, geo_analytic.pref, geo_analytic.pbounds
    for i in range(i0, i1):
        ox, oy, oz, dx, dy, dz = O[i, 0], O[i, 1], O[i, 2], D[i, 0], D[i, 1], D[i, 2]
        eps = rel_eps * max(max(abs(ox), abs(oy), abs(oz)), extent)
        inv_w = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
        # the analytic primitives' nearest hit, as closest finds it (the list, then the
        # tree), counted: it is the far end of the triangles' search
        best, brow, w = np.inf, -1, eps * inv_w
        counts[i, AN_NODES], counts[i, AN_TESTS] = 0, 0
        for q in range(free.shape[0]):
            counts[i, AN_TESTS] += 1
            t, p, f = row_hit(geo_analytic, free[q], ox, oy, oz, dx, dy, dz, inv_w, 0.0,
                              reach(best, brow, w, np.inf), zero, eps, stack, st, sp_, sf, sn)
            if nearer(t, free[q], best, brow, w, np.inf):
                best, brow = t, free[q]
        if pref.shape[0] > 0:
            if _bounds_hit(pbounds, ox, oy, oz, dx, dy, dz, 0.0, reach(best, brow, w, np.inf)):
                t, _, _, row = prim_tree_walk(geo_analytic, ox, oy, oz, dx, dy, dz, inv_w, 0.0, np.inf, best, brow,
                                              False, False, zero, eps, stack, st, sp_, sf, sn, True,
                                              counts[i, _AN:_AN_END])
                if row >= 0:
                    best, brow = t, row
            else:
                counts[i, AN_NODES] = 1
        counts[i, TRI_NODES], counts[i, TRI_TESTS] = 1, 0
        lim = reach(best, brow, w, np.inf)
        if has_tri and _bounds_hit(bounds, ox, oy, oz, dx, dy, dz, 0.0, lim):
            counts[i, TRI_NODES] = 0
            count_hit(bvh, ox, oy, oz, dx, dy, dz, 0.0, lim, stack,
                      counts[i, _TRI:_TRI_END])


@nb.njit(cache=True, error_model="numpy", parallel=True)
def count_rays(geo_analytic, bvh, bounds, has_tri, O, D, zero, rel_eps, extent, counts):
    """Per ray ``counts[i]`` (columns :class:`..kernels.columns.TraversalCount`: nodes visited
    and tests, in the triangles' structure and in the analytic primitives') of the closest-hit
    search from ``t = 0`` (see the module docstring); ``geo_analytic`` is the kernels' geometry tuple without its triangles."""
    n = O.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    nit = _tasks(nchunks)
    for c in prange(nit):
        scr = scratch()
        for q in range(c, nchunks, nit):
            _count_chunk(geo_analytic, bvh, bounds, has_tri, O, D, zero, rel_eps, extent, counts,
                         q * CHUNK, min(n, (q + 1) * CHUNK), scr)


def ray_counts(sd, O: np.ndarray, D: np.ndarray) -> np.ndarray:
    """(N, TRAVERSAL_COUNTS) int64 per ray ``O + t D``, t >= 0, of the flattened scene ``sd``
    (:class:`.flatten.SceneData`; columns :class:`..kernels.columns.TraversalCount`): nodes
    visited and tests in the triangles' structure and in the analytic primitives' (the list's
    primitives counted as tests)."""
    geo = sd.kernel_args()._replace(tri_v=np.zeros((0, 9)))  # the analytic primitives only
    b = sd.bvh
    counts = np.zeros((len(O), TRAVERSAL_COUNTS), dtype=np.int64)
    count_rays(geo, (b.node, b.child, b.leaf, b.first, b.tv4), b.bounds, len(sd.tri_v) > 0,
               np.ascontiguousarray(O, dtype=np.float64), np.ascontiguousarray(D, dtype=np.float64),
               tol.zero, tol.ray_offset, sd.extent, counts)
    return counts


def primary_ray_counts(sd, O: np.ndarray, D: np.ndarray) -> dict:
    """The render's ``stats`` entries from its camera rays ``O, D`` (N, 3), means over the
    rays: nodes visited in both structures (``accel_nodes_per_ray``; the triangles' alone
    ``accel_triangle_nodes_per_ray``, the analytic primitives' ``accel_analytic_nodes_per_ray``),
    triangle tests (``accel_triangle_tests_per_ray``), analytic primitive tests
    (``accel_analytic_tests_per_ray``) and both (``accel_primitive_tests_per_ray``)."""
    c = ray_counts(sd, O, D).mean(axis=0)
    tri_nodes, tri_tests = float(c[TRI_NODES]), float(c[TRI_TESTS])
    an_nodes, an_tests = float(c[AN_NODES]), float(c[AN_TESTS])
    return {"accel_nodes_per_ray": tri_nodes + an_nodes,
            "accel_triangle_nodes_per_ray": tri_nodes, "accel_analytic_nodes_per_ray": an_nodes,
            "accel_triangle_tests_per_ray": tri_tests, "accel_analytic_tests_per_ray": an_tests,
            "accel_primitive_tests_per_ray": tri_tests + an_tests}
