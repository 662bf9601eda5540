"""Ray tracer intersections: analytic values, the numba kernels against the readable shapes,
CSG identities, BVH against brute force, watertight meshes, no self-intersection."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import workbench
from workbench.renderers.kernels import shapes as kernel_shapes
from workbench.core.jit_options import python_twin
from workbench.renderers.raytrace import shapes
from workbench.scene.io import scene_from_dict
from workbench.scene.kinds import csg, quadric, sphere
from workbench.scene.kinds.quadric import quadric_matrix


def scene(objects, materials=None, lights=(), **extra):
    mats = {"m": {"color": [0.8, 0.8, 0.8]}}
    mats.update(materials or {})
    d = {"camera": {"position": [0, 0, -10], "look_at": [0, 0, 0]}, "materials": mats,
         "objects": [dict(o, material=o.get("material", "m")) for o in objects],
         "lights": list(lights)}
    d.update(extra)
    return scene_from_dict(d)


def cast(sc, O, D):
    return workbench.raytrace.intersect(sc, np.atleast_2d(O).astype(float), np.atleast_2d(D).astype(float))


def test_sphere_away_from_origin_t4_and_t6():
    """DESIGN errata 1: origin 0, direction +z, centre (0, 0, 5), r = 1 -> t = 4 and 6."""
    assert [t for t, _ in sphere.roots((0, 0, 5), 1.0, np.zeros(3), np.array([0, 0, 1.0]))] == pytest.approx([4, 6])
    ok, t0, t1 = python_twin(kernel_shapes.sphere_roots)(np.array([[0, 0, 5, 1.0]]), 0, 0, 0, 0, 0, 0, 1.0)
    assert ok and (t0, t1) == pytest.approx((4, 6))
    sc = scene([{"type": "sphere", "center": [0, 0, 5], "radius": 1.0}])
    t, n, obj = cast(sc, [[0, 0, 0], [0, 0, 5]], [[0, 0, 1], [0, 0, 1]])
    assert t == pytest.approx([4, 1]) and obj.tolist() == [0, 0]
    assert n[0] == pytest.approx([0, 0, -1]) and n[1] == pytest.approx([0, 0, 1])


@settings(max_examples=60, deadline=None, derandomize=True)
@given(b=st.floats(0.0, 3.0), phi=st.floats(0, 2 * np.pi), r=st.floats(0.1, 2.0),
       scale=st.sampled_from([1e-6, 1.0, 1e6]))
def test_hit_iff_ray_passes_within_radius(b, phi, r, scale):
    if abs(b - r) < 1e-6 * r:
        return  # tangent within rounding: either answer is right
    c = np.array([1.0, -2.0, 30.0]) * scale
    sc = scene([{"type": "sphere", "center": c.tolist(), "radius": r * scale}])
    O = (np.array([b * np.cos(phi), b * np.sin(phi), -20.0]) * scale + [c[0], c[1], 0])
    t, n, obj = cast(sc, O, [0, 0, 1])
    assert (obj[0] == 0) == (b < r)
    if b < r:
        assert t[0] == pytest.approx(c[2] - O[2] - np.sqrt(r * r - b * b) * scale, rel=1e-9)


def test_tiny_far_and_huge_near_spheres():
    """Cancellation cases (Haines et al. 2019): a 1e-3 sphere 1e6 away, a 1e6 sphere just ahead."""
    sc = scene([{"type": "sphere", "center": [0, 0, 1e6], "radius": 1e-3}])
    t, n, obj = cast(sc, [[0, 0, 0], [0, 2e-3, 0]], [[0, 0, 1], [0, 0, 1]])
    assert obj.tolist() == [0, -1] and t[0] == pytest.approx(1e6 - 1e-3, rel=1e-12)
    sc = scene([{"type": "sphere", "center": [0, 0, 1e6 + 1], "radius": 1e6}])
    t, n, obj = cast(sc, [0, 0, 0], [0, 0, 1])
    assert t[0] == pytest.approx(1.0, rel=1e-9) and n[0] == pytest.approx([0, 0, -1])


def test_quadric_normals_are_the_gradient():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(3, 3))
    Q = np.zeros((4, 4))
    Q[:3, :3] = A @ A.T + np.eye(3)  # an ellipsoid, rotated
    Q[3, 3] = -1.0
    sc = scene([{"type": "quadric", "Q": Q.tolist(), "bounds": {"min": [-3] * 3, "max": [3] * 3}}])
    O = rng.normal(size=(200, 3)) * 0.1 + [0, 0, -8]
    D = np.c_[rng.normal(size=(200, 2)) * 0.05, np.ones(200)]
    t, n, obj = cast(sc, O, D)
    hit = obj == 0
    assert hit.sum() > 50
    P = np.c_[O[hit] + t[hit, None] * D[hit], np.ones(hit.sum())]
    assert np.abs(np.einsum("ij,jk,ik->i", P, Q, P)).max() < 1e-9  # on the surface
    g = (P @ Q)[:, :3]  # gradient / 2
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    assert np.allclose(n[hit], g, atol=1e-9)


def test_quadric_with_zero_quadratic_coefficient():
    """A = 0 (errata 2): a ray along a paraboloid's axis has one linear root."""
    Q, _ = quadric_matrix("paraboloid", (1.0, 1.0, 1.0))
    A, B, C = quadric.quadric_coefficients(Q, np.array([0, 5.0, 0]), np.array([0, -1.0, 0]))
    assert A == 0.0 and quadric.solve_quadratic(A, B, C) == pytest.approx([5.0])
    sc = scene([{"type": "quadric", "shape": "paraboloid", "bounds": {"min": [-2] * 3, "max": [2] * 3}}])
    t, n, obj = cast(sc, [[0, 5, 0], [0.5, 5, 0]], [[0, -1, 0], [0, -1, 0]])
    assert t == pytest.approx([5.0, 5.0 - 0.25])
    assert n[0] == pytest.approx([0, -1, 0])  # gradient of x^2 + z^2 - y at the vertex
    # a ray parallel to a cylinder's axis never meets it (A = B = 0)
    sc = scene([{"type": "quadric", "shape": "cylinder", "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}}])
    assert cast(sc, [0.5, -5, 0], [0, 1, 0])[2][0] == -1


def test_cut_quadric_is_open_and_bounded():
    sc = scene([{"type": "quadric", "shape": "cylinder", "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}}])
    t, n, obj = cast(sc, [[0, 0, -5], [0, 2, -5], [0, 5, 0]], [[0, 0, 1], [0, 0, 1], [0, -1, 0]])
    assert obj.tolist() == [0, -1, -1]  # inside through the open top: no cap
    assert t[0] == pytest.approx(4.0)


def test_box_rectangle_polygon_and_transform():
    objs = [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1],
             "transform": {"translate": [0, 0, 5], "rotate": [0, 45, 0]}},
            {"type": "plane", "point": [10, 0, 0], "normal": [0, 0, -1], "size": [2, 4]},
            {"type": "polygon", "vertices": [[20, 0, 0], [22, 0, 0], [20, 2, 0]]}]
    sc = scene(objs)
    O = np.array([[0.3, 0, -5], [10.9, 1.9, -5], [11.1, 0, -5], [20.5, 0.5, -5], [21.5, 1.5, -5]], float)
    t, n, obj = cast(sc, O, np.tile([0, 0, 1.0], (5, 1)))
    assert obj.tolist() == [0, 1, -1, 2, -1]
    assert t[0] == pytest.approx(10.3 - np.sqrt(2)) and n[0] == pytest.approx([np.sqrt(0.5), 0, -np.sqrt(0.5)])
    assert t[1] == pytest.approx(5) and t[3] == pytest.approx(5)


def test_transformed_sphere_equals_ellipsoid_quadric():
    tr = {"translate": [0.3, -0.2, 4], "rotate": [10, 20, 30], "scale": [1, 2, 0.5]}
    a = scene([{"type": "sphere", "radius": 1.0, "transform": tr}])
    rigid = {"translate": tr["translate"], "rotate": tr["rotate"]}
    b = scene([{"type": "quadric", "shape": "ellipsoid", "radii": [1, 2, 0.5], "transform": rigid}])
    rng = np.random.default_rng(0)
    O = np.tile([0, 0, -3.0], (300, 1))
    D = np.c_[rng.normal(size=(300, 2)) * 0.25, np.ones(300)]
    ta, na, oa = cast(a, O, D)
    tb, nb, ob = cast(b, O, D)
    assert (oa == 0).sum() > 50 and np.array_equal(oa, ob)
    h = oa == 0
    assert np.allclose(ta[h], tb[h], rtol=1e-10) and np.allclose(na[h], nb[h], atol=1e-8)


# --------------------------------------------------------------------------- CSG
SPHERE = {"type": "sphere", "radius": 1.0, "center": [0, 0, 0]}


def _rays(n=400, seed=1):
    rng = np.random.default_rng(seed)
    O = np.tile([0, 0, -5.0], (n, 1))
    D = np.c_[rng.uniform(-0.3, 0.3, size=(n, 2)), np.ones(n)]
    return O, D


@pytest.mark.parametrize("leaf", [SPHERE, {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1]},
                                  {"type": "quadric", "shape": "cylinder", "bounds": {"min": [-1] * 3, "max": [1] * 3}}])
def test_csg_identities(leaf):
    """A - A is empty, A n A = A u A = A (coincident surfaces)."""
    O, D = _rays()
    alone = scene([{"type": "csg", "op": "union", "left": leaf,
                    "right": {"type": "sphere", "radius": 1e-3, "center": [50, 0, 0]}}])
    ta, na, _ = cast(alone, O, D)
    assert np.isfinite(ta).sum() > 100
    for op in ("union", "intersection"):
        t, n, _ = cast(scene([{"type": "csg", "op": op, "left": leaf, "right": leaf}]), O, D)
        assert np.array_equal(np.isfinite(t), np.isfinite(ta))
        h = np.isfinite(ta)
        assert np.allclose(t[h], ta[h]) and np.allclose(n[h], na[h])
    t, _, obj = cast(scene([{"type": "csg", "op": "difference", "left": leaf, "right": leaf}]), O, D)
    assert np.isinf(t).all() and (obj == -1).all()


def test_csg_difference_flips_the_subtracted_normal():
    sc = scene([{"type": "csg", "op": "difference", "left": {"type": "box", "min": [-1] * 3, "max": [1] * 3},
                 "right": {"type": "sphere", "center": [0, 0, -1], "radius": 0.5}}])
    t, n, obj = cast(sc, [[0, 0, -5], [0.8, 0.8, -5]], [[0, 0, 1], [0, 0, 1]])
    assert t == pytest.approx([4.5, 4.0])
    assert n[0] == pytest.approx([0, 0, -1])  # the pit's floor faces the viewer (into the hole)


def test_csg_reference_interval_lists():
    A = [csg.Crossing(1.0, "a"), csg.Crossing(3.0, "a")]
    B = [csg.Crossing(2.0, "b"), csg.Crossing(4.0, "b")]
    ts = lambda L: [c.t for c in L]  # noqa: E731
    assert ts(csg.combine("union", A, B, 1e-9)) == [1, 4]
    assert ts(csg.combine("intersection", A, B, 1e-9)) == [2, 3]
    d = csg.combine("difference", A, B, 1e-9)
    assert ts(d) == [1, 2] and d[1].flip and not d[0].flip
    assert csg.combine("difference", A, A, 1e-9) == []


# --------------------------------------------------------------------------- meshes
@pytest.fixture(scope="module")
def blob():
    from workbench.scene.generate import generate_mesh
    m = generate_mesh("blob", subdivisions=3)
    return np.asarray(m.vertices), np.asarray(m.faces)


def _mesh_scene(V, F):
    return scene([{"type": "mesh", "vertices": V.tolist(), "faces": F.tolist()}])


def test_bvh_equals_brute_force(blob):
    V, F = blob
    sc = _mesh_scene(V, F)
    rng = np.random.default_rng(5)
    O = rng.normal(size=(500, 3)) * 3
    D = rng.normal(size=(500, 3)) * 0.7 - O  # mostly towards the blob, some from inside
    t, n, obj = cast(sc, O, D)
    for i in range(0, 500, 5):
        tb, _, _ = shapes.triangles(V[F], O[i], D[i])
        tb = np.where(tb > 0, tb, np.inf).min()
        assert t[i] == pytest.approx(tb, rel=1e-9) if np.isfinite(tb) else np.isinf(t[i])
    assert np.isfinite(t).sum() > 100


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000))
def test_mesh_is_watertight_at_edges_and_vertices(seed, blob):
    """Rays aimed exactly at vertices and edge points of a closed mesh from outside always hit
    (Woop et al. 2013 watertight test), and cross it an even number of times."""
    V, F = blob
    sc = _mesh_scene(V, F)
    rng = np.random.default_rng(seed)
    f = F[rng.integers(len(F), size=64)]
    s = rng.uniform(size=(64, 1))
    targets = np.r_[V[f[:32, 0]], s[32:] * V[f[32:, 0]] + (1 - s[32:]) * V[f[32:, 1]]]
    # from the front of the face (a silhouette edge, grazed, may be missed by rounding)
    nf = np.cross(V[f[:, 1]] - V[f[:, 0]], V[f[:, 2]] - V[f[:, 0]])
    nf /= np.linalg.norm(nf, axis=1, keepdims=True)
    dirs = nf + 0.3 * rng.normal(size=(64, 3))
    dirs = np.where(np.sum(dirs * nf, 1, keepdims=True) > 0.5 * np.linalg.norm(dirs, axis=1, keepdims=True), dirs, nf)
    O = targets + 3 * dirs
    t, n, obj = cast(sc, O, targets - O)
    assert (obj == 0).all()
    assert (t <= 1.0 + 1e-9).all()


def test_vertex_normals_do_not_change_geometric_normal(blob):
    V, F = blob
    sc = _mesh_scene(V, F)
    t, n, obj = cast(sc, [0, 0, -5], [0, 0, 1])
    assert n[0] @ [0, 0, -1] > 0.5


def test_geometric_normal_alone_equals_the_whole_surface_data(blob):
    """``trace_batch`` without the surface arrays (as ``intersect`` calls it) gives the same
    distances, primitives and geometric normals, to the bit, as with them: a mesh, a sphere
    and a CSG difference (a flipped face) in one scene."""
    from workbench.core.tol import tol
    from workbench.renderers.raytrace.flatten import flatten
    from workbench.renderers.raytrace.whitted import _alloc, _kernels
    V, F = blob
    sc = scene([{"type": "mesh", "vertices": V.tolist(), "faces": F.tolist()},
                {"type": "sphere", "center": [3, 0, 0], "radius": 1.0},
                {"type": "csg", "op": "difference", "left": {"type": "box", "min": [-4, -1, -1], "max": [-2, 1, 1]},
                 "right": {"type": "sphere", "center": [-3, 0, -1], "radius": 0.5}}])
    rng = np.random.default_rng(9)
    n = 600
    O = np.c_[rng.uniform(-5, 5, n), rng.uniform(-2, 2, n), np.full(n, -10.0)]
    D = np.c_[rng.normal(0, 0.02, (n, 2)), np.ones(n)]
    sd = flatten(sc)
    out = []
    for surface in (True, False):
        h = _alloc(n, surface)
        _kernels().trace_batch(sd.kernel_args(), O, D, np.zeros(n), np.full(n, np.inf), tol.zero, tol.ray_offset,
                               sd.extent, tol.normal_cancel, False, h["t"], h["prim"], h["ng"], h["ns"], h["uv"],
                               h["po"], h["ev"])
        hit = h["prim"] >= 0
        out.append((h["t"], h["prim"], h["ng"][hit]))
    assert len(set(sd.obj[out[0][1][out[0][1] >= 0]])) == 3  # every object hit
    for a, b in zip(*out):
        assert np.array_equal(a, b)


# --------------------------------------------------------------------------- self-intersection
@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000), scale=st.sampled_from([1e-6, 1e-3, 1.0, 1e3, 1e6]))
def test_no_self_intersection_of_offset_rays(seed, scale):
    """Secondary rays leave a surface from ``P + offset N`` (offset scaled with the hit point
    and the scene, tol.offset_scale): outward rays never hit the convex object they leave, and
    inward rays cross the whole chord (no hit at t ~ 0)."""
    from workbench.core.tol import offset_scale
    from workbench.renderers.raytrace.flatten import flatten
    rng = np.random.default_rng(seed)
    c = rng.normal(size=3) * 10 * scale
    r = rng.uniform(0.5, 2.0) * scale
    sc = scene([{"type": "sphere", "center": c.tolist(), "radius": r},
                {"type": "box", "min": (c - 3 * r + [0, 0, 10 * r]).tolist(), "max": (c + 3 * r + [0, 0, 10 * r]).tolist()}])
    ext = flatten(sc).extent
    N = rng.normal(size=(200, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    P = c + r * N
    off = np.array([offset_scale(np.abs(p).max(), ext) for p in P])[:, None]
    D = rng.normal(size=(200, 3))
    D = np.where(np.sum(D * N, 1, keepdims=True) > 0, D, -D)  # outward hemisphere
    t, _, obj = cast(sc, P + off * N, D)
    assert not (obj == 0).any()
    t, _, obj = cast(sc, P - off * N, -D)
    cos = np.sum(N * D / np.linalg.norm(D, axis=1, keepdims=True), 1)
    chord = 2 * r * cos
    assert (obj == 0).all()
    # the far side of the chord (the origin moved inwards by `off` shortens it by ~off / cos)
    assert (np.abs(t * np.linalg.norm(D, axis=1) - chord) <= 1e-6 * chord + 4 * off[:, 0] / cos).all()


def test_intersect_rejects_bad_input():
    sc = scene([SPHERE])
    with pytest.raises(workbench.WorkbenchError):
        cast(sc, np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(workbench.WorkbenchError):
        workbench.raytrace.intersect(sc, np.zeros((2, 2)), np.zeros((2, 2)))


def test_rays_in_a_face_plane_of_an_axis_aligned_mesh_are_not_culled():
    """A ray with zero direction components lying exactly in the plane of a box face (e.g. the
    middle row of an odd-sized image, the camera level with a face) is inside that slab: the
    BVH must not cull the box (0 * inf is NaN, not a bound), so the watertight test finds the
    front face's edge."""
    g = np.linspace(-1.0, 1.0, 5)
    V, F = [], []
    for ax in range(3):  # a closed cube [-1, 1]^3 of 6 x 4 x 4 quads
        for sign in (-1.0, 1.0):
            for a0, a1 in zip(g[:-1], g[1:]):
                for b0, b1 in zip(g[:-1], g[1:]):
                    quad = []
                    for a, b in ((a0, b0), (a1, b0), (a1, b1), (a0, b1)):
                        p = [0.0, 0.0, 0.0]
                        p[ax], p[(ax + 1) % 3], p[(ax + 2) % 3] = sign, a, b
                        quad.append(p)
                    k = len(V)
                    V += quad
                    F += [[k, k + 1, k + 2], [k, k + 2, k + 3]]
    sc = _mesh_scene(np.array(V), np.array(F))
    xs = np.array([-1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5])
    X, Y = np.meshgrid(xs, xs)
    O = np.stack([X.ravel(), Y.ravel(), np.full(X.size, -3.0)], 1)
    t, n, obj = cast(sc, O, np.tile([0.0, 0.0, 1.0], (len(O), 1)))
    inside = (np.abs(O[:, 0]) <= 1.0) & (np.abs(O[:, 1]) <= 1.0)
    assert np.array_equal(np.isfinite(t), inside)
    assert np.allclose(t[inside], 2.0)


def test_a_triangles_normal_from_its_packed_group_is_the_tables():
    """``trace_batch`` without the surface data takes a triangle hit's geometric normal from the
    packed group the walk tested (``intersect.closest``), with it from the triangle table
    (``intersect.geometric_normal``): the same normal to the bit, for every hit of the mesh
    scene's camera rays (a wrong group or lane would give a neighbour's normal)."""
    from dataclasses import replace

    from workbench.core.tol import tol
    from workbench.renderers.raytrace.flatten import flatten
    from workbench.renderers.raytrace.whitted import _alloc, _kernels
    sc = workbench.load_scene("mesh")
    sc = replace(sc, camera=sc.camera.with_resolution(48, 36))
    O, D = (np.ascontiguousarray(a.reshape(-1, 3)) for a in sc.camera.rays())
    sd = flatten(sc)
    n = len(O)
    out = {}
    for surface in (False, True):
        h = _alloc(n, surface)
        _kernels().trace_batch(sd.kernel_args(), O, D, np.zeros(n), np.full(n, np.inf), tol.zero, tol.ray_offset,
                               sd.extent, tol.normal_cancel, False, h["t"], h["prim"], h["ng"], h["ns"], h["uv"],
                               h["po"], h["ev"])
        out[surface] = h
    tri_hit = np.isin(out[True]["prim"], sd.tri_prim)
    assert tri_hit.sum() > 200 and np.array_equal(out[False]["prim"], out[True]["prim"])
    assert np.array_equal(out[False]["ng"][tri_hit], out[True]["ng"][tri_hit])
