"""One camera for all methods: rays through pixel centres and the GL projection agree."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from workbench.core import transform as tf
from workbench.scene.model import Camera


def _cam(**kw):
    return Camera(position=(1.0, 2.0, -6.0), look_at=(0.3, 0.5, 1.0), up=(0.0, 1.0, 0.0), fov_y=50.0,
                  width=64, height=48, **kw)


def test_ray_through_pixel_centre_projects_back_to_it():
    cam = _cam()
    o, d = cam.rays()
    i, j = 7, 41
    p = o[i, j] + 3.7 * d[i, j]
    xy, depth = cam.project(p[None])
    assert xy[0] == pytest.approx([j + 0.5, i + 0.5], abs=1e-9)
    assert depth[0] > 0


def test_gl_matrices_put_a_point_on_the_same_pixel_as_project():
    cam = _cam()
    near, far = 0.1, 100.0
    rng = np.random.default_rng(1)
    pts = np.asarray(cam.look_at) + rng.uniform(-1, 1, size=(50, 3))
    clip = (cam.clip_from_camera(near, far) @ cam.camera_from_world() @ np.c_[pts, np.ones(50)].T).T
    ndc = clip[:, :3] / clip[:, 3:4]
    # OpenGL viewport transform; window y grows upwards, image rows grow downwards
    px = (ndc[:, 0] + 1) / 2 * cam.width
    py = cam.height - (ndc[:, 1] + 1) / 2 * cam.height
    xy, depth = cam.project(pts)
    assert np.allclose(np.c_[px, py], xy, atol=1e-9)
    # camera-space depth along the view axis equals the clip w
    assert np.allclose(depth, clip[:, 3])


def test_row_zero_is_the_top_and_centre_ray_is_the_view_axis():
    cam = Camera(position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, 1.0), width=3, height=3, fov_y=90.0)
    _, d = cam.rays()
    assert d[0, 1, 1] > 0 and d[2, 1, 1] < 0          # top row looks up
    assert np.allclose(d[1, 1], [0, 0, 1])
    assert d[1, 0, 0] > 0                              # right-handed, y up, looking +z: column 0 is +x
    assert np.allclose(np.linalg.norm(d, axis=-1), 1.0)


@settings(max_examples=40, deadline=None)
@given(st.floats(10, 120), st.integers(1, 200), st.integers(1, 200), st.floats(-5, 5), st.floats(-5, 5))
def test_projection_roundtrip_property(fov, w, h, x, y):
    cam = Camera(position=(x, y, -3.0), look_at=(0.0, 0.0, 2.0), fov_y=fov, width=w, height=h)
    o, d = cam.rays()
    i, j = h // 2, w - 1
    xy, _ = cam.project((o[i, j] + 2.0 * d[i, j])[None])
    assert np.allclose(xy[0], [j + 0.5, i + 0.5], atol=1e-6)


def test_look_at_is_orthonormal_and_maps_eye_to_origin():
    m = tf.look_at([1, 2, 3], [4, 0, -1], [0, 1, 0])
    assert np.allclose(m[:3, :3] @ m[:3, :3].T, np.eye(3))
    assert np.allclose(tf.transform_points(m, np.array([[1, 2, 3.0]])), 0)


def test_normalize_keeps_the_direction_of_tiny_vectors():
    # a face normal at scene scale 1e-6: cross product of 1e-7 edges is 1e-14 long
    e1, e2 = np.array([1e-7, 0, 0]), np.array([0, 1e-7, 0])
    assert np.allclose(tf.normalize(np.cross(e1, e2)), [0, 0, 1])
    assert np.array_equal(tf.normalize(np.zeros(3)), np.zeros(3))
