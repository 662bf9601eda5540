"""The ``accel`` option of the ray tracer (bvh, octree, none): the same images, the octree's
references cover its triangles, traversal statistics exact on constructed cases and equal to
the real traversal's hits, bad values refused in one line."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

ACCELS = ("bvh", "octree", "none")


def _scene(objects, materials, camera=None):
    from workbench.scene.io import scene_from_dict
    cam = camera or {"position": [0.0, 1.4, 4.0], "look_at": [0.0, 0.6, 0.0], "fov_y": 40.0,
                     "resolution": [40, 30]}
    return scene_from_dict({"scene": {"background": [0.1, 0.1, 0.12], "ambient": [0.1, 0.1, 0.1]},
                            "camera": cam,
                            "lights": [{"type": "point", "position": [3.0, 4.0, 3.0], "intensity": 0.9}],
                            "materials": materials, "objects": objects})


def _mesh_scene():
    """A 5120-triangle blob on a floor, both reflective (shadow feelers and reflected rays go
    through the triangles' structure too)."""
    return _scene(
        [{"type": "mesh", "material": "clay", "transform": {"translate": [0.0, 0.9, 0.0], "scale": 0.8},
          "generate": {"kind": "blob", "subdivisions": 4, "seed": 3, "amplitude": 0.2}},
         {"type": "plane", "material": "floor", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [8, 8]}],
        {"clay": {"color": [0.75, 0.55, 0.4], "ks": 0.4, "shininess": 30.0, "kr": 0.3},
         "floor": {"color": [0.5, 0.6, 0.6], "kr": 0.2}})


def _many_spheres_scene():
    """64 analytic spheres and 16 small sphere meshes (1280 triangles) in a grid."""
    objs = []
    for i in range(8):
        for j in range(8):
            objs.append({"type": "sphere", "material": "red" if (i + j) % 2 else "glass",
                         "center": [-1.4 + 0.4 * i, 0.15, -1.4 + 0.4 * j], "radius": 0.15})
    for i in range(4):
        for j in range(4):
            objs.append({"type": "mesh", "material": "blue", "generate": {"kind": "icosphere", "subdivisions": 2},
                         "transform": {"translate": [-1.2 + 0.8 * i, 0.55, -1.2 + 0.8 * j], "scale": 0.2}})
    objs.append({"type": "plane", "material": "floor", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [8, 8]})
    return _scene(objs, {"red": {"color": [0.8, 0.2, 0.2], "kr": 0.2},
                         "glass": {"color": [0.9, 0.9, 0.9], "kt": 0.6, "kr": 0.1, "ior": 1.5},
                         "blue": {"color": [0.2, 0.3, 0.8], "ks": 0.5, "kr": 0.25},
                         "floor": {"color": [0.6, 0.6, 0.5]}})


@pytest.mark.parametrize("make", [_mesh_scene, _many_spheres_scene], ids=["mesh", "many_spheres"])
def test_every_structure_gives_the_same_image(make):
    import workbench
    scene = make()
    images = {a: workbench.render(scene, "raytrace", accel=a, max_depth=3).image for a in ACCELS}
    assert np.ptp(images["bvh"]) > 0.1  # a picture, not a blank
    for a in ("octree", "none"):
        assert np.array_equal(images[a], images["bvh"]), a


def test_the_octree_references_every_triangle_in_every_cell_its_box_meets():
    from workbench.renderers.raytrace.octree import REF_FACTOR, build_octree
    rng = np.random.default_rng(4)
    c = rng.uniform(-5, 5, size=(3000, 1, 3))
    tri = (c + rng.normal(scale=0.3, size=(3000, 3, 3))).reshape(-1, 9)
    refs, (node, child, leaf) = build_octree(tri)
    assert np.array_equal(np.unique(refs), np.arange(len(tri)))
    assert len(tri) < len(refs) <= REF_FACTOR * len(tri)
    # each leaf's cell box (from its parent's slot) meets the box of every triangle it lists, and
    # every triangle whose box meets a leaf's cell is listed there
    tb = np.concatenate([tri.reshape(-1, 3, 3).min(1), tri.reshape(-1, 3, 3).max(1)], 1)
    checked = 0
    for nd, j in zip(*np.nonzero(child < -1)):
        lo, hi = node[nd, :3, j], node[nd, 3:, j]
        first, count = leaf[-2 - child[nd, j]]
        listed = set(refs[first:first + count].tolist())
        meets = np.flatnonzero((tb[:, :3] <= hi).all(1) & (tb[:, 3:] >= lo).all(1))
        assert listed == set(meets.tolist())
        assert np.allclose(hi - lo, (hi - lo)[0], rtol=1e-12)  # a cube
        checked += 1
    assert checked == len(leaf) > 8


def _structures(tri):
    from workbench.renderers.raytrace.accel import build_accel
    for a in ACCELS:
        order, tree = build_accel(tri, a)
        yield a, order, tree


def test_counting_traversal_finds_the_kernels_hits_and_brute_force_counts_are_exact(bvh_hit):
    from workbench.renderers.kernels import walks
    from workbench.renderers.raytrace.traversal_stats import count_hit
    rng = np.random.default_rng(7)
    c = rng.uniform(-3, 3, size=(500, 1, 3))
    tri = (c + rng.normal(scale=0.4, size=(500, 3, 3))).reshape(-1, 9)
    stack = np.empty((walks.BVH_STACK, 2))
    O = rng.uniform(-6, 6, size=(300, 3))
    D = rng.normal(size=(300, 3))
    D /= np.linalg.norm(D, axis=1, keepdims=True)
    D[:100] = -O[:100] / np.linalg.norm(O[:100], axis=1, keepdims=True)  # towards the centre: hits
    hits = {}
    for a, order, tree in _structures(tri):
        arrays = (tree.node, tree.child, tree.leaf, tree.first, tree.tv4)
        ts = []
        for o, d in zip(O, D):
            t, tr, _, _, _, _ = bvh_hit(arrays, *o, *d, 0.0, np.inf, np.bool_(False), stack)
            cnt = np.zeros(2, np.int64)
            t2, tr2 = count_hit(arrays, *o, *d, 0.0, np.inf, stack, cnt)
            assert (t2, tr2) == (t, tr)
            assert cnt[0] >= 1 and cnt[1] % 4 == 0
            if a == "none":  # one node; every triangle (in groups of four) if the ray meets their box
                assert cnt[0] == 1 and cnt[1] in (0, 4 * ((len(tri) + 3) // 4))
                assert cnt[1] > 0 or tr < 0
            ts.append(t)
        hits[a] = np.array(ts)
    assert np.isfinite(hits["bvh"]).sum() >= 100
    for a in ("octree", "none"):
        assert np.array_equal(hits[a], hits["bvh"])


def test_stats_count_one_node_for_rays_that_miss_the_root_box():
    import workbench
    # the camera looks away from the mesh: every ray misses its box (and there is nothing else)
    scene = _scene([{"type": "mesh", "material": "m", "generate": {"kind": "icosphere", "subdivisions": 1}}],
                   {"m": {"color": [0.5, 0.5, 0.5]}},
                   camera={"position": [0, 0, 5], "look_at": [0, 0, 10], "fov_y": 30.0, "resolution": [8, 6]})
    for a in ACCELS:
        st = workbench.render(scene, "raycast", accel=a, traversal_stats=True).stats
        assert st["accel_nodes_per_ray"] == 1.0
        assert st["accel_triangle_tests_per_ray"] == 0.0 == st["accel_primitive_tests_per_ray"]


def test_stats_on_the_mesh_scene_are_plausible():
    import workbench
    scene = _mesh_scene()
    st = {a: workbench.render(scene, "raycast", accel=a, traversal_stats=True).stats for a in ACCELS}
    T = st["bvh"]["triangles"]
    assert T == 5120 and st["octree"]["triangle_references"] > T == st["bvh"]["triangle_references"]
    # brute force: every ray into the box tests all T triangles (T / 4 groups), one node each
    assert st["none"]["accel_nodes_per_ray"] == 1.0
    share = st["none"]["accel_triangle_tests_per_ray"] / T
    assert 0.05 < share < 1.0  # the share of rays meeting the mesh's box (not all, not none)
    for a in ("bvh", "octree"):  # the trees test a small fraction of that
        assert 1.0 < st[a]["accel_nodes_per_ray"] < 200
        assert st[a]["accel_triangle_tests_per_ray"] < 0.02 * st["none"]["accel_triangle_tests_per_ray"]
        # the floor: the one analytic primitive, in the primitives' tree, tested by the rays
        # that enter its box (the camera looks down at it: most of them)
        assert 0.5 < st[a]["accel_analytic_tests_per_ray"] <= 1.0
        assert st[a]["accel_primitive_tests_per_ray"] == pytest.approx(
            st[a]["accel_triangle_tests_per_ray"] + st[a]["accel_analytic_tests_per_ray"], rel=1e-12)
    # brute force: the floor in the list, tested by every ray
    assert st["none"]["accel_analytic_tests_per_ray"] == 1.0
    assert "accel_nodes_per_ray" not in workbench.render(scene, "raycast").stats  # only when asked


def test_octree_memory_estimate_counts_its_references():
    from workbench.renderers.base import get_renderer
    from workbench.renderers.raytrace.octree import REF_FACTOR
    from workbench.renderers.base import convert_options
    r = get_renderer("raycast")
    scene = _mesh_scene()
    est = {a: r.estimate_bytes(scene, 40, 30, **convert_options(r, {"accel": a})) for a in ACCELS}
    assert est["bvh"] == est["none"] < est["octree"]
    assert est["octree"] - est["bvh"] >= (REF_FACTOR - 1) * 5120 * 33 * 8  # the repeated triangle rows


def test_a_bad_accel_value_is_one_line_and_exit_2(tmp_path):
    r = subprocess.run([sys.executable, "-m", "workbench.app.cli", "render", "whitted", "-m", "raycast",
                        "--set", "accel=kdtree", "-o", str(tmp_path / "x.png")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "accel" in r.stderr and "bvh, octree, none" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "x.png").exists()


def test_octree_of_coincident_triangles_stays_within_its_reference_budget(bvh_hit):
    # 600 copies of one triangle: every cut would copy them all into one octant, level after
    # level; the depth and the reference budget end it, and rays still find the triangle
    from workbench.renderers.kernels import walks
    from workbench.renderers.raytrace.octree import REF_FACTOR, build_octree
    tri = np.tile([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], (600, 1))
    tri[:300, 2] = tri[:300, 5] = tri[:300, 8] = 0.5  # and 300 copies of a parallel one, 0.5 behind
    refs, _ = build_octree(tri)
    assert len(tri) <= len(refs) <= REF_FACTOR * len(tri)
    stack = np.empty((walks.BVH_STACK, 2))
    for a, order, tree in _structures(tri):
        arrays = (tree.node, tree.child, tree.leaf, tree.first, tree.tv4)
        t, k, _, _, _, _ = bvh_hit(arrays, 0.2, 0.2, -1.0, 0.0, 0.0, 1.0, 0.0, np.inf, np.bool_(False), stack)
        assert abs(t - 1.0) <= 1e-12 and k >= 0 and tri[order[k], 2] == 0.0, a
        t, k, _, _, _, _ = bvh_hit(arrays, 0.2, 0.2, 2.0, 0.0, 0.0, -1.0, 0.0, np.inf, np.bool_(False), stack)
        assert abs(t - 1.5) <= 1e-12 and tri[order[k], 2] == 0.5, a
