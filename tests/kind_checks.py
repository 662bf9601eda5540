"""Shared checks of the tests of the object kinds in ``workbench/scene/kinds`` (blob,
isosurface, lathe, prism): a kernel parameter row, closed outward meshes, interval lists."""
from __future__ import annotations

import numpy as np

NPAR = 20
SCALES = (1e-6, 1e-3, 1.0, 1e3, 1e6)


def scratch():
    """``(out_t, out_f, stack)``: the scratch arrays the kinds' numba entry points take."""
    return np.zeros(64), np.zeros(64, dtype=np.int64), np.zeros((64, 4))


def table(head: np.ndarray, row: int = 0) -> np.ndarray:
    """A (row + 1, NPAR) parameter table whose row ``row`` is ``head`` (the kernels' layout)."""
    par = np.zeros((row + 1, NPAR))
    par[row, :len(head)] = head
    return par


def mesh_volume(P: np.ndarray, F: np.ndarray) -> float:
    """Signed volume of a closed triangle mesh (divergence theorem): positive when its
    triangles wind counter-clockwise seen from outside."""
    a = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    return float(np.einsum("ij,ij->i", P[F[:, 0]], a).sum() / 6.0)


def welded_edge_uses(P: np.ndarray, F: np.ndarray) -> np.ndarray:
    """How many triangles use each edge, vertices merged by position to 1e-9 of the mesh's
    extent (marching cubes leaves triangles of rounding size where a sample is nearly zero;
    faceted meshes repeat vertices per face): a closed surface gives all 2."""
    q = np.round((P - P.min(0)) / (1e-9 * np.ptp(P, axis=0).max()))
    _, ids = np.unique(q, axis=0, return_inverse=True)
    G = ids.reshape(-1)[F]
    G = G[(G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 2] != G[:, 0])]   # collapsed
    e = np.sort(np.concatenate([G[:, [0, 1]], G[:, [1, 2]], G[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


def assert_alternates(crossings, inside_at):
    """The crossings' status between consecutive ones follows entering / leaving."""
    ts = [t for t, _ in crossings]
    assert ts == sorted(ts)
    assert len(ts) % 2 == 0
    for i, (a, b) in enumerate(zip(ts[:-1], ts[1:])):
        if b > a:
            assert inside_at(0.5 * (a + b)) == (i % 2 == 0), (i, ts)


def index_edge_uses(F: np.ndarray) -> np.ndarray:
    """How many triangles use each edge of an indexed mesh (closed and welded: all 2)."""
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)[1]
