"""Analytic primitives under the ``accel`` structures (bvh, octree): the bounded ones in a
tree of their own, the unbounded ones in a list; the same images as brute force (``none``),
ties between coincident surfaces included; traversal statistics that show the tree working."""
from __future__ import annotations

import glob
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

ACCELS = ("bvh", "octree", "none")
# the API-made unbounded cylinder: its infinite bounds meet the scene extent's matmul (inf * 0)
pytestmark = pytest.mark.filterwarnings("ignore:invalid value encountered in matmul:RuntimeWarning")
ROOT = Path(__file__).resolve().parents[3]


def _spheres_scene(n=120, seed=5):
    """``n`` random spheres (every third stretched into an ellipsoid by its transform, every
    fifth glass), 12 pairs of coincident spheres of different materials (equal ``t``: the
    lower row must win, as in the brute-force loop), a box, a CSG difference, a cylinder
    unbounded along its axis (the list) and a floor; reflective and transmissive, so that secondary rays and
    shadow feelers go through the structures too."""
    from workbench.scene.io import scene_from_dict
    rng = np.random.default_rng(seed)
    objs = []
    for i in range(n):
        o = {"type": "sphere", "material": "glass" if i % 5 == 0 else ("red" if i % 2 else "blue"),
             "center": [float(x) for x in rng.uniform(-2, 2, 3) + [0, 2.1, 0]], "radius": float(rng.uniform(0.08, 0.25))}
        if i % 3 == 0:
            o["transform"] = {"scale": [1.0, 0.5, 1.6]}
        objs.append(o)
    for i in range(12):
        c = [float(x) for x in rng.uniform(-2, 2, 3) + [0, 2.1, 0]]
        objs.append({"type": "sphere", "material": "red", "center": c, "radius": 0.3})
        objs.append({"type": "sphere", "material": "blue", "center": c, "radius": 0.3})
    objs += [{"type": "box", "material": "blue", "min": [-0.3, 0.0, -0.3], "max": [0.3, 0.6, 0.3]},
             {"type": "csg", "op": "difference", "material": "red",
              "left": {"type": "sphere", "material": "red", "center": [1.5, 0.5, 1.0], "radius": 0.5},
              "right": {"type": "box", "material": "blue", "min": [1.5, 0.0, 0.5], "max": [2.1, 1.1, 1.6]}},
             {"type": "quadric", "shape": "cylinder", "radii": [0.1, 1.0, 0.1], "material": "blue",
              "transform": {"translate": [-2.5, 0.0, -1.0]}, "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}},
             {"type": "plane", "material": "floor", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [10, 10]}]
    scene = scene_from_dict({
        "scene": {"background": [0.1, 0.1, 0.12], "ambient": [0.1, 0.1, 0.1]},
        "camera": {"position": [0.0, 3.0, 7.0], "look_at": [0.0, 1.5, 0.0], "fov_y": 45.0, "resolution": [48, 36]},
        "lights": [{"type": "point", "position": [3.0, 6.0, 3.0], "intensity": 0.9}],
        "materials": {"red": {"color": [0.8, 0.2, 0.2], "kr": 0.2, "ks": 0.3},
                      "blue": {"color": [0.2, 0.3, 0.8], "ks": 0.5},
                      "glass": {"color": [0.9, 0.9, 0.9], "kt": 0.6, "kr": 0.1, "ior": 1.5},
                      "floor": {"color": [0.6, 0.6, 0.5], "kr": 0.1}},
        "objects": objs})
    # a scene file's quadric is always cut to finite bounds; through the API one may be
    # unbounded along its axis: the list of primitives every ray tests
    k = len(objs) - 2
    cyl = replace(scene.objects[k], bounds_min=(-1.0, -np.inf, -1.0), bounds_max=(1.0, np.inf, 1.0))
    return replace(scene, objects=scene.objects[:k] + (cyl,) + scene.objects[k + 1:])


def test_the_structures_hold_the_bounded_primitives_and_list_the_unbounded():
    from workbench.renderers.raytrace.flatten import flatten
    from workbench.scene.kinds import world_bounds
    scene = _spheres_scene()
    top = None
    for a in ACCELS:
        sd = flatten(scene, a)
        p = sd.prims
        rows = np.flatnonzero(sd.top)
        top = rows if top is None else top
        assert np.array_equal(rows, top)
        if a == "none":  # brute force: every row in the list, in row order
            assert np.array_equal(p.free, rows) and len(p.ref) == 0
            continue
        # the cylinder alone is unbounded
        assert [scene.objects[sd.obj[k]].kind for k in p.free] == ["quadric"]
        in_tree = np.unique(p.ref)
        assert np.array_equal(np.sort(np.concatenate([in_tree, p.free])), rows)
        if a == "bvh":
            assert len(p.ref) == len(in_tree)  # each once
        # every leaf's box holds the world bounds of each primitive it lists
        for q in range(len(p.child)):
            for j in range(4):
                c = p.child[q, j]
                if c > -2:
                    continue
                first, count = p.leaf[-2 - c]
                box = p.node[q, :, j]
                for k in p.ref[first:first + count]:
                    lo, hi = world_bounds(scene.objects[sd.obj[k]], np.eye(4))
                    if a == "bvh":  # a bvh box holds its items; an octree cell only meets them
                        assert np.all(box[:3] <= lo) and np.all(hi <= box[3:])
                    else:
                        assert np.all(box[:3] <= hi) and np.all(lo <= box[3:])


@pytest.mark.parametrize("method", ["raycast", "raytrace"])
def test_analytic_structures_give_the_brute_force_image(method):
    import workbench
    scene = _spheres_scene()
    opts = dict(max_depth=4) if method == "raytrace" else {}
    images = {a: workbench.render(scene, method, accel=a, **opts).image for a in ACCELS}
    assert np.ptp(images["none"]) > 0.1
    for a in ("bvh", "octree"):
        assert np.array_equal(images[a], images["none"]), a
    # transmissive shadows: the feelers' closest hits go through the structures as well
    t = {a: workbench.render(scene, method, accel=a, transmissive_shadows=True, **opts).image for a in ("bvh", "none")}
    assert np.array_equal(t["bvh"], t["none"])
    assert not np.array_equal(t["none"], images["none"])  # the option changed the image


def test_a_tie_between_coincident_spheres_goes_to_the_first_as_in_brute_force():
    import workbench
    scene = _spheres_scene(n=0)
    img = {a: workbench.render(scene, "raycast", accel=a).image for a in ACCELS}
    # the pairs are red then blue: brute force shows red; so must the trees
    for a in ("bvh", "octree"):
        assert np.array_equal(img[a], img["none"])
    r, b = img["none"][..., 0], img["none"][..., 2]
    assert (r > b + 0.2).sum() > 20


def test_traversal_stats_show_the_tree_testing_few_of_many_spheres():
    import workbench
    scene = _spheres_scene()
    n_top = len(scene.objects) + 0  # no area lights
    st = {a: workbench.render(scene, "raycast", accel=a, traversal_stats=True, width=32, height=24).stats
          for a in ACCELS}
    assert st["none"]["accel_analytic_tests_per_ray"] == n_top  # every primitive, every ray
    assert st["none"]["accel_analytic_nodes_per_ray"] == 0.0
    for a in ("bvh", "octree"):
        assert st[a]["accel_analytic_tests_per_ray"] < 0.2 * n_top
        assert st[a]["accel_analytic_nodes_per_ray"] >= 1.0
        assert st[a]["accel_primitive_tests_per_ray"] == st[a]["accel_analytic_tests_per_ray"]  # no triangles


@pytest.mark.parametrize("name", ["sky_spheres", "cornell_spheres"])
def test_the_path_tracer_gives_the_same_image_with_every_structure(name):
    """The same seed, the same image, bit for bit, with every structure: the sky-lit spheres
    (paths bounce through the analytic primitives' trees), and cornell_spheres, whose area
    light the path tracer makes two triangles that the octree references from several cells
    each: light sampling must still pick each triangle once by its power (it once sampled
    every octree reference: the light counted 4 times, the image 2.3 times too bright)."""
    import workbench
    if name == "sky_spheres":
        scene = _spheres_scene(n=40)
        scene = replace(scene, lights=(), background=(0.8, 0.8, 0.9))  # lit by the sky: paths bounce
        size = dict(spp=2, seed=3, width=24, height=18)
    else:
        scene, size = workbench.load_scene(name), dict(spp=4, seed=1, width=24, height=18)
    res = {a: workbench.render(scene, "pathtrace", accel=a, **size) for a in ACCELS}
    img = {a: r.image for a, r in res.items()}
    assert np.ptp(img["none"]) > 0.05
    for a in ("bvh", "octree"):
        assert np.array_equal(img[a], img["none"]), (a, float(np.mean(img[a])), float(np.mean(img["none"])))
    if name == "cornell_spheres":
        st = {a: r.stats for a, r in res.items()}
        assert st["octree"]["triangle_references"] > st["octree"]["triangles"]  # repeats to get right
        assert {s["triangles"] for s in st.values()} == {st["none"]["triangle_references"]}
        assert {s["emitter_triangles"] for s in st.values()} == {2}


@pytest.mark.slow
@pytest.mark.parametrize("path", sorted(glob.glob(str(ROOT / "scenes" / "*.toml"))), ids=lambda p: Path(p).stem)
def test_every_bundled_scene_gives_the_brute_force_image_with_every_structure(path):
    import workbench
    scene = workbench.load_scene(path)
    for method in ("raycast", "raytrace", "pathtrace"):
        opts = dict(spp=4, seed=1) if method == "pathtrace" else {}
        images = {a: workbench.render(scene, method, accel=a, width=40, height=30, **opts).image for a in ACCELS}
        for a in ("bvh", "octree"):
            assert np.array_equal(images[a], images["none"]), (method, a)
