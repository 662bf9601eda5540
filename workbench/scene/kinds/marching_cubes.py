"""Triangles of a level set ``v(x, y, z) = 0`` sampled on a grid: the raster path of the implicit
kinds (blob, isosurface).

Marching cubes (Lorensen & Cline, SIGGRAPH 1987) with each cube cut into six tetrahedra
around its main diagonal (Freudenthal's subdivision; "marching tetrahedra", Doi & Koide,
IEICE Trans. 1991): a tetrahedron has only three cases (one corner apart from three: one
triangle; two from two: a quad), with no ambiguous face and no 256-entry table, and since
neighbouring cubes cut their shared face along the same diagonal, the mesh has no cracks.
Each edge's vertex is the linear interpolation of the samples' zero crossing, shared by every
triangle that uses that edge (an indexed mesh); given the field itself, the vertex is then moved
along its edge onto the level set (:func:`edge_roots`): linear interpolation of a field that is
not linear (a blob's falloff) puts a coarse mesh off the surface by a good part of a cell, on
either side, while a mesh whose vertices lie on a convex surface stays inside it.

Inside is ``v < 0``; triangles wind counter-clockwise seen from outside (``v >= 0``).  The
work goes in slabs of cubes along x so that memory stays proportional to one slab and the
triangles; :func:`grid_cells` checks the grid against the memory limit before anything is
sampled.
"""
from __future__ import annotations

from itertools import permutations

import numpy as np

from ...core.errors import WorkbenchError
from ...core.memory import gib, memory_limit

# the six tetrahedra of a cube: corners 0 -> e_a -> e_a + e_b -> 7 for each order (a, b, c) of
# the axes; corner code = x + 2 y + 4 z
_TETS = np.array([[0, 1 << a, (1 << a) | (1 << b), 7] for a, b, _ in permutations(range(3))],
                 dtype=np.int64)
_BYTES_PER_CELL = 6 * 4 * 8 * 6
"""Estimated peak bytes per cube of a slab (six tetrahedra, four corners, a few int64/float64
work arrays each) and per grid sample."""
MAX_RESOLUTION = 1024
"""Most cells a grid may have along one axis."""
ROOT_STEPS = 8
"""Illinois steps of :func:`edge_roots` (superlinear: eight take a smooth field's root on a
cell's edge to about 1e-12 of the edge)."""


def grid_cells(lo, hi, resolution: int, what: str) -> tuple[int, int, int]:
    """Cells along x, y, z of a grid over the box ``[lo, hi]`` with ``resolution`` cells along its
    longest side (cubic cells, at least one per axis), checked against the memory limit.

    Raises :class:`WorkbenchError` (naming ``what``) when the grid would not fit."""
    if not 1 <= resolution <= MAX_RESOLUTION:
        raise WorkbenchError(f"{what}: marching-cubes resolution {resolution} outside 1..{MAX_RESOLUTION}")
    ext = np.asarray(hi, dtype=np.float64) - np.asarray(lo, dtype=np.float64)
    h = ext.max() / resolution
    n = tuple(max(1, int(round(e / h))) for e in ext)
    need = (n[0] + 3) * (n[1] + 3) * (n[2] + 3) * 8 + (n[1] + 2) * (n[2] + 2) * _BYTES_PER_CELL
    if need > memory_limit():
        raise WorkbenchError(f"{what}: a {n[0]}x{n[1]}x{n[2]} marching-cubes grid needs about "
                             f"{gib(need)}, over the memory limit of {gib(memory_limit())}")
    return n


def edge_roots(field, A: np.ndarray, B: np.ndarray, fa: np.ndarray, fb: np.ndarray,
               w: np.ndarray) -> np.ndarray:
    """Roots of ``field`` on segments, by the Illinois variant of regula falsi (Dowell &
    Jarratt, BIT 1971): the bracket shrinks at every step, and halving the value kept on the
    same side twice in a row makes the convergence superlinear.

    Parameters
    ----------
    field : callable, (n, 3) points -> (n,) values; NaN counts as outside (positive).
    A, B : (n, 3) the segments' ends, ``field(A) = fa < 0 <= fb = field(B)``.
    w : (n,) the starting estimates in ``[0, 1]`` (the linear interpolation).

    Returns ``(n,)`` fractions along ``A -> B``, within the final bracket.
    """
    a, b = np.zeros_like(w), np.ones_like(w)
    fa, fb = fa.astype(np.float64), fb.astype(np.float64)
    side = np.zeros(len(w), dtype=np.int8)  # the end moved last: -1 a, +1 b
    for _ in range(ROOT_STEPS):
        f = np.asarray(field(A + w[:, None] * (B - A)), dtype=np.float64)
        f = np.where(np.isnan(f), np.abs(fa), f)  # outside, of an arbitrary size
        inside = f < 0.0
        fb = np.where(inside & (side == -1), 0.5 * fb, fb)
        fa = np.where(~inside & (side == 1), 0.5 * fa, fa)
        a, fa = np.where(inside, w, a), np.where(inside, f, fa)
        b, fb = np.where(inside, b, w), np.where(inside, fb, f)
        side = np.where(inside, -1, 1).astype(np.int8)
        den = fb - fa
        w = np.where(den > 0.0, a - fa * (b - a) / np.where(den > 0.0, den, 1.0), 0.5 * (a + b))
        w = np.clip(w, a, b)
    return w


