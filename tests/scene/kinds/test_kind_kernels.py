"""The ray tracer's kernels dispatch the new kinds (blob, isosurface, lathe, prism) through their
rows of the primitive table and the flat aux array: closest hits and normals of
``trace_batch`` against the readable twins, with transformed objects and a CSG difference of
two new kinds.  The rows are written by hand here (what the flattening step of each kind will
write), appended to a flattened one-sphere scene."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from seen_pixels import scene_dict
from workbench.core.tol import tol
from workbench.renderers.raytrace import flatten as fl
from workbench.renderers.raytrace.whitted import _alloc, _kernels
from workbench.scene.io import scene_from_dict
from workbench.scene.kinds import CSGNODE, blob, isosurface, lathe, prism
from workbench.scene.kinds.csg import CSG_DIFFERENCE

COMMON = {"material": "m"}
BLOB = blob.read({"threshold": 0.3, "components": [{"center": [0, 0, 0], "radius": 1.0},
                                                   {"center": [1.2, 0, 0], "radius": 1.0}]}, "b", COMMON)
ISO = isosurface.read({"function": "(sqrt(x^2 + z^2) - 1)^2 + y^2", "threshold": 0.09, "max_gradient": 5.0,
                       "bounds": {"min": [-1.5, -0.5, -1.5], "max": [1.5, 0.5, 1.5]}}, "i", COMMON)
LATHE = lathe.read({"points": [[0, -1], [0.8, -1], [0.5, 0], [0.8, 1], [0, 1]]}, "l", COMMON)
PRISM = prism.read({"polygon": [[0, 0], [2, 0], [2, 2], [1, 1], [0, 2]], "heights": [-0.5, 0.5]}, "p", COMMON)
MODS = {"blob": blob, "isosurface": isosurface, "lathe": lathe, "prism": prism}


def _wfo(scale, angle, shift):
    c, s = np.cos(angle), np.sin(angle)
    W = np.eye(4)
    W[:3, :3] = scale * np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    W[:3, 3] = shift
    return W


PLACED = [(BLOB, _wfo(1.0, 0.0, [-4, 0, 0])), (ISO, _wfo(2.0, 0.3, [0, 0, 0])),
          (LATHE, _wfo(1.0, 0.0, [4, 0, 0])), (PRISM, _wfo(0.5, 1.0, [0, 3, 0]))]


def _geometry(placed, csg=None):
    """A flattened scene (one far sphere) with rows for ``placed`` (object, world_from_object)
    and, with ``csg = (a, b)``, a CSG difference of rows a - b (a and b become leaves)."""
    sd = fl.flatten(scene_from_dict(scene_dict([{"type": "sphere", "center": [0, 0, -100], "radius": 0.1,
                                                 "material": "m"}])))
    rows = dict(ptype=list(sd.ptype), top=list(sd.top), xf=list(sd.xf), nm=list(sd.nm), par=list(sd.par),
                solid=list(sd.solid), shadow=list(sd.shadow), ident=list(sd.ident), obj=list(sd.obj))
    aux, off = [], 0
    for obj, W in placed:
        mod = MODS[obj.kind]
        head, a = mod.params(obj, off)
        aux.append(a)
        off += len(a)
        par = np.zeros(fl.NPAR)
        par[:len(head)] = head
        ofw = np.linalg.inv(W)
        for key, v in (("ptype", mod.PTYPE), ("top", True), ("xf", ofw[:3, :4].reshape(-1)),
                       ("nm", ofw[:3, :3].T.reshape(-1)), ("par", par), ("solid", True), ("shadow", True),
                       ("ident", False), ("obj", len(rows["obj"]))):
            rows[key].append(v)
    prog = np.zeros(1, dtype=np.int64)
    if csg is not None:
        a, b = (len(sd.ptype) + i for i in csg)
        rows["top"][a] = rows["top"][b] = False
        prog = np.array([a, b, CSG_DIFFERENCE], dtype=np.int64)
        par = np.zeros(fl.NPAR)
        par[:2] = (0, 3)
        for key, v in (("ptype", CSGNODE), ("top", True), ("xf", np.eye(4)[:3].reshape(-1)),
                       ("nm", np.eye(3).reshape(-1)), ("par", par), ("solid", True), ("shadow", True),
                       ("ident", True), ("obj", len(rows["obj"]))):
            rows[key].append(v)
    arr = {k: np.ascontiguousarray(np.array(v)) for k, v in rows.items()}
    from workbench.renderers.raytrace.accel import build_prim_tree
    top = np.flatnonzero(arr["top"])  # rows added by hand: the brute-force list of them all
    return replace(sd, prims=build_prim_tree(top, np.full((len(top), 6), np.nan), "none"),
                   ptype=arr["ptype"].astype(np.int64), top=arr["top"].astype(bool), xf=arr["xf"],
                   nm=arr["nm"], par=arr["par"], solid=arr["solid"].astype(bool),
                   shadow=arr["shadow"].astype(bool), ident=arr["ident"].astype(bool),
                   obj=arr["obj"].astype(np.int64), csg_prog=prog, aux=np.concatenate(aux))


def _trace(sd, O, D):
    n = len(O)
    h = _alloc(n)
    _kernels().trace_batch(sd.kernel_args(), O, D, np.zeros(n), np.full(n, np.inf), tol.zero, tol.ray_offset,
                           sd.extent, tol.normal_cancel, False, h["t"], h["prim"], h["ng"], h["ns"], h["uv"],
                           h["po"], h["ev"])
    return h["t"], h["prim"], h["ng"]


def _readable(obj, W, O, D):
    """World hit (t, unit world normal) of the readable twin."""
    inv = np.linalg.inv(W)
    t, n = MODS[obj.kind].intersect(obj, inv[:3, :3] @ O + inv[:3, 3], inv[:3, :3] @ D)
    if t == np.inf:
        return t, None
    nw = inv[:3, :3].T @ n
    return t, nw / np.linalg.norm(nw)


def test_closest_hits_and_normals_of_placed_kinds():
    sd = _geometry(PLACED)
    rng = np.random.default_rng(3)
    O = rng.normal(size=(300, 3)) * 2 + [0, 0, 9]
    D = rng.uniform([-5, -1.5, -1.5], [5, 3.5, 1.5], (300, 3)) - O
    t, prim, ng = _trace(sd, np.ascontiguousarray(O), np.ascontiguousarray(D))
    seen = set()
    for i in range(len(O)):
        best = min((_readable(obj, W, O[i], D[i]) + (k,) for k, (obj, W) in enumerate(PLACED)),
                   key=lambda r: r[0])
        if best[0] == np.inf:
            assert t[i] == np.inf
            continue
        k = best[2]
        assert prim[i] == 1 + k and abs(t[i] - best[0]) <= 1e-12 * best[0]
        assert np.allclose(ng[i], best[1], atol=1e-9)
        seen.add(k)
    assert seen == {0, 1, 2, 3}


def test_csg_difference_of_new_kinds():
    """The prism minus the blob (both untransformed), against the readable interval lists."""
    placed = [(PRISM, np.eye(4)), (BLOB, np.eye(4))]
    sd = _geometry(placed, csg=(0, 1))
    rng = np.random.default_rng(4)
    O = rng.normal(size=(200, 3)) + [1, 0, 6]
    D = rng.uniform([0, -0.5, 0], [2, 0.5, 2], (200, 3)) - O
    t, prim, ng = _trace(sd, np.ascontiguousarray(O), np.ascontiguousarray(D))
    hits = 0
    for i in range(len(O)):
        ts = sorted(x for x, _ in prism.crossings(PRISM, O[i], D[i]) + blob.crossings(BLOB, O[i], D[i]))
        want = np.inf
        for a in ts:        # the first boundary where (in prism and not in blob) changes
            before, after = O[i] + (a - 1e-9) * D[i], O[i] + (a + 1e-9) * D[i]
            if (prism.inside(PRISM, before) and not blob.inside(BLOB, before)) != \
                    (prism.inside(PRISM, after) and not blob.inside(BLOB, after)):
                want = a
                break
        if want == np.inf:
            assert t[i] == np.inf
            continue
        hits += 1
        assert abs(t[i] - want) <= 1e-9 * want
        assert ng[i] @ D[i] < 0                # the surface the ray enters faces it
    assert hits > 50
