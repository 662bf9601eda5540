"""Automatic near and far clip planes of the raster methods (GLSL and pyrender).

The planes come from the bounding box of each drawn part, clipped to the view frustum: the
near plane sits just before the nearest point any part shows, the far plane just after the
farthest.  A huge floor passing under the camera or a tiny object far away does not move the
near plane past the objects in front of the camera (as one box around the whole scene did,
with ``near >= far * 1e-3``).

Depth precision (standard OpenGL projection, window depth ``d = f (z - n) / ((f - n) z)``):
the farthest fragment must keep ``1 - d >= DEPTH_MARGIN`` or it rounds onto the cleared depth
1 and vanishes.  ``1 - d(z_max) = n (f - z_max) / ((f - n) z_max)``, so ``f`` is chosen from
``n``; a spread ``z_max / z_min`` beyond ``1 / (2 DEPTH_MARGIN)`` raises ``n`` (what is nearer
than 2e-6 of the far distance is clipped, a documented limit).  A camera inside a part's box
(a room, a sky sphere) bounds the near plane by ``INSIDE_RATIO`` times that part's far
distance, which keeps the depth buffer's resolution at the far walls.
"""
from __future__ import annotations

import numpy as np

from .model import Camera

DEPTH_MARGIN = 1e-6
"""Smallest ``1 - d`` of the farthest fragment: 16 float32 (or 24-bit) steps below the clear
depth, above the rounding of the projection in single precision."""
INSIDE_RATIO = 1e-3
"""Near plane as a fraction of the far distance of a part whose box holds the camera."""
FAR_GROWTH = 1.01
NEAR_SHRINK = 0.99


def _clip(poly: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman: the part of the convex polygon (k, 3) where ``normal . p <= 0``."""
    s = poly @ normal
    out = []
    for i in range(len(poly)):
        j = (i + 1) % len(poly)
        if s[i] <= 0.0:
            out.append(poly[i])
        if (s[i] <= 0.0) != (s[j] <= 0.0):
            out.append(poly[i] + (poly[j] - poly[i]) * (s[i] / (s[i] - s[j])))
    return np.array(out).reshape(-1, 3)


_FACES = ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5))


def visible_depths(camera: Camera, box: np.ndarray, view: np.ndarray | None = None
                   ) -> tuple[float, float, bool] | None:
    """Depth range of the part of a world box (2, 3) inside the camera's frustum (sides only,
    no near or far plane): ``(z_min, z_max, holds_camera)`` or ``None`` when none of it is.
    ``view``: the camera's ``camera_from_world`` (4, 4) if already formed.

    The intersection of a box and the frustum is a convex polyhedron whose vertices are box
    corners, box edges crossing a frustum side, frustum edges crossing a box face, or the
    camera itself; all but the last lie on the box's faces, so clipping the six faces by the
    four sides finds them.
    """
    lo, hi = np.asarray(box[0], dtype=np.float64), np.asarray(box[1], dtype=np.float64)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    V = camera.camera_from_world() if view is None else view
    c = corners @ V[:3, :3].T + V[:3, 3]
    c = np.stack([c[:, 0], c[:, 1], -c[:, 2]], -1)  # x, y, depth (the camera looks down -z)
    ty = np.tan(np.radians(camera.fov_y) / 2.0)
    tx = ty * camera.aspect
    sides = [np.array([1.0, 0.0, -tx]), np.array([-1.0, 0.0, -tx]),
             np.array([0.0, 1.0, -ty]), np.array([0.0, -1.0, -ty])]
    depths = []
    for f in _FACES:
        poly = c[list(f)]
        for n in sides:
            poly = _clip(poly, n)
            if len(poly) == 0:
                break
        depths.extend(poly[:, 2])
    eye = np.asarray(camera.position, dtype=np.float64)
    holds = bool(np.all(lo <= eye) and np.all(eye <= hi))
    if not depths:
        return None
    return max(min(depths), 0.0), max(depths), holds


def auto_near_far(camera: Camera, boxes: np.ndarray) -> tuple[float, float]:
    """Clip planes for the parts' world boxes (K, 2, 3) seen from ``camera`` (its own near and
    far win).  See the module docstring for the rule."""
    view = camera.camera_from_world()
    ranges = [r for r in (visible_depths(camera, b, view) for b in np.asarray(boxes).reshape(-1, 2, 3)) if r]
    ranges = [r for r in ranges if r[1] > 0.0]
    if not ranges:  # nothing in view: any valid pair
        far = camera.far or 1.0
        return camera.near or far * INSIDE_RATIO, far
    z_max = max(r[1] for r in ranges)
    near_of = [INSIDE_RATIO * r[1] * FAR_GROWTH if (r[2] or r[0] <= 0.0) else NEAR_SHRINK * r[0]
               for r in ranges]
    near = camera.near or max(min(near_of), 2.0 * DEPTH_MARGIN * z_max)
    if camera.far:
        return near, camera.far
    # 1 - d(z_max) >= DEPTH_MARGIN  <=>  f (n - m z_max) >= n z_max (1 - m)
    m = DEPTH_MARGIN
    far = FAR_GROWTH * z_max
    if near > m * z_max:
        far = max(far, z_max * near * (1.0 - m) / (near - m * z_max))
    else:
        far = near / m
    return near, max(far, near * FAR_GROWTH)
