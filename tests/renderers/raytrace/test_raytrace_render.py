"""Whole renders: the numba kernels against the readable reference on every bundled scene
(small images), scale invariance, stiff cases without NaN, stats, left_out, tiles, depth,
vertex emission, the ray tree."""
from __future__ import annotations

import dataclasses
import tomllib

import numpy as np
import pytest

import workbench
from workbench.renderers.raytrace import reference, whitted
from workbench.scene import library
from workbench.scene.io import scene_from_dict

SMALL = {"whitted": (32, 24), "cornell": (10, 10), "csg": (32, 24), "quadrics": (32, 24),
         "globe": (24, 18), "bricks": (24, 18), "envmap": (24, 18), "mesh": (8, 6), "kinds": (24, 18)}


@pytest.mark.parametrize("name", sorted(SMALL))
def test_kernels_match_the_reference(name):
    """Same image from the numba kernel and the one-ray-at-a-time reference
    (except at most 2 % of pixels, where a ray grazes an edge and float rounding decides)."""
    sc = workbench.load_scene(name)
    w, h = SMALL[name]
    opts = dict(max_depth=4, threshold=1e-3, fresnel="exact" if name == "whitted" else "none")
    r = workbench.render(sc, "raytrace", width=w, height=h, **opts)
    ref = reference.render(sc, w, h, **opts)
    err = np.abs(r.image - ref).max(-1)
    assert np.mean(err > 1e-5) <= 0.02, f"{np.sum(err > 1e-5)} pixels differ, max {err.max()}"
    assert np.median(err) < 1e-6


def _reference_counts(sc, w, h, **opts):
    """Ray counts of the readable reference's ray trees (:func:`reference.ray_tree`) over the
    image: shadow feelers, reflected and refracted rays traced, rays that left the scene."""
    counts = dict(shadow_rays=0, reflected_rays=0, refracted_rays=0, escaped_rays=0)
    names = {"reflection": "reflected_rays", "refraction": "refracted_rays"}

    def walk(node):
        counts["shadow_rays"] += len(node["shadow_feelers"])
        counts["escaped_rays"] += node["object"] is None
        for child in node["children"]:
            if "ray" in child:
                if child["kind"] in names:
                    counts[names[child["kind"]]] += 1
                walk(child["ray"])
    for i in range(h):
        for j in range(w):
            walk(reference.ray_tree(sc, i, j, **opts))
    return counts


@pytest.mark.parametrize("name", ["whitted", "bricks", "envmap", "csg"])
def test_ray_counts_match_the_reference_ray_trees(name):
    """The kernel traces the rays the readable reference traces: shadow feelers, reflected and
    refracted children and escaped rays, summed over the ray trees of every pixel, and the
    depth map is the primary hits' camera-space depth."""
    w, h = 12, 9
    sc = workbench.load_scene(name)
    sc = dataclasses.replace(sc, camera=dataclasses.replace(sc.camera, width=w, height=h))
    opts = dict(max_depth=4, threshold=1e-3, fresnel="schlick")
    r = workbench.render(sc, "raytrace", width=w, height=h, **opts)
    want = _reference_counts(sc, w, h, **opts)
    for key in ("shadow_rays", "reflected_rays", "refracted_rays", "escaped_rays"):
        assert r.stats[key] == want[key], (key, r.stats[key], want[key])
    assert r.stats["primary_rays"] == w * h


def test_only_scenes_with_maps_beyond_checkers_compile_the_maps():
    """The maps' marker names ``maps`` for image textures, bump maps, opacity maps and
    environments, not for plain colours and planar or solid checkers (``whitted``: the kernel
    compiles the checker alone)."""
    from workbench.renderers.kernels.layout import marker_features
    from workbench.renderers.raytrace.maps import texture_tables
    for name, maps in (("whitted", False), ("cornell", False), ("globe", True), ("bricks", True), ("envmap", True)):
        sc = workbench.load_scene(name)
        sd = whitted.flatten(sc)
        assert ("maps" in marker_features(texture_tables(sc, sd).marker)) == maps, name
        assert (whitted.fused_textures(sc, sd) is None) == maps, name


def _scaled_whitted(s):
    d = tomllib.loads(library.resolve("whitted").read_text())
    cam = d["camera"]
    cam["position"] = [x * s for x in cam["position"]]
    cam["look_at"] = [x * s for x in cam["look_at"]]
    cam["resolution"] = [48, 36]
    for lt in d["lights"]:
        lt["position"] = [x * s for x in lt["position"]]
    for o in d["objects"]:
        for k in ("center", "point"):
            if k in o:
                o[k] = [x * s for x in o[k]]
        if "radius" in o:
            o["radius"] *= s
        if "size" in o:
            o["size"] = [x * s for x in o["size"]]
    d["materials"]["checker"]["texture"]["scale"] /= s
    return scene_from_dict(d)


