"""Ray / triangle intersection, readable version (all triangles of a mesh at once): the
reference tracer's (:mod:`.reference`) twin of the kernels' BVH leaves.  The analytic kinds'
readable intersections are their ``hits`` in :mod:`workbench.scene.kinds`.
"""
from __future__ import annotations

import numpy as np


def triangles(tri, O, D) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All triangles at once (Moller & Trumbore 1997).  ``tri`` (T, 3, 3).  Returns ``t`` (T,)
    (inf where missed) and the barycentric weights ``b1``, ``b2`` of vertices 1 and 2."""
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p = np.cross(D, e2)
    det = np.sum(e1 * p, -1)
    ok = det != 0.0
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = O - tri[:, 0]
    b1 = np.sum(s * p, -1) * inv
    q = np.cross(s, e1)
    b2 = (q @ D) * inv
    t = np.sum(e2 * q, -1) * inv
    hit = ok & (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1)
    return np.where(hit, t, np.inf), b1, b2
