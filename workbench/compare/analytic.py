"""Analytic images of sphere-only scenes: the exact limit that Gouraud / Phong approach as the
tessellation is refined, computed independently of every registered method.

Each pixel's primary ray (``Camera.rays``, pixel centres) is intersected with every sphere
without cancellation (:func:`ray_sphere`) and shaded with the one local model
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
    """Nearest positive hit parameter of rays with one sphere, free of cancellation.

    The textbook discriminant ``B^2 - 4AC`` loses every digit for a small sphere far away
    (``B^2 ~ 4 |o - c|^2`` while the discriminant is ``~ 4 (r^2 - b^2)``).  Instead, with unit
    ``d``: ``t_ca = d.(c - o)``, the impact parameter ``b = |(c - o) - t_ca d|`` computed as the
    norm of a vector, ``h = (r - b)(r + b)``, and the stable root pair (errata 7)
    ``q = t_ca + sign(t_ca) sqrt(h)``, ``t = q`` and ``C / q`` with ``C = (|c - o| - r)(|c - o| + r)``.

    Parameters
    ----------
    o, d : (N, 3) float64 ray origins and directions (normalised here).
    c : (3,) centre; r : radius.

    Returns
    -------
    (N,) float64, ``inf`` where the ray misses.
    """
    d = normalize(np.asarray(d, dtype=np.float64))
    oc = np.asarray(c, dtype=np.float64) - o
    tca = np.sum(d * oc, -1)
    b = np.linalg.norm(oc - tca[:, None] * d, axis=-1)
    h = (r - b) * (r + b)
    hit = h >= 0.0
    sq = np.sqrt(np.where(hit, h, 0.0))
    L = np.linalg.norm(oc, axis=-1)
    C = (L - r) * (L + r)
    q = tca + np.where(tca >= 0.0, sq, -sq)
    with np.errstate(divide="ignore", invalid="ignore"):
        t2 = np.where(q != 0.0, C / q, 0.0)
    lo, hi = np.minimum(q, t2), np.maximum(q, t2)
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
    """
    return sphere_hits(scene, width, height)[0]


def sphere_hits(scene: Scene, width: int | None = None, height: int | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`sphere_image` and the (H, W) int index of the object seen (-1: background).

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
    return img.reshape(H, W, 3).astype(np.float32), which.reshape(H, W)


def interior(index: np.ndarray) -> np.ndarray:
    """(H, W) bool: pixels whose 3 x 3 neighbourhood sees the same object (or background):
    away from silhouettes, where discretised geometry (tessellation) moves the outline."""
    H, W = index.shape
    pad = np.pad(index, 1, mode="edge")
    same = np.ones((H, W), dtype=bool)
    for di in range(3):
        for dj in range(3):
            same &= pad[di:di + H, dj:dj + W] == index
    return same


__all__ = ["interior", "ray_sphere", "sphere_hits", "sphere_image"]