def test_scale_invariance_from_1e_minus6_to_1e6():
    """The same scene at scale 1e-6, 1 and 1e6 renders the same image: no acne, no leaks."""
    imgs = [workbench.render(_scaled_whitted(s), "raytrace").image for s in (1e-6, 1.0, 1e6)]
    for img in (imgs[0], imgs[2]):
        err = np.abs(img - imgs[1]).max(-1)
        assert np.mean(err > 1e-3) < 0.01 and np.median(err) < 1e-5


def test_stiff_cases_never_give_nan():
    """Tangent and grazing rays, a tiny far sphere and a huge near one, a glass block seen at
    and beyond its critical angle, coincident CSG, shininess 0 and 1e4."""
    objs = [
        {"type": "sphere", "center": [0, 0, 5], "radius": 1.0, "material": "glass"},
        {"type": "sphere", "center": [2.0, 0, 0], "radius": 2.0, "material": "shiny"},  # tangent to the eye rays at x = 0
        {"type": "sphere", "center": [0, 1e5, 1e7], "radius": 1e-2, "material": "dull"},
        {"type": "sphere", "center": [0, -1e6 - 1.5, 0], "radius": 1e6, "material": "mirror"},
        {"type": "box", "min": [-3, -1, 3], "max": [-1.5, 1, 4], "material": "glass",
         "transform": {"rotate": [0, 41.81, 0]}},
        {"type": "csg", "op": "difference", "material": "dull",
         "left": {"type": "box", "min": [1, 1, 3], "max": [2, 2, 4]},
         "right": {"type": "box", "min": [1, 1, 3], "max": [2, 2, 4]}},
        {"type": "csg", "op": "union", "material": "shiny",
         "left": {"type": "sphere", "center": [-1, 1.5, 4], "radius": 0.5},
         "right": {"type": "sphere", "center": [-1, 1.5, 4], "radius": 0.5}},
        {"type": "plane", "point": [0, 0, 10], "normal": [0, 0, -1], "size": [30, 30], "material": "dull"},
        {"type": "plane", "point": [0, 2.5, 0], "normal": [0, 1, 0], "size": [30, 30], "material": "dull"},
    ]
    mats = {"glass": {"kt": 0.9, "kr": 0.1, "ior": 1.5, "ks": 0.5, "shininess": 1e4},
            "shiny": {"ks": 1.0, "shininess": 0.0}, "dull": {"kd": 0.8},
            "mirror": {"kr": 0.9, "kd": 0.1}}
    sc = scene_from_dict({"camera": {"position": [0, 2.5, -5], "look_at": [0, 0, 5], "resolution": [40, 30]},
                          "materials": mats, "objects": objs,
                          "lights": [{"type": "point", "position": [0, 5, -5]},
                                     {"type": "directional", "direction": [0, -1, 0]}]})
    for fresnel in ("none", "schlick", "exact"):
        r = workbench.render(sc, "raytrace", max_depth=8, fresnel=fresnel, transmissive_shadows=True)
        assert r.stats["nonfinite_pixels"] == 0 and np.isfinite(r.image).all()
        assert np.isfinite(r.depth[np.isfinite(r.depth)]).all()


def test_stats_left_out_and_skipped_paths():
    sc = workbench.load_scene("whitted")
    rc = workbench.render(sc, "raycast", width=32, height=24)
    assert rc.stats["reflected_rays"] == rc.stats["refracted_rays"] == 0
    assert rc.stats["primary_rays"] == 32 * 24 and rc.stats["shadow_rays"] > 0
    assert any(x.feature == "reflection" for x in rc.left_out)
    assert any(x.feature == "meshes" for x in rc.left_out)
    rt = workbench.render(sc, "raytrace", width=32, height=24, shadows=False)
    assert rt.stats["shadow_rays"] == 0 and rt.stats["reflected_rays"] > 0 and rt.stats["refracted_rays"] > 0
    assert any(x.feature == "shadows" for x in rt.left_out)
    assert "refraction" in rt.features_used
    cb = workbench.render(workbench.load_scene("cornell"), "raytrace", width=8, height=8)
    assert cb.stats["refracted_rays"] == 0 and cb.stats["reflected_rays"] == 0
    assert any(x.feature == "refraction" for x in cb.left_out)
    assert cb.timings["trace"] > 0 and "compile" in cb.timings and cb.stats["mrays_per_s"] > 0
    with pytest.raises(workbench.WorkbenchError):
        workbench.render(sc, "raytrace", max_depth=0)
    with pytest.raises(workbench.WorkbenchError):
        workbench.render(sc, "raytrace", fresnel="maybe")


