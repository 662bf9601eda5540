"""CPU ray caster and Whitted ray tracer (``raycast``, ``raytrace``), the public
``intersect`` (``workbench.raytrace.intersect``) and ``ray_tree``.

Modules: :mod:`.flatten` (scene -> arrays, through each object kind's ``flatten``), :mod:`.bvh`
(binned SAH BVH), :mod:`.kernels` (numba: shading with shadow feelers, child rays, the per-pixel
driver, the batch intersector), :mod:`.maps` and :mod:`.opacity` (texture maps in the kernel),
:mod:`.whitted` (the two renderers), and the readable reference
:mod:`.reference` with each object kind's ``hits`` and ``normal`` (:mod:`workbench.scene.kinds`)
and :mod:`.shapes` (triangles) (one ray at a time, the course's
trace / shade / intersect structure; tested against the kernels).

Options of both methods (``workbench methods`` lists them): ``spp`` and ``seed`` (stratified
jitter), ``shadows``, ``transmissive_shadows`` (an occluder with k_t attenuates a shadow
feeler by k_t instead of blocking it), ``blinn``, ``fresnel`` (``none``: constant k_r, k_t;
``schlick``; ``exact`` dielectric: reflection ``k_r + k_t F``, transmission ``k_t (1 - F)``),
``progress`` (tqdm bar on stderr) and ``on_tile``; ``raytrace`` adds ``max_depth`` (its quality
knob: the maximum number of ray generations in a path, primary = 1, as the course's
``recurs_max`` and POV-Ray's ``max_trace_level``) and ``threshold`` (the course's perceptual
threshold: a child whose accumulated RGB weight, max component, is at most this is not traced).

For a UI: ``on_tile(y0, y1, x0, x1, tile)`` is called in the rendering thread after each band
of rows with the finished (y1 - y0, x1 - x0, 3) float32 linear tile (full width bands of about
65k rays); ``ray_tree(scene, i, j, **options)`` returns the tree of pixel (i, j).

Stats: ``primary_rays``, ``shadow_rays``, ``reflected_rays``, ``refracted_rays``,
``ended_by_depth``, ``ended_by_threshold``, ``escaped_rays``, ``total_internal_reflections``,
``total_rays``, ``mrays_per_s``; timings ``build`` (scene arrays and BVH), ``bvh_build``,
``compile`` (first-call JIT or numba disk-cache load of the kernels the render needs),
``trace`` (camera rays, tracing and shading) and ``trace_cpu``;
``RenderResult.depth`` is the camera-space depth of the primary hit.

Conventions: normals from the intersection are outward; the shading normal is turned towards
the viewer (two-sided surfaces).  Rectangles and polygons are thin sheets (transmission goes
straight through); spheres, boxes, quadrics, meshes and CSG solids are media (refraction with
a small stack of nested media, Beer-Lambert absorption inside).  A top-level quadric is its
surface cut to its bounds (open); inside a CSG tree it is the solid ``P^T Q P < 0`` within its
bounds box (capped).  Meshes inside CSG trees are not supported.  Area lights are point-light
stand-ins for shading and emissive front-facing polygons (radiance colour x intensity) that
cast no shadow.  Mesh ``vertex_emission`` is interpolated and added as emission.
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
    h = _alloc(n, surface=False)  # the geometric normal alone
    _kernels().trace_batch(sd.kernel_args(), O, D, np.zeros(n), np.full(n, np.inf), tol.zero,
                           tol.ray_offset, sd.extent, tol.normal_cancel, False, h["t"], h["prim"], h["ng"],
                           h["ns"], h["uv"], h["po"], h["ev"])
    hit = h["prim"] >= 0
    obj = np.where(hit, sd.obj[np.maximum(h["prim"], 0)], -1)
    normal = np.where(hit[:, None], h["ng"], 0.0)
    return np.where(hit, h["t"], np.inf), normal, obj


def ray_tree(scene, i, j, **options):
    """The ray tree of pixel (row ``i``, column ``j``); see :func:`.reference.ray_tree`."""
    from .reference import ray_tree as _rt
    return _rt(scene, i, j, **options)
