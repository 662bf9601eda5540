"""The Z-buffer's furs: the raster's layered shells (:mod:`.raster_fur`, whose module docstring
states the model) in numpy, float64, over the Z-buffer's image.

Each shell's triangles (the same tessellation and scales as the GL path) are scan-converted one
shell and one side at a time (:mod:`.zbuffer_scan`, near-plane clipping of :mod:`.zbuffer`):
the polygon a pixel sees gives, by intersecting the pixel centre's ray with its plane, the
fragment's exact point (what GL's perspective-correct interpolation gives, not the course's
screen-space one); a fragment behind the opaque surface (the depth buffer) is dropped.  The
texel is :func:`workbench.scene.kinds.fur.texel`.  The sides are composited in the GL order:
back faces from the outermost shell inwards, then front faces from the innermost outwards,
``pixel = a J + (1 - a) pixel``.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from ..scene.kinds import fur as fur_kind
from ..scene.model import Camera, Scene
from . import raster_fur as rf
from .raster_shaders import light_kind, light_values
from .zbuffer_scan import new_frame, scan_polygons

BYTES_PER_PIXEL = 1200
"""The scan's frame (depth, id, one attribute), the rays and the shading's float64 (P, 3)
temporaries (about 30 of them) and the image being composited."""
BYTES_PER_TRIANGLE = 600
"""One shell's world triangles, their window polygons and their planes (float64)."""


def shell_bytes(scene: Scene, level: int, shells: int, width: int, height: int) -> int:
    """Bytes of the furs' composite at ``width x height`` (one shell scanned at a time);
    checks ``shells``."""
    rf.check_shells(shells)
    if not rf.furs(scene):
        return 0
    return BYTES_PER_TRIANGLE * rf.fur_triangles(scene, level) + BYTES_PER_PIXEL * width * height


