"""CPU ray caster and Whitted ray tracer (``raycast``, ``raytrace``) and the public
``intersect`` (``workbench.raytrace.intersect``).

Modules: :mod:`.flatten` (scene -> arrays), :mod:`.bvh` (SAH BVH), :mod:`.kernels` (numba),
:mod:`.csg` and :mod:`.shapes` + :mod:`.reference` (readable reference, ray tree),
:mod:`.whitted` (the renderers).
"""
from __future__ import annotations

import numpy as np

from ...core.errors import WorkbenchError

__all__ = ["intersect", "ray_tree"]


def intersect(scene, origins, directions):
    """Closest hits of rays with a scene.

    Parameters
    ----------
    scene : Scene
    origins, directions : (N, 3) float64; directions need not be unit length (t is then in
        units of the given direction).

    Returns
    -------
    t : (N,) float64, ray parameter of the hit (``inf`` on a miss).
    normal : (N, 3) float64, unit outward geometric normal at the hit (0 on a miss).
    object_index : (N,) int64, index into ``scene.objects`` (area light ``k`` is
        ``len(scene.objects) + k``), ``-1`` on a miss.
    """
    from ...core.tol import tol
    from .flatten import flatten
    from .whitted import _alloc, _kernels
    O = np.ascontiguousarray(origins, dtype=np.float64)
    D = np.ascontiguousarray(directions, dtype=np.float64)
    if O.ndim != 2 or O.shape[1] != 3 or D.shape != O.shape:
        raise WorkbenchError(f"intersect: origins and directions must both be (N, 3), got {O.shape} and {D.shape}")
    if not (np.isfinite(O).all() and np.isfinite(D).all()):
        raise WorkbenchError("intersect: origins and directions must be finite")
    if (np.linalg.norm(D, axis=1) <= tol.zero).any():
        raise WorkbenchError("intersect: a direction has zero length")
    sd = flatten(scene)
    n = len(O)
    h = _alloc(n)
    _kernels().trace_batch(sd.kernel_args(), O, D, np.zeros(n), np.full(n, np.inf), tol.zero,
                           tol.ray_offset, sd.extent, tol.normal_cancel, h["t"], h["prim"], h["ng"],
                           h["ns"], h["uv"], h["po"], h["ev"])
    hit = h["prim"] >= 0
    obj = np.where(hit, sd.obj[np.maximum(h["prim"], 0)], -1)
    normal = np.where(hit[:, None], h["ng"], 0.0)
    return np.where(hit, h["t"], np.inf), normal, obj


def ray_tree(scene, i, j, **options):
    """The ray tree of pixel (row ``i``, column ``j``); see :func:`.reference.ray_tree`."""
    from .reference import ray_tree as _rt
    return _rt(scene, i, j, **options)
