"""Tessellation: analytic checks (radius, areas, volumes of CSG results against closed forms),
normals, transforms, quadrics cut to bounds."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.core import transform as tf
from workbench.scene import model as m
from workbench.scene.kinds.quadric import quadric_matrix
from workbench.scene.tessellate import tessellate_object, tessellate_scene


def _area(p):
    P, F = p.positions, p.faces
    return 0.5 * np.linalg.norm(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]), axis=1).sum()


def _volume(parts):
    """Divergence theorem over closed, consistently oriented surfaces (welded or not)."""
    v = 0.0
    for p in parts:
        a, b, c = (p.positions[p.faces[:, k]] for k in range(3))
        v += np.sum(a * np.cross(b, c)) / 6.0
    return v


def _check_normals(p):
    assert np.isfinite(p.normals).all()
    assert np.allclose(np.linalg.norm(p.normals, axis=1), 1.0, atol=1e-9)
    # the winding agrees with the shading normals (counter-clockwise seen from the normal side)
    P, F = p.positions, p.faces
    fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    big = np.linalg.norm(fn, axis=1) > 1e-9 * np.linalg.norm(fn, axis=1).max()
    assert (np.sum(fn * p.normals[F].mean(1), -1)[big] > 0).mean() > 0.99


def test_sphere_on_its_surface_with_radial_normals_and_converging_volume():
    s = m.Sphere("a", center=(1.0, -2.0, 0.5), radius=2.0)
    errs = []
    for level in (1, 2, 4, 8):
        (p,) = tessellate_object(s, level)
        d = p.positions - np.asarray(s.center)
        assert np.allclose(np.linalg.norm(d, axis=1), 2.0)
        assert np.allclose(p.normals, d / 2.0)
        _check_normals(p)
        errs.append(abs(_volume([p]) - 4 / 3 * np.pi * 8) / (4 / 3 * np.pi * 8))
    assert all(b < a / 3 for a, b in zip(errs, errs[1:])), errs  # O(h^2)


def test_plane_box_polygon_areas():
    pl = m.Plane("a", point=(0, 1, 0), normal=(0, 0, 1), size=(3.0, 2.0))
    (p,) = tessellate_object(pl, 3)
    assert _area(p) == pytest.approx(6.0) and np.allclose(p.face_normals, [0, 0, 1])
    bx = m.Box("a", min=(-1, 0, 0), max=(1, 2, 3))
    (p,) = tessellate_object(bx, 2)
    assert _area(p) == pytest.approx(2 * (2 * 2 + 2 * 3 + 2 * 3))
    assert _volume([p]) == pytest.approx(12.0)
    _check_normals(p)
    pent = np.array([[0, 0, 0], [2, 0, 0], [2.5, 1.5, 0], [1, 2.5, 0], [-0.5, 1.5, 0]], dtype=float)
    (p,) = tessellate_object(m.Polygon("a", vertices=pent), 3)
    shoelace = 0.5 * abs(np.dot(pent[:, 0], np.roll(pent[:, 1], -1)) - np.dot(pent[:, 1], np.roll(pent[:, 0], -1)))
    assert _area(p) == pytest.approx(shoelace)
    # flat shading data: one normal and centroid for the whole polygon
    assert np.allclose(p.face_centroids, pent.mean(0))


def test_transform_positions_and_normals():
    M = tf.translate([1, 2, 3]) @ tf.rotate([0, 1, 0], 30) @ tf.scale([2.0, 1.0, 0.5])
    s = m.Sphere("a", world_from_object=M, radius=1.0)
    (p,) = tessellate_object(s, 3)
    assert np.allclose(p.positions, tf.transform_points(M, p.obj_positions))
    # ellipsoid normals: inverse transpose of M applied to the object normal
    assert np.allclose(p.normals, tf.transform_normals(M, p.obj_positions))
    _check_normals(p)


@pytest.mark.parametrize("shape", ["ellipsoid", "cylinder", "cone", "hyperboloid", "hyperboloid2", "paraboloid"])
def test_named_quadrics_on_surface_and_inside_bounds(shape):
    Q, natural = quadric_matrix(shape, (0.8, 1.2, 0.6))
    lo, hi = natural or ((-1.0, -2.0, -1.0), (1.0, 2.0, 1.0))
    q = m.Quadric("a", Q=Q, bounds_min=lo, bounds_max=hi, shape=shape)
    (p,) = tessellate_object(q, 4)
    P = p.obj_positions
    assert (P >= np.asarray(lo) - 1e-9).all() and (P <= np.asarray(hi) + 1e-9).all()
    H = np.c_[P, np.ones(len(P))]
    g = 2 * (H @ Q)[:, :3]
    # on the surface: |P^T Q P| / |grad| is a distance; vertices created by cutting along a
    # bound lie on chords, within a cell of the surface
    dist = np.abs(np.einsum("ni,ij,nj->n", H, Q, H)) / np.maximum(np.linalg.norm(g, axis=1), 1e-12)
    assert np.median(dist) < 1e-9 and dist.max() < 0.05
    ok = np.linalg.norm(g, axis=1) > 1e-6
    assert np.allclose(p.normals[ok], g[ok] / np.linalg.norm(g[ok], axis=1, keepdims=True), atol=1e-9)


def test_general_quadric_by_level_set():
    Q = np.diag([1.0, 1.0, 1.0, -1.0])
    q = m.Quadric("a", Q=Q, bounds_min=(-2, -2, -2), bounds_max=(2, 0.5, 2), shape="general")
    (p,) = tessellate_object(q, 4)
    r = np.linalg.norm(p.obj_positions, axis=1)
    assert np.abs(r - 1.0).max() < 0.02 and p.obj_positions[:, 1].max() <= 0.5 + 1e-6
    _check_normals(p)


def _cap(r, h):
    return np.pi * h * h * (3 * r - h) / 3


def test_csg_volumes_against_closed_forms():
    box = m.Box("ivory", min=(-1, -1, -1), max=(1, 1, 1))
    pip = lambda c: m.Sphere("pip", center=c, radius=0.3)
    die = m.CSG("ivory", op="difference", left=m.CSG("ivory", op="difference", left=box, right=pip((0, 0, 1.1))),
                right=pip((0, 1.1, 0)))
    parts = tessellate_object(die, 8)
    assert {p.material for p in parts} == {"ivory", "pip"}
    want = 8.0 - 2 * _cap(0.3, 0.2)
    assert _volume(parts) == pytest.approx(want, rel=5e-3)
    for p in parts:
        _check_normals(p)
    # the dents are lit from inside the pip spheres: their normals point towards the centre
    dent = next(p for p in parts if p.material == "pip")
    centres = np.where(dent.positions[:, 2:3] > 0.75, [0, 0, 1.1], [0, 1.1, 0])
    assert np.all(np.sum(dent.normals * (centres - dent.positions), -1) > 0)
    lens = m.CSG("a", op="intersection", left=m.Sphere("a", center=(0, 0, -0.5), radius=1.0),
                 right=m.Sphere("a", center=(0, 0, 0.5), radius=1.0))
    assert _volume(tessellate_object(lens, 8)) == pytest.approx(2 * _cap(1.0, 0.5), rel=1e-2)
    union = m.CSG("a", op="union", left=m.Sphere("a", radius=1.0), right=m.Sphere("a", center=(1.5, 0, 0), radius=1.0))
    assert _volume(tessellate_object(union, 8)) == pytest.approx(2 * 4 / 3 * np.pi - 2 * _cap(1.0, 0.25), rel=1e-2)


def test_mesh_with_cancelled_normals_gets_face_normals():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    mesh = m.Mesh("a", vertices=V, faces=np.array([[0, 1, 2]]), normals=np.zeros((3, 3)))
    (p,) = tessellate_object(mesh, 1)
    assert np.allclose(p.normals, [0, 0, 1])


def test_every_bundled_scene_tessellates():
    import workbench
    from workbench.scene.library import bundled
    for path in bundled():
        parts = tessellate_scene(workbench.load_scene(path), 2)
        assert parts and all(np.isfinite(p.positions).all() and np.isfinite(p.normals).all() for p in parts)


def test_csg_with_closed_quadric_leaves():
    Q, _ = quadric_matrix("cylinder", (0.35, 1.0, 0.35))
    cyl = m.Quadric("a", Q=Q, bounds_min=(-0.4, 0.0, -0.4), bounds_max=(0.4, 1.2, 0.4), shape="cylinder")
    capsule = m.CSG("a", op="union", left=cyl, right=m.Sphere("a", center=(0, 1.2, 0), radius=0.35))
    parts = tessellate_object(capsule, 12)
    want = np.pi * 0.35 ** 2 * 1.2 + 2 / 3 * np.pi * 0.35 ** 3
    assert _volume(parts) == pytest.approx(want, rel=1e-2)
    Qe, nat = quadric_matrix("ellipsoid", (1.0, 0.5, 0.8))
    ell = m.Quadric("a", Q=Qe, bounds_min=nat[0], bounds_max=nat[1], shape="ellipsoid")
    half = m.CSG("a", op="difference", left=ell, right=m.Box("a", min=(-2, 0, -2), max=(2, 2, 2)))
    assert _volume(tessellate_object(half, 12)) == pytest.approx(2 / 3 * np.pi * 1.0 * 0.5 * 0.8, rel=1e-2)


def test_csg_quadric_caps_have_flat_normals():
    Q, _ = quadric_matrix("cylinder", (0.5, 1.0, 0.5))
    cyl = m.Quadric("a", Q=Q, bounds_min=(-1, 0.0, -1), bounds_max=(1, 1.0, 1), shape="cylinder")
    parts = tessellate_object(m.CSG("a", op="union", left=cyl, right=m.Sphere("a", center=(3, 0, 0), radius=0.5)), 6)
    p = next(q for q in parts if np.allclose(q.positions[:, 0].mean(), 0.0, atol=0.1))
    top = np.abs(p.positions[:, 1] - 1.0) < 1e-9
    tri_top = top[p.faces].all(1)
    assert tri_top.any()
    assert np.allclose(p.normals[p.faces[tri_top]].reshape(-1, 3), [0, 1, 0])


def test_mirroring_transform_keeps_triangles_wound_outward():
    from workbench.core import transform as tf
    from workbench.scene.model import Sphere
    from workbench.scene.tessellate import tessellate_object
    for M in (np.eye(4), tf.scale([-1.0, 1.0, 1.0])):
        part = tessellate_object(Sphere(material="m", world_from_object=M, radius=1.0), 4)[0]
        P, F = part.positions, part.faces
        geo = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
        outward = np.sum(geo * P[F].mean(1), -1) > 0
        assert outward.mean() > 0.99