def kajiya_kay(f: fur_kind.Fur, T: np.ndarray, L: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per unit light at (P,) points: ``(sin(T, L), ks max(0, cos phi)^shininess)`` with
    ``cos phi = (T.L)(T.d) + sin(T, L) sin(T, d)`` (``fur_kernels.kajiya_kay``; x^0 = 1)."""
    tl, td = np.einsum("ij,ij->i", T, L), np.einsum("ij,ij->i", T, d)
    sl, sd = np.sqrt(np.maximum(0.0, 1.0 - tl * tl)), np.sqrt(np.maximum(0.0, 1.0 - td * td))
    c = tl * td + sl * sd
    spec = np.where(c > 0.0, f.ks * np.maximum(c, 0.0) ** f.shininess, 0.0)
    return sl, spec


def source(f: fur_kind.Fur, scene: Scene, P: np.ndarray, T: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``J`` (P, 3) at world points P with world tangents T and view directions d (unit):
    ``kd C Ia + sum_l I_l s_l (kd C sin(T, L) + spec)``, the raster's lights, no shadowing."""
    albedo = f.kd * np.asarray(f.color, dtype=np.float64)
    J = np.broadcast_to(albedo * np.asarray(scene.ambient, dtype=np.float64), P.shape).copy()
    for light in scene.point_lights():
        point, inv_sq, lobe = light_kind(light)
        pos, color = light_values(light)
        v = pos - P if point else np.broadcast_to(pos, P.shape)
        r2 = np.einsum("ij,ij->i", v, v)
        ok = r2 > 0.0
        L = v / np.sqrt(np.where(ok, r2, 1.0))[:, None]
        scale = np.where(ok, 1.0 / np.where(ok, r2, 1.0) if inv_sq else 1.0, 0.0)
        if lobe is not None:
            scale = scale * np.maximum(0.0, -(L @ np.asarray(lobe, dtype=np.float64)))
        sl, spec = kajiya_kay(f, T, L, d)
        J += (scale[:, None] * color) * (albedo * sl[:, None] + spec[:, None])
    return J


def composite(image: np.ndarray, scene: Scene, camera: Camera, depth: np.ndarray, level: int, shells: int,
              polygons: Callable) -> np.ndarray:
    """``image`` (H, W, 3) with every fur's shells composited over it, the furs back to front
    by their centres' distance.  ``depth`` (H, W): the opaque surfaces' camera depth (inf:
    none); ``polygons(P)``: window polygons of world triangles P (T, 3, 3) (:mod:`.zbuffer`'s
    projection and near clipping, ids = triangle indices)."""
    image = np.array(image, dtype=np.float64)
    eye = np.asarray(camera.position, dtype=np.float64)
    dirs = camera.rays()[1]
    furs = sorted(rf.furs(scene), key=lambda o: -float(np.linalg.norm(
        np.asarray(o.world_from_object, dtype=np.float64)[:3, 3] - eye)))
    for f in furs:
        W = np.asarray(f.world_from_object, dtype=np.float64)
        inv = np.linalg.inv(W)
        P0, _, F = fur_kind.base_mesh(f, level)
        scales = fur_kind.shell_scales(f, shells)
        order = [(i, False) for i in range(shells - 1, -1, -1)] + [(i, True) for i in range(shells)]
        for i, front in order:
            Pw = (P0 * scales[i]) @ W[:3, :3].T + W[:3, 3]
            tri = Pw[F]
            n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            faces_eye = np.einsum("ij,ij->i", n, eye - tri[:, 0]) > 0.0
            keep = np.flatnonzero(faces_eye == front)
            _shell(image, f, scene, camera, depth, dirs, eye, W, inv, tri[keep], n[keep], scales[i], shells,
                   polygons)
    return image


def _shell(image, f, scene, camera, depth, dirs, eye, W, inv, tri, n, scale, shells, polygons) -> None:
    """Composite one side of one shell (triangles ``tri`` with normals ``n``) over ``image``."""
    if not len(tri):
        return
    polys = polygons(tri)
    if not len(polys.start):
        return
    frame = new_frame(camera.width, camera.height, 1, 24)
    scan_polygons(polys, frame)
    pix = np.flatnonzero(frame.ident.ravel() >= 0)
    if not len(pix):
        return
    k = frame.ident.ravel()[pix]
    d = dirs.reshape(-1, 3)[pix]
    nk = n[k]
    denom = np.einsum("ij,ij->i", nk, d)
    t = np.einsum("ij,ij->i", nk, tri[k, 0] - eye) / np.where(denom != 0.0, denom, 1.0)
    P = eye + t[:, None] * d
    ok = (denom != 0.0) & (t > 0.0) & (camera.project(P)[1] < depth.ravel()[pix])
    pix, P, d = pix[ok], P[ok], d[ok]
    x = P @ inv[:3, :3].T + inv[:3, 3]
    D, T_obj = fur_kind.texel(f, x)
    hit = D > 0.0
    pix, P, d, x, T_obj = pix[hit], P[hit], d[hit], x[hit], T_obj[hit]
    if not len(pix):
        return
    # the shell's normal: radial on a sphere, the face's on a box (as fur_shell.frag)
    n_obj = x if f.base == "sphere" else _box_normal(x, np.asarray(f.size, dtype=np.float64) * scale)
    n_obj = n_obj / np.linalg.norm(n_obj, axis=1)[:, None]
    u = d @ inv[:3, :3].T
    u /= np.linalg.norm(u, axis=1)[:, None]
    c = np.abs(np.einsum("ij,ij->i", u, n_obj))
    layer = f.length / shells
    a = 1.0 - np.exp(-f.density * np.minimum(layer / np.maximum(c, 1e-30), f.length))
    T = T_obj @ np.linalg.inv(W[:3, :3])  # the normal matrix inv(W)^T applied to rows
    T /= np.maximum(np.linalg.norm(T, axis=1), 1e-300)[:, None]
    J = source(f, scene, P, T, d)
    flat = image.reshape(-1, 3)
    flat[pix] = a[:, None] * J + (1.0 - a[:, None]) * flat[pix]


def _box_normal(x: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Outward face normal of the box of half-sizes ``half`` at points ``x`` on it: the axis
    where ``|x| / half`` is largest."""
    r = np.abs(x) / half
    axis = np.argmax(r, axis=1)
    out = np.zeros_like(x)
    out[np.arange(len(x)), axis] = np.sign(x[np.arange(len(x)), axis])
    return out

