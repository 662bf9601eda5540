"""Pure camera functions behind the mouse: orbit, pan, zoom and reset.

Each returns a new :class:`~workbench.scene.model.Camera` (``dataclasses.replace``); the orbit
parameters (target, yaw, pitch, distance) are derived from the camera itself: target is
``look_at``, distance ``|position - look_at|``, yaw and pitch are the spherical angles of
``position - look_at`` in a frame whose pole is the camera's ``up`` vector.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...core.tol import tol
from ...core.transform import normalize
from ...scene.model import Camera, Scene

PITCH_LIMIT = math.radians(89.0)
"""Pitch is clamped short of the poles, where yaw is undefined."""


def _frame(up) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormal frame (e1, e2, pole) with ``pole`` along ``up``."""
    pole = normalize(np.asarray(up, dtype=float))
    helper = np.array([1.0, 0.0, 0.0]) if abs(pole[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    e1 = normalize(np.cross(helper, pole))
    return e1, np.cross(pole, e1), pole


def orbit_parameters(cam: Camera) -> tuple[np.ndarray, float, float, float]:
    """(target (3,), yaw, pitch, distance) of ``cam`` (angles in radians)."""
    target = np.asarray(cam.look_at, dtype=float)
    d = np.asarray(cam.position, dtype=float) - target
    dist = float(np.linalg.norm(d))
    e1, e2, pole = _frame(cam.up)
    yaw = math.atan2(float(d @ e2), float(d @ e1))
    pitch = math.asin(max(-1.0, min(1.0, float(d @ pole) / max(dist, tol.zero))))
    return target, yaw, pitch, dist


def from_orbit(cam: Camera, target, yaw: float, pitch: float, distance: float) -> Camera:
    """``cam`` moved to the orbit position (target, yaw, pitch, distance)."""
    e1, e2, pole = _frame(cam.up)
    pitch = max(-PITCH_LIMIT, min(PITCH_LIMIT, pitch))
    d = math.cos(pitch) * (math.cos(yaw) * e1 + math.sin(yaw) * e2) + math.sin(pitch) * pole
    target = np.asarray(target, dtype=float)
    pos = target + distance * d
    return replace(cam, position=tuple(float(x) for x in pos),
                   look_at=tuple(float(x) for x in target))


def orbit(cam: Camera, d_yaw: float, d_pitch: float) -> Camera:
    """Turn around the target by ``d_yaw`` and ``d_pitch`` radians."""
    target, yaw, pitch, dist = orbit_parameters(cam)
    return from_orbit(cam, target, yaw + d_yaw, pitch + d_pitch, dist)


def pan(cam: Camera, dx: float, dy: float) -> Camera:
    """Slide camera and target in the image plane by (dx, dy) fractions of the view height at
    the target's distance (dx to the right, dy up)."""
    target, _, _, dist = orbit_parameters(cam)
    forward = normalize(target - np.asarray(cam.position, dtype=float))
    right = normalize(np.cross(forward, np.asarray(cam.up, dtype=float)))
    up = np.cross(right, forward)
    h = 2.0 * dist * math.tan(math.radians(cam.fov_y) / 2.0)
    shift = h * (dx * right + dy * up)
    return replace(cam, position=tuple(float(x) for x in np.asarray(cam.position) + shift),
                   look_at=tuple(float(x) for x in target + shift))


def zoom(cam: Camera, factor: float) -> Camera:
    """Multiply the distance to the target by ``factor`` (> 0; < 1 moves closer)."""
    if not factor > 0.0:
        raise ValueError(f"zoom factor must be > 0, got {factor}")
    target, yaw, pitch, dist = orbit_parameters(cam)
    return from_orbit(cam, target, yaw, pitch, max(dist * factor, tol.zero))


def reset(scene: Scene, cam: Camera) -> Camera:
    """The scene's camera at ``cam``'s resolution."""
    return scene.camera.with_resolution(cam.width, cam.height)


# ---------------------------------------------------------------- linked image view (2D zoom)
MAX_VIEW_ZOOM = 32.0


def view_window(view: tuple[float, float, float]) -> tuple[tuple[float, float], tuple[float, float]]:
    """Texture window (uv0, uv1) of the shared 2D view ``(zoom, cu, cv)``: a square of side
    ``1 / zoom`` centred on (cu, cv), u to the right and v down, kept inside [0, 1]^2."""
    z, cu, cv = view
    h = 0.5 / z
    cu, cv = min(max(cu, h), 1.0 - h), min(max(cv, h), 1.0 - h)
    return (cu - h, cv - h), (cu + h, cv + h)


def zoom_view(view: tuple[float, float, float], factor: float, at: tuple[float, float]):
    """Zoom the 2D view by ``factor`` keeping the image point ``at`` (uv) under the mouse."""
    (u0, v0), _ = view_window(view)
    z = min(max(view[0] * factor, 1.0), MAX_VIEW_ZOOM)
    fx, fy = (at[0] - u0) * view[0], (at[1] - v0) * view[0]  # mouse position in the panel [0, 1]
    return (z, at[0] - fx / z + 0.5 / z, at[1] - fy / z + 0.5 / z)


def pan_view(view: tuple[float, float, float], du: float, dv: float):
    """Slide the 2D view by (du, dv) fractions of the panel (the image follows the mouse)."""
    (u0, v0), (u1, v1) = view_window(view)
    z = view[0]
    return (z, (u0 + u1) / 2 - du / z, (v0 + v1) / 2 - dv / z)
