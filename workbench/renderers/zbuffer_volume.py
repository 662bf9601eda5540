"""The Z-buffer's hypertextures: the raster's ray march (:mod:`.raster_volume`, whose module
docstring states the model) in numpy, float64, on the same density grid (``density_grid`` at the
texture's resolution, read by ``sample_grid``: the GL texture's trilinear filter with
clamped edges).
"""
from __future__ import annotations

import numpy as np

from ..scene.kinds import hypertexture as ht
from ..scene.model import Camera, Scene
from . import raster_volume as rv

BYTES_PER_PIXEL = 480
"""The march's per-pixel float64 temporaries (ray, object-space origin and direction, segment,
radiance, transmittance, samples: about 20 (P, 3) arrays)."""


def sphere_segment(O: np.ndarray, D: np.ndarray, R: float, t_surface: np.ndarray):
    """The overlap ``[t0, t1]`` of rays ``O + t D`` (O (3,), D (P, 3)) with ``|x| < R``, clipped
    to ``t >= 0`` and ``t <= t_surface`` (P,) (stable roots; the GLSL of ``volume.frag``).
    Returns ``t0, t1`` (P,) and ``hit`` (P,) bool (``t1 > t0``)."""
    a = np.einsum("ij,ij->i", D, D)
    b = D @ O
    c = float(O @ O) - R * R
    disc = b * b - a * c
    hit = disc > 0.0
    q = -(b + np.where(b >= 0.0, 1.0, -1.0) * np.sqrt(np.where(hit, disc, 0.0)))
    q = np.where(hit, q, 1.0)
    ta, tb = q / a, c / q
    t0 = np.maximum(np.minimum(ta, tb), 0.0)
    t1 = np.minimum(np.maximum(ta, tb), t_surface)
    return t0, t1, hit & (t1 > t0)


def march(h: ht.Hypertexture, grid: np.ndarray, step: float, ambient, O: np.ndarray, D: np.ndarray,
          t0: np.ndarray, t1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Front-to-back march of medium ``h`` along segments ``[t0, t1]`` (P,) of ``O + t D``:
    returns ``L`` (P, 3) and ``T`` (P,) (:mod:`.raster_volume`'s equations)."""
    R = ht.bound_radius(h)
    len_D = np.linalg.norm(D, axis=1)
    n = np.maximum(1, np.ceil((t1 - t0) * len_D / step)).astype(np.int64)
    dt = (t1 - t0) / n
    tau_per_density = h.density * dt * len_D
    albedo, emission, ambient = (np.asarray(v, dtype=np.float64) for v in (h.albedo, h.emission, ambient))
    L = np.zeros((len(D), 3))
    T = np.ones(len(D))
    for j in range(int(n.max(initial=0))):
        k = np.flatnonzero(n > j)
        x = O + (t0[k] + (j + 0.5) * dt[k])[:, None] * D[k]
        Dj = ht.sample_grid(grid, R, x)
        e = np.exp(-tau_per_density[k] * Dj)
        colour = ht.ramp(h, Dj)
        a = albedo * colour
        J = (1.0 - a) * emission * colour + a * ambient
        L[k] += (T[k] * (1.0 - e))[:, None] * J
        T[k] *= e
    return L, T


def composite(image: np.ndarray, scene: Scene, camera: Camera, depth: np.ndarray, volume_resolution: int,
              step_scale: float) -> tuple[np.ndarray, float]:
    """``image`` (H, W, 3) with the scene's media marched over it, back to front; ``depth``
    (H, W) the camera-space depth of the opaque surface (inf: none).  Returns the image and
    the seconds spent baking the grids."""
    import time
    rv.volume_bytes(scene, volume_resolution, step_scale)
    o, d = camera.rays()
    d = d.reshape(-1, 3)
    forward = -camera.camera_from_world()[2, :3]
    with np.errstate(divide="ignore"):
        t_surface = np.where(np.isfinite(depth.ravel()), depth.ravel() / (d @ forward), np.inf)
    out = image.reshape(-1, 3).astype(np.float64)
    eye = np.asarray(camera.position, dtype=np.float64)
    bake = 0.0
    for h in rv.back_to_front(rv.media(scene), eye):
        t = time.perf_counter()
        grid = ht.density_grid(h, rv.resolution_of(h, volume_resolution))
        bake += time.perf_counter() - t
        M = np.linalg.inv(np.asarray(h.world_from_object, dtype=np.float64))
        O, D = M[:3, :3] @ eye + M[:3, 3], d @ M[:3, :3].T
        t0, t1, hit = sphere_segment(O, D, ht.bound_radius(h), t_surface)
        k = np.flatnonzero(hit)
        L, T = march(h, grid, h.step * step_scale, scene.ambient, O, D[k], t0[k], t1[k])
        out[k] = L + T[:, None] * out[k]
    return out.reshape(image.shape), bake