def marching_cubes(values: np.ndarray, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray, field=None):
    """Triangulate the zero set of grid samples.

    Parameters
    ----------
    values : (X, Y, Z) float64 samples ``v(xs[i], ys[j], zs[k])``; NaN counts as outside.
    xs, ys, zs : (X,), (Y,), (Z,) non-decreasing coordinates of the grid planes (a repeated
        coordinate makes a flat layer of cells: padding a grid with copies of its first and
        last planes sampled as outside closes the surface on the grid's faces).
    field : optional callable, (n, 3) points -> (n,) values of ``v``: each vertex is moved
        along its edge onto ``v = 0`` (:func:`edge_roots`).

    Returns
    -------
    P : (V, 3) float64 vertices (on cube edges: linearly interpolated, or on the level set).
    F : (T, 3) int64 faces, counter-clockwise seen from the outside.  Vertices at the same
        position are merged (a sample exactly at the level, a flat layer) and the triangles
        that collapse to a segment or a point are left out.
    """
    v = np.where(np.isnan(values), 1.0, values).astype(np.float64)
    X, Y, Z = v.shape
    inside = v < 0.0
    # linear index offset of each cube corner
    corner = np.array([((c & 1) * Y + ((c >> 1) & 1)) * Z + ((c >> 2) & 1) for c in range(8)])
    flat_v, flat_in = v.reshape(-1), inside.reshape(-1)
    keys, tris = [], []
    jj, kk = np.meshgrid(np.arange(Y - 1), np.arange(Z - 1), indexing="ij")
    base_yz = (jj * Z + kk).reshape(-1)
    for i in range(X - 1):
        base = i * Y * Z + base_yz
        cin = flat_in[base[:, None] + corner]                       # (cubes, 8)
        mixed = cin.any(1) & ~cin.all(1)
        if not mixed.any():
            continue
        g = (base[mixed][:, None, None] + corner[_TETS][None]).reshape(-1, 4)   # (tets, 4)
        s = flat_in[g]
        cnt = s.sum(1)
        keep = (cnt > 0) & (cnt < 4)
        g, s, cnt = g[keep], s[keep], cnt[keep]
        order = np.argsort(~s, axis=1, kind="stable")               # inside corners first
        a = np.take_along_axis(g, order, 1)
        for c, pairs in ((1, ((0, 1), (0, 2), (0, 3))), (3, ((0, 3), (1, 3), (2, 3))),
                         (2, ((0, 2), (0, 3), (1, 3), (1, 2)))):
            sel = a[cnt == c]
            if not len(sel):
                continue
            e = np.stack([np.sort(sel[:, list(p)], axis=1) for p in pairs], 1)   # (n, 3|4, 2)
            keys.append(e[:, [0, 1, 2]])
            tris.append(sel)
            if c == 2:
                keys.append(e[:, [0, 2, 3]])
                tris.append(sel)
    if not keys:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    e = np.concatenate(keys)                                            # (T, 3, 2) grid indices
    tets = np.concatenate(tris)                                         # (T, 4), inside first
    n_pts = X * Y * Z
    uniq, inv = np.unique((e[..., 0] * n_pts + e[..., 1]).reshape(-1), return_inverse=True)
    p_idx, q_idx = uniq // n_pts, uniq % n_pts
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), -1).reshape(-1, 3)
    vp, vq = flat_v[p_idx], flat_v[q_idx]
    den = vp - vq
    w = np.clip(np.divide(vp, den, out=np.zeros_like(vp), where=den != 0.0), 0.0, 1.0)
    if field is not None:  # edges of non-zero length with the level strictly inside
        long_ = (grid[p_idx] != grid[q_idx]).any(1)
        r = np.flatnonzero((vp < 0.0) & (vq > 0.0) & long_)
        w[r] = edge_roots(field, grid[p_idx[r]], grid[q_idx[r]], vp[r], vq[r], w[r])
        r = np.flatnonzero((vq < 0.0) & (vp > 0.0) & long_)  # inside end last: from q to p
        w[r] = 1.0 - edge_roots(field, grid[q_idx[r]], grid[p_idx[r]], vq[r], vp[r], 1.0 - w[r])
    w = w[:, None]
    P = grid[p_idx] + w * (grid[q_idx] - grid[p_idx])
    F = inv.reshape(-1, 3).astype(np.int64)
    # orient: the face normal points from the tetrahedron's inside corners to its outside ones,
    # decided in grid-index space, where no cell is flat (the grid map is diagonal and
    # non-decreasing per cell, so it keeps the sign of the normal's component along any axis
    # it does not flatten, and a flattened triangle's only normal component is along that axis)
    def index_xyz(lin):
        return np.stack([lin // (Y * Z), (lin // Z) % Y, lin % Z], -1).astype(np.float64)
    Q = index_xyz(p_idx) + w * (index_xyz(q_idx) - index_xyz(p_idx))
    n = np.cross(Q[F[:, 1]] - Q[F[:, 0]], Q[F[:, 2]] - Q[F[:, 0]])
    ins = flat_in[tets]
    cpos = index_xyz(tets)
    out_dir = ((cpos * (~ins)[..., None]).sum(1) / (~ins).sum(1)[:, None]
               - (cpos * ins[..., None]).sum(1) / ins.sum(1)[:, None])
    flip = (n * out_dir).sum(1) < 0.0
    F[flip] = F[flip][:, ::-1]
    # a sample exactly at the level puts the vertices of all its edges on it: merge vertices
    # at one position and drop the triangles that collapse (keeps every edge used twice)
    P, same = np.unique(P, axis=0, return_inverse=True)
    F = same.reshape(-1)[F]
    good = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])
    return P, F[good]


