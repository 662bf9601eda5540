"""4x4 homogeneous transforms, column-vector convention: ``p_world = world_from_object @ p``.

Names follow pbrt: a matrix ``a_from_b`` maps coordinates of frame b into frame a.
"""
from __future__ import annotations

import numpy as np



def normalize(v: np.ndarray, axis: int = -1) -> np.ndarray:
    """Unit vectors along ``axis``; zero vectors stay zero (never NaN).

    Any non-zero finite vector has a direction, however short: a cross product of two 1e-7
    edges (a scene at scale 1e-6) is 1e-14 long and must not be taken for zero, so there is
    no absolute threshold here (callers that need one, e.g. cancelled normals, test the length
    against ``tol`` themselves)."""
    v = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(v, axis=axis, keepdims=True)
    return np.divide(v, n, out=np.zeros_like(v), where=(n > 0.0) & np.isfinite(n))


def translate(t) -> np.ndarray:
    """Translation matrix (4, 4)."""
    m = np.eye(4)
    m[:3, 3] = np.asarray(t, dtype=np.float64)
    return m


def scale(s) -> np.ndarray:
    """Scale matrix (4, 4); ``s`` is a scalar or a 3-vector."""
    s = np.broadcast_to(np.asarray(s, dtype=np.float64), (3,))
    return np.diag([s[0], s[1], s[2], 1.0])


def rotate(axis, angle_deg: float) -> np.ndarray:
    """Rotation by ``angle_deg`` degrees about ``axis`` (Rodrigues), right-handed, (4, 4)."""
    a = normalize(np.asarray(axis, dtype=np.float64))
    th = np.radians(angle_deg)
    c, s = np.cos(th), np.sin(th)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + s * K + (1 - c) * (K @ K)
    return m


def rotate_xyz(angles_deg) -> np.ndarray:
    """Rotation about x, then y, then z (degrees): ``Rz @ Ry @ Rx``."""
    ax, ay, az = angles_deg
    return rotate([0, 0, 1], az) @ rotate([0, 1, 0], ay) @ rotate([1, 0, 0], ax)


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two 3-vectors (3,), the same roundings as ``np.cross`` without its
    axis handling (which costs ~20x the arithmetic on one pair: a camera drag forms several
    view matrices a frame)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def look_at(eye, target, up) -> np.ndarray:
    """``camera_from_world`` for a camera at ``eye`` looking at ``target`` (OpenGL frame:
    the camera looks down its -z axis, x right, y up)."""
    eye = np.asarray(eye, dtype=np.float64)
    f = normalize(np.asarray(target, dtype=np.float64) - eye)
    r = normalize(cross3(f, np.asarray(up, dtype=np.float64)))
    u = cross3(r, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = r, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective(fov_y_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """OpenGL ``clip_from_camera`` projection (gluPerspective), depth mapped to [-1, 1]."""
    f = 1.0 / np.tan(np.radians(fov_y_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = f
    m[2, 2] = (far + near) / (near - far)
    m[2, 3] = 2.0 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def transform_points(m: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Apply a (4, 4) affine transform to points (N, 3)."""
    p = np.asarray(p, dtype=np.float64)
    return p @ m[:3, :3].T + m[:3, 3]


def transform_vectors(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Apply the linear part of a (4, 4) transform to directions (N, 3) (no translation)."""
    return np.asarray(v, dtype=np.float64) @ m[:3, :3].T


def transform_normals(m: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Transform normals (N, 3) by the inverse transpose of ``m``'s linear part, normalised."""
    inv_t = np.linalg.inv(m[:3, :3]).T
    return normalize(np.asarray(n, dtype=np.float64) @ inv_t.T)
