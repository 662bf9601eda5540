"""The emitters of a scene as the path tracer samples them (next-event estimation), built from
the ray tracer's flattened arrays (:class:`..raytrace.flatten.SceneData`).

Every emissive surface the estimator can sample is cut into triangles: area lights and other
convex polygons (fan), rectangles (2), boxes (12) and the triangles of emissive meshes
(material emission or ``vertex_emission``).  A triangle is chosen with probability
proportional to its power ``A_e * mean(L_e)`` (its area times its mean radiance, the mean of
R, G, B), then a point uniformly on it (Shirley's square-root map), so the density of the
light strategy per unit area on a surface is ``mean(L_e) / sum_e A_e mean(L_e)`` (one value
per analytic primitive, one per mesh triangle): :attr:`Emitters.lpdf_prim`, :attr:`lpdf_tri`.

Emissive spheres, quadrics, CSG solids and concave polygons are not sampled: BSDF sampling
alone finds them (still unbiased, noisier); :attr:`Emitters.unsampled` says which.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.columns import cell
from ...core.tol import tol
from ...scene.kinds import BOX, KINDS, MESH, POLYGON, RECT
from ...scene.kinds.box import Par as BoxPar
from ...scene.kinds.plane import Par as RectPar
from ...scene.kinds.polygon import Par as PolygonPar
from ..kernels.columns import Mat
from ..raytrace.flatten import SceneData

_BOX_QUADS = ((0, 2, 6, 4), (1, 5, 7, 3), (0, 4, 5, 1), (2, 3, 7, 6), (0, 1, 3, 2), (4, 6, 7, 5))
"""Faces of a box as corner indices (corner ``c``: bit 0 = x max, bit 1 = y max, bit 2 = z max)."""


@dataclass
class Emitters:
    """Sampleable emitter triangles.

    tri : (E, 9) float64 world vertices; normal : (E, 3) unit normal (right-hand rule);
    prim : (E,) int64 primitive row; mesh_tri : (E,) int64 a row of the mesh triangle in the
    flattened triangle arrays (its first; the octree repeats a triangle) or -1;
    cdf : (E,) float64 cumulative selection probabilities (last 1);
    lpdf_prim : (P,) float64 light-strategy density per unit area on analytic primitive k
    (0: not sampled); lpdf_tri : (T,) the same on mesh triangles, per row of the flattened
    triangle arrays (equal on every row of one triangle);
    unsampled : reasons of the emitters left to BSDF sampling.
    """

    tri: np.ndarray
    normal: np.ndarray
    prim: np.ndarray
    mesh_tri: np.ndarray
    cdf: np.ndarray
    lpdf_prim: np.ndarray
    lpdf_tri: np.ndarray
    unsampled: list

    def arrays(self) -> tuple:
        """The tuple the kernels read: ``(tri, normal, prim, mesh_tri, cdf, lpdf_prim, lpdf_tri)``."""
        return (self.tri, self.normal, self.prim, self.mesh_tri, self.cdf, self.lpdf_prim, self.lpdf_tri)


def _world(W, pts):
    pts = np.asarray(pts, dtype=np.float64).reshape(-1, 3)
    return pts @ W[:3, :3].T + W[:3, 3]


def fan_triangles(poly):
    """Fan triangles (n - 2, 9) of a convex polygon, or None if it is not convex."""
    v0, a, b = poly[0], poly[1:-1], poly[2:]
    cr = np.cross(a - v0, b - v0)
    n = cr.sum(0)
    scale = np.linalg.norm(n)
    if scale <= tol.zero:
        return None
    # every fan triangle turns the same way, and every vertex is convex
    turns = np.cross(np.roll(poly, -1, 0) - poly, np.roll(poly, -2, 0) - np.roll(poly, -1, 0)) @ n
    if (cr @ n < 0.0).any() or (turns < -tol.planar * scale * scale).any():
        return None
    return np.concatenate([np.repeat(v0[None], len(a), 0), a, b], 1)


def _prim_triangles(sd: SceneData, k: int):
    """World triangles (n, 9) of analytic primitive ``k``, or None if it is not sampled."""
    W, par, kind = sd.wfo[k], sd.par[k], sd.ptype[k]
    if kind == POLYGON:
        s, n = int(cell(par, PolygonPar.FIRST)), int(cell(par, PolygonPar.COUNT))
        tris = fan_triangles(_world(W, sd.poly_v[s:s + n]))
        return tris
    if kind == RECT:
        p, u, v, hu, hv = (cell(par, c) for c in (RectPar.POINT, RectPar.U, RectPar.V, RectPar.HALF_U, RectPar.HALF_V))
        c = _world(W, [p - hu * u - hv * v, p + hu * u - hv * v, p + hu * u + hv * v, p - hu * u + hv * v])
        return np.stack([np.r_[c[0], c[1], c[2]], np.r_[c[0], c[2], c[3]]])
    if kind == BOX:
        lo, hi = cell(par, BoxPar.MIN), cell(par, BoxPar.MAX)
        corners = _world(W, [np.where([(c >> a) & 1 for a in range(3)], hi, lo) for c in range(8)])
        out = []
        for q in _BOX_QUADS:
            a, b, c, d = corners[list(q)]
            out += [np.r_[a, b, c], np.r_[a, c, d]]
        return np.stack(out)
    return None

def kind_name(ptype: int) -> str:
    """The scene-file name of the kind of a ``ptype`` (every registered kind, plugins included:
    an emissive blob, lathe, prism or isosurface named a ptype past a hand-written list of six
    and raised IndexError)."""
    return next((k.TYPE for k in KINDS.values() if k.PTYPE == ptype), "primitive")


def build_emitters(sd: SceneData) -> Emitters:
    """The emitter table of a flattened scene (see the module docstring)."""
    tris, prims, mtris, lums, unsampled = [], [], [], [], []
    emission = sd.mat_tab[:, Mat.EMISSION:Mat.EMISSION + 3]
    for k in range(len(sd.ptype)):
        if sd.ptype[k] == MESH or not sd.top[k]:
            continue
        le = emission[sd.mat[k]]
        if le.max() <= 0.0:
            continue
        t = _prim_triangles(sd, k)
        if t is None:
            unsampled.append(f"primitive {k} (object {sd.obj[k]}): an emissive "
                             f"{kind_name(int(sd.ptype[k]))} "
                             "is found by BSDF sampling only (no next-event estimation)")
            continue
        tris.append(t)
        prims += [k] * len(t)
        mtris += [-1] * len(t)
        lums += [le.mean()] * len(t)
    if len(sd.tri_v):
        # one entry per triangle, in the meshes' input order, whatever the structure's row order
        # (the octree's rows repeat a triangle once per cell it meets: sampled once per
        # reference, it would be chosen k times as often as its density says); its first row
        # stands for it
        _, first = np.unique(sd.tri_src, return_index=True)
        le = emission[sd.mat[sd.tri_prim[first]]] + sd.tri_e[first].reshape(-1, 3, 3).mean(1)
        lit = le.max(1) > 0.0
        sel = first[lit]
        tris.append(sd.tri_v[sel])
        prims += list(sd.tri_prim[sel])
        mtris += list(sel)
        lums += list(le[lit].mean(1))
    T = np.concatenate(tris) if tris else np.zeros((0, 9))
    e1, e2 = T[:, 3:6] - T[:, 0:3], T[:, 6:9] - T[:, 0:3]
    cr = np.cross(e1, e2)
    area = 0.5 * np.linalg.norm(cr, axis=1)
    keep = area > 0.0
    T, cr, area = T[keep], cr[keep], area[keep]
    prims = np.asarray(prims, np.int64)[keep]
    mtris = np.asarray(mtris, np.int64)[keep]
    lums = np.asarray(lums, np.float64)[keep]
    power = area * lums
    total = power.sum()
    lpdf_prim = np.zeros(len(sd.ptype))
    lpdf_src = np.zeros(sd.tri_src.max() + 1 if len(sd.tri_src) else 0)
    if total > 0.0:
        cdf = np.cumsum(power) / total
        cdf[-1] = 1.0
        dens = lums / total
        analytic = mtris < 0
        lpdf_prim[prims[analytic]] = dens[analytic]
        lpdf_src[sd.tri_src[mtris[~analytic]]] = dens[~analytic]
    else:
        cdf = np.zeros(0)
        T = T[:0]
    lpdf_tri = lpdf_src[sd.tri_src]  # every row of a triangle: a hit's row is any of them
    n = cr / np.maximum(2.0 * area, tol.zero)[:, None] if len(cr) else np.zeros((0, 3))
    m = len(cdf)
    return Emitters(np.ascontiguousarray(T[:m]), np.ascontiguousarray(n[:m]), prims[:m].copy(),
                    mtris[:m].copy(), np.ascontiguousarray(cdf), lpdf_prim, lpdf_tri, unsampled)