def test_tiles_depth_and_spp():
    sc = scene_from_dict({"camera": {"position": [0, 0, -5], "look_at": [0, 0, 0], "resolution": [40, 30]},
                          "materials": {"m": {"ka": 1.0, "kd": 0.0, "color": [1, 1, 1]}},
                          "objects": [{"type": "plane", "point": [0, 0, 3], "normal": [0, 0, -1], "size": [100, 100], "material": "m"}],
                          "scene": {"ambient": [0.5, 0.25, 1.0]}})
    tiles = []
    r = workbench.render(sc, "raycast", on_tile=lambda y0, y1, x0, x1, t: tiles.append((y0, y1, x0, x1, t.copy())))
    covered = np.zeros((30, 40), bool)
    for y0, y1, x0, x1, t in tiles:
        assert np.array_equal(t, r.image[y0:y1, x0:x1])
        covered[y0:y1, x0:x1] = True
    assert covered.all()
    assert np.allclose(r.depth, 8.0)  # camera-space distance along the view axis
    assert np.allclose(r.image, [0.5, 0.25, 1.0])
    r4 = workbench.render(sc, "raycast", spp=4, seed=1)
    assert np.allclose(r4.image, r.image) and r4.stats["primary_rays"] == 4 * 40 * 30


def test_vertex_emission_is_interpolated():
    V = [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]
    E = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [1.0, 1.0, 1.0]])
    # seen from the front (+z: the triangles' counter-clockwise side); the back emits nothing
    sc = scene_from_dict({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "resolution": [5, 5], "fov_y": 10.0},
                          "materials": {"m": {"ka": 0.0, "kd": 0.0}},
                          "objects": [{"type": "mesh", "vertices": V, "faces": [[0, 1, 2], [0, 2, 3]], "material": "m"}]})
    from dataclasses import replace
    mesh = replace(sc.objects[0], vertex_emission=E)
    sc = replace(sc, objects=(mesh,))
    r = workbench.render(sc, "raycast")
    O, D = sc.camera.rays()
    t, n, obj = workbench.raytrace.intersect(sc, O.reshape(-1, 3), D.reshape(-1, 3))
    P = (O.reshape(-1, 3) + t[:, None] * D.reshape(-1, 3))
    u, v = (P[:, 0] + 1) / 2, (P[:, 1] + 1) / 2  # bilinear on a square = barycentric per triangle
    lower = u >= v
    exp = np.where(lower[:, None], (1 - u)[:, None] * E[0] + (u - v)[:, None] * E[1] + v[:, None] * E[2],
                   (1 - v)[:, None] * E[0] + (v - u)[:, None] * E[3] + u[:, None] * E[2])
    assert np.allclose(r.image.reshape(-1, 3), exp, atol=1e-6)
    assert np.allclose(reference.render(sc, 5, 5).reshape(-1, 3), exp, atol=1e-6)
    back = sc.with_camera(replace(sc.camera, position=(0.0, 0.0, -5.0)))
    assert workbench.render(back, "raycast").image.max() == 0.0
    assert reference.render(back, 5, 5).max() == 0.0


def test_ray_tree_of_a_glass_pixel():
    sc = workbench.load_scene("whitted")
    w, h = 48, 36
    sc = sc.with_camera(sc.camera.with_resolution(w, h))
    i, j = 19, 19  # on the glass sphere
    tree = workbench.raytrace.ray_tree(sc, i, j, max_depth=2)
    assert tree["object"] == 2
    glass = sc.objects[2]
    assert tree["object_name"] == (glass.name or "sphere 2") and tree["material"] == glass.material
    kinds = [c["kind"] for c in tree["children"]]
    assert kinds == ["reflection", "refraction"]
    assert len(tree["shadow_feelers"]) >= 1
    deep = tree["children"][1]["ray"]["children"]
    assert any(c.get("stop") == "max depth" for c in deep)
    r = workbench.render(sc, "raytrace", max_depth=2)
    assert np.allclose(tree["color"], r.image[i, j], atol=1e-5)
