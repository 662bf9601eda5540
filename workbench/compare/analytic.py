"""Analytic images of sphere-only scenes: the exact limit that Gouraud / Phong approach as the
tessellation is refined, computed independently of every registered method.

Each pixel's primary ray (``Camera.rays``, pixel centres) is intersected with every sphere by
the stable quadratic (DESIGN.md errata 1 and 7: ``B = 2 d.(o - c)``, ``q = -(B + sign(B)
sqrt(disc)) / 2``, ``t = q / A, C / q``) and shaded with the one local model
(:func:`workbench.renderers.local_model.shade`), visibility 1 (no shadow feelers, like the
raster methods).  Used as the reference of the study tests and of the stress cases.
"""
from __future__ import annotations

import numpy as np

from ..core.errors import NotApplicable
from ..core.transform import normalize, transform_points
from ..renderers.local_model import shade
from ..scene.model import Scene, Sphere


def ray_sphere(o: np.ndarray, d: np.ndarray, c, r: float) -> np.ndarray:
    """Nearest positive hit parameter of rays with one sphere.

    Parameters
    ----------
    o, d : (N, 3) float64 ray origins and unit directions.
    c : (3,) centre; r : radius.

    Returns
    -------
    (N,) float64, ``inf`` where the ray misses.
    """
    oc = o - np.asarray(c, dtype=np.float64)
    A = np.sum(d * d, -1)
    B = 2.0 * np.sum(d * oc, -1)
    # C = |oc|^2 - r^2 factored to limit cancellation for far spheres (|oc| >> r)
    C = (np.linalg.norm(oc, axis=-1) - r) * (np.linalg.norm(oc, axis=-1) + r)
    disc = B * B - 4.0 * A * C
    hit = disc >= 0.0
    sq = np.sqrt(np.where(hit, disc, 0.0))
    q = -0.5 * (B + np.where(B >= 0.0, sq, -sq))
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = q / A, np.where(q != 0.0, C / q, 0.0)
    lo, hi = np.minimum(t1, t2), np.maximum(t1, t2)
    t = np.where(lo > 0.0, lo, np.where(hi > 0.0, hi, np.inf))
    return np.where(hit, t, np.inf)


def _world_sphere(obj: Sphere) -> tuple[np.ndarray, float]:
    """Centre and radius in world space (uniform scale + rigid motion only)."""
    M = np.asarray(obj.world_from_object)
    c = transform_points(M, np.asarray([obj.center], dtype=np.float64))[0]
    s = np.linalg.svd(M[:3, :3], compute_uv=False)
    if s.max() - s.min() > 1e-9 * s.max():
        raise NotApplicable(f"sphere {obj.name or '?'}: non-uniform scale (an ellipsoid), not analytic here")
    return c, float(obj.radius * s[0])


def sphere_image(scene: Scene, width: int | None = None, height: int | None = None) -> np.ndarray:
    """The exact image of a scene made only of untextured spheres, local model, no shadows.

    Returns
    -------
    (H, W, 3) float32 linear RGB (background where no sphere is hit).

    Raises
    ------
    NotApplicable
        If the scene holds anything but plain spheres (textures, bump, reflection, ...).
    """
    cam = scene.camera
    if width is not None:
        cam = cam.with_resolution(width, height)
    for obj in scene.objects:
        mat = scene.material_of(obj)
        if not isinstance(obj, Sphere):
            raise NotApplicable(f"analytic image needs spheres only, got a {obj.kind}")
        if mat.texture or mat.bump or mat.opacity or mat.kr or mat.kt or mat.environment:
            raise NotApplicable(f"material {mat.name!r}: analytic image covers the plain local model only")
    o, d = cam.rays()
    H, W = d.shape[:2]
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    img = np.broadcast_to(np.asarray(scene.background, dtype=np.float64), (H * W, 3)).copy()
    t_best = np.full(H * W, np.inf)
    which = np.full(H * W, -1)
    spheres = [_world_sphere(obj) for obj in scene.objects]
    for k, (c, r) in enumerate(spheres):
        t = ray_sphere(o, d, c, r)
        closer = t < t_best
        t_best[closer], which[closer] = t[closer], k
    lights = scene.point_lights()
    for k, obj in enumerate(scene.objects):
        sel = which == k
        if not sel.any():
            continue
        c, r = spheres[k]
        P = o[sel] + t_best[sel, None] * d[sel]
        N = normalize(P - c)
        mat = scene.material_of(obj)
        img[sel] = shade(P, N, -d[sel], np.asarray(mat.color), mat, lights, scene.ambient)
    return img.reshape(H, W, 3).astype(np.float32)


__all__ = ["ray_sphere", "sphere_image"]