def closed_grid(lo, hi, cells) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coordinates of a grid of ``cells`` over the box, each axis padded with a copy of its
    first and last plane (sample the padding as outside to close the surface on the box)."""
    return tuple(np.concatenate([[a], np.linspace(a, b, n + 1), [b]])
                 for a, b, n in zip(lo, hi, cells))


def pad_outside(values: np.ndarray) -> np.ndarray:
    """``values`` (X, Y, Z) with one layer of ``+1`` (outside) around it (see :func:`closed_grid`)."""
    return np.pad(values, 1, constant_values=1.0)


def shade_normals(P: np.ndarray, F: np.ndarray, gradient, lo, hi):
    """Vertex normals of a marching-cubes mesh of a solid cut by the box ``[lo, hi]``.

    Triangles lying in a face of the box (the caps) get that face's outward normal on
    vertices of their own; the others get ``gradient(P)`` normalised (the outward direction,
    where the sampled value increases), or their area-weighted face normal where the gradient
    is zero or not finite.

    Returns ``(P, N, F)``: (V', 3) vertices, (V', 3) unit normals, (T, 3) faces.
    """
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    cap_normal = np.zeros((len(F), 3))
    for axis in range(3):
        for side, plane in ((-1.0, lo[axis]), (1.0, hi[axis])):
            on = (P[F, axis] == plane).all(1)
            cap_normal[on, axis] = side
    is_cap = cap_normal.any(1)
    # the surface part keeps shared vertices with gradient normals
    G = np.asarray(gradient(P), dtype=np.float64).reshape(-1, 3)
    ln = np.linalg.norm(G, axis=1, keepdims=True)
    fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    acc = np.zeros_like(P)
    for c in range(3):
        np.add.at(acc, F[~is_cap, c], fn[~is_cap])
    la = np.linalg.norm(acc, axis=1, keepdims=True)
    fallback = np.divide(acc, la, out=np.tile([0.0, 1.0, 0.0], (len(P), 1)), where=la > 0.0)
    good = np.isfinite(ln) & (ln > 0.0)
    N = np.where(good, G / np.where(good, ln, 1.0), fallback)
    cf = F[is_cap]
    Pc = P[cf].reshape(-1, 3)
    Nc = np.repeat(cap_normal[is_cap], 3, axis=0)
    # a cap triangle winds counter-clockwise seen along its face normal
    cn = np.cross(P[cf[:, 1]] - P[cf[:, 0]], P[cf[:, 2]] - P[cf[:, 0]])
    back = (cn * cap_normal[is_cap]).sum(1) < 0.0
    Fc = (len(P) + np.arange(3 * len(cf))).reshape(-1, 3)
    Fc[back] = Fc[back][:, ::-1]
    P, N, F = np.concatenate([P, Pc]), np.concatenate([N, Nc]), np.concatenate([F[~is_cap], Fc])
    used, F = np.unique(F, return_inverse=True)      # drop the vertices only caps used
    return P[used], N[used], F.reshape(-1, 3).astype(np.int64)
