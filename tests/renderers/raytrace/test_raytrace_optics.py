"""Geometric optics of the ray tracer: Snell-Descartes, critical angle, lateral offset through a
slab, Fresnel, furnaces (mirror and dielectric), Beer-Lambert, nested media, shadow feelers,
and the local model against the numpy reference."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.renderers import local_model
from workbench.renderers.raytrace import reference
from workbench.scene.io import scene_from_dict
from workbench.scene.media import enclosing_media


def make(objects, materials, lights=(), camera=None, **scene_kw):
    d = {"scene": dict(scene_kw), "camera": camera or {"position": [0, 0, -10], "look_at": [0, 0, 0], "resolution": [16, 12]},
         "materials": materials, "lights": list(lights), "objects": objects}
    return scene_from_dict(d)


# --------------------------------------------------------------------------- Snell, TIR
@pytest.mark.parametrize("n", [1.0, 2.0, 20.0, 60.0, 200.0, 300.0, 1023.0, 1024.0, 37.5, 2000.0])
def test_highlight_power_without_pow(n):
    """The kernels' Phong power ``optics._pow`` (by squaring for an integer exponent up to 1024,
    0 where ``n (1 - b)`` says the power is negligible) is ``b ** n`` within a few ulps, and where
    it answers 0 the power is below 1.1e-20."""
    from workbench.core.jit_options import python_twin
    from workbench.renderers.kernels.optics import _pow as kernel_pow
    _pow = python_twin(kernel_pow)
    b = np.concatenate([np.linspace(0.0, 1.0, 1001), [1.0 - 1e-12, 0.5 ** 0.5, 1e-300]])
    got = np.array([_pow(x, n) for x in b])
    want = b ** n
    cut = (got == 0.0) & (want > 0.0)
    assert (want[cut] < 1.1e-20).all()
    assert np.allclose(got[~cut], want[~cut], rtol=1e-13, atol=0.0)


@pytest.mark.parametrize("deg", [0.0, 10.0, 30.0, 41.0, 41.8, 60.0, 89.0])
def test_snell_descartes_and_critical_angle(deg):
    """n_i sin(i) = n_t sin(t), T in the plane of incidence, unit; from glass (1.5) to air the
    critical angle is asin(1/1.5) = 41.81 deg: beyond it, total internal reflection."""
    th = np.radians(deg)
    N = np.array([0.0, 0.0, -1.0])  # on the incident side
    D = np.array([np.sin(th), 0.0, np.cos(th)])
    T, cosi, cost = reference.refraction(D, N, 1.0, 1.5)  # entering glass: always refracts
    assert np.sin(th) == pytest.approx(1.5 * np.linalg.norm(np.cross(T, -N)), abs=1e-12)
    assert np.linalg.norm(T) == pytest.approx(1.0) and abs(T[1]) < 1e-15
    T, cosi, cost = reference.refraction(D, N, 1.5, 1.0)
    crit = np.degrees(np.arcsin(1 / 1.5))
    assert crit == pytest.approx(41.81, abs=5e-3)
    if deg < crit:
        assert T is not None and 1.5 * np.sin(th) == pytest.approx(np.linalg.norm(np.cross(T, -N)), abs=1e-12)
    else:
        assert T is None


def test_exactly_at_the_critical_angle_is_reflection_not_nan():
    th = np.arcsin(1 / 1.5)
    D = np.array([np.sin(th), 0.0, np.cos(th)])
    T, cosi, cost = reference.refraction(D, np.array([0.0, 0.0, -1.0]), 1.5, 1.0)
    assert T is None or (np.isfinite(T).all() and abs(T[2]) < 1e-6)


@pytest.mark.parametrize("mode", ["schlick", "exact"])
def test_fresnel_limits(mode):
    assert reference.fresnel(mode, 1.0, 1.5, 1.0, 1.0) == pytest.approx(0.04)
    cos_t = np.sqrt(1 - (1 / 1.5) ** 2 * (1 - 1e-8))
    assert reference.fresnel(mode, 1.0, 1.5, 1e-4, cos_t) == pytest.approx(1.0, abs=2e-3)
    if mode == "exact":  # Brewster: rp = 0 -> F = rs^2 / 2
        b = np.arctan(1.5)
        ci, ct = np.cos(b), np.sqrt(1 - (np.sin(b) / 1.5) ** 2)
        rs = (ci - 1.5 * ct) / (ci + 1.5 * ct)
        assert reference.fresnel(mode, 1.0, 1.5, ci, ct) == pytest.approx(rs * rs / 2)


@pytest.mark.parametrize("deg", [20.0, 50.0])
def test_lateral_offset_through_a_glass_slab(deg):
    """A slab of thickness e: the ray leaves parallel to itself, shifted by
    e sin(i - t) / cos(t) (ray tree of the centre pixel, reference tracer)."""
    e = 0.4
    slab = {"type": "box", "min": [-3, -3, -e / 2], "max": [3, 3, e / 2], "material": "glass",
            "transform": {"rotate": [0, deg, 0]}}
    sc = make([slab], {"glass": {"kt": 1.0, "ior": 1.5, "ka": 0.0, "kd": 0.0}},
              camera={"position": [0, 0, -10], "look_at": [0, 0, 0], "resolution": [3, 3]})
    tree = workbench.raytrace.ray_tree(sc, 1, 1, max_depth=4, threshold=0.0)
    D0 = np.array(tree["direction"])
    inside = tree["children"][0]["ray"]
    out = inside["children"][-1]["ray"]
    D2 = np.array(out["direction"])
    assert D2 == pytest.approx(D0, abs=1e-12)
    i = np.radians(deg)
    t = np.arcsin(np.sin(i) / 1.5)
    P0, P2 = np.array(tree["origin"]), np.array(out["origin"])
    w = P2 - P0
    shift = np.linalg.norm(w - (w @ D0) * D0)
    # up to the secondary rays' origin offsets (tol.offset_scale: 1e-7 x the scene extent)
    assert shift == pytest.approx(e * np.sin(i - t) / np.cos(t), abs=1e-5)


# --------------------------------------------------------------------------- furnaces
@pytest.mark.parametrize("kr,threshold,expected_terms", [(1.0, 0.0, 6), (0.5, 0.0, 6), (0.5, 0.1, 4)])
def test_mirror_furnace(kr, threshold, expected_terms):
    """Inside an emitting mirror sphere (emission E, reflectance kr) every pixel sees
    E (1 + kr + ... + kr^(n-1)): n = max_depth, or fewer when kr^k falls to the threshold."""
    E = 0.2
    sc = make([{"type": "sphere", "radius": 5.0, "material": "mirror"}],
              {"mirror": {"kr": kr, "ka": 0.0, "kd": 0.0, "emission": [E, E, E]}},
              camera={"position": [0, 0.5, 0.3], "look_at": [1, 0, 2], "resolution": [12, 9]})
    r = workbench.render(sc, "raytrace", max_depth=6, threshold=threshold)
    expected = E * sum(kr ** k for k in range(expected_terms))
    assert np.allclose(r.image, expected, rtol=1e-6)
    assert r.stats["escaped_rays"] == 0
    n = 12 * 9
    if threshold == 0.0:
        assert r.stats["ended_by_depth"] == n and r.stats["reflected_rays"] == 5 * n
    else:
        assert r.stats["ended_by_threshold"] == n and r.stats["ended_by_depth"] == 0


@pytest.mark.parametrize("shape,fresnel", [("sphere", "exact"), ("sphere", "schlick"), ("box", "none"), ("box", "exact")])
def test_dielectric_in_a_white_furnace_conserves_energy(shape, fresnel):
    """A lossless dielectric (kt = 1, nothing absorbed) under a uniform white background looks
    white: Fresnel splits energy between reflection and transmission, and total internal
    reflection sends it all to reflection (never a made-up colour)."""
    obj = ({"type": "sphere", "radius": 1.0} if shape == "sphere" else
           {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1], "transform": {"rotate": [30, 40, 0]}})
    sc = make([dict(obj, material="glass")], {"glass": {"kt": 1.0, "ior": 1.5, "ka": 0.0, "kd": 0.0}},
              camera={"position": [0, 0, -4], "look_at": [0, 0, 0], "resolution": [24, 24]},
              background=[1.0, 1.0, 1.0])
    r = workbench.render(sc, "raytrace", max_depth=40, threshold=1e-9, fresnel=fresnel)
    assert r.stats["refracted_rays"] > 0
    if shape == "box":
        assert r.stats["total_internal_reflections"] > 0
    lost = 1.0 - r.image
    assert lost.min() > -1e-9
    assert np.mean(lost) < 1e-3


def test_beer_lambert_absorption():
    a, e = 0.7, 0.5
    sc = make([{"type": "box", "min": [-2, -2, 0], "max": [2, 2, e], "material": "tinted"}],
              {"tinted": {"kt": 1.0, "ior": 1.0, "ka": 0.0, "kd": 0.0, "absorption": [a, 2 * a, 0.0]}},
              camera={"position": [0, 0, -5], "look_at": [0, 0, 0], "resolution": [1, 1]},
              background=[1.0, 1.0, 1.0])
    r = workbench.render(sc, "raytrace")
    assert r.image[0, 0] == pytest.approx([np.exp(-a * e), np.exp(-2 * a * e), 1.0], rel=1e-6)


def test_nested_media_use_the_ratio_of_their_indices():
    """A ball of water inside a ball of water is invisible (eta = 1.33 / 1.33 at its surface);
    an air bubble inside is not."""
    def render(inner_ior):
        objs = [{"type": "plane", "point": [0, 0, 4], "normal": [0, 0, -1], "size": [20, 20], "material": "board"},
                {"type": "sphere", "radius": 2.0, "material": "water"}]
        if inner_ior:
            objs.append({"type": "sphere", "radius": 1.0, "center": [0.2, 0.1, 0], "material": "inner"})
        sc = make(objs, {"board": {"texture": {"type": "checker", "projection": "planar", "pole": [0, 0, 1], "scale": 2.0}},
                         "water": {"kt": 1.0, "ior": 1.33, "ka": 0.0, "kd": 0.0},
                         "inner": {"kt": 1.0, "ior": inner_ior or 1.0, "ka": 0.0, "kd": 0.0}},
                  lights=[{"type": "directional", "direction": [0, 0, 1]}],
                  camera={"position": [0, 0, -8], "look_at": [0, 0, 0], "resolution": [32, 32]})
        return workbench.render(sc, "raytrace", max_depth=8).image
    alone = render(None)
    assert np.allclose(render(1.33), alone, atol=1e-6)
    assert np.abs(render(1.0) - alone).max() > 0.1


@pytest.mark.parametrize("transmissive", [False, True])
def test_shadow_feelers_and_transmissive_occluders(transmissive):
    objs = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [20, 20], "material": "floor"},
            {"type": "plane", "point": [0, 2, 0], "normal": [0, 1, 0], "size": [2, 2], "material": "sheet"}]
    sc = make(objs, {"floor": {"ka": 0.0, "kd": 1.0, "color": [1, 1, 1]},
                     "sheet": {"ka": 0.0, "kd": 0.0, "kt": 0.5}},
              lights=[{"type": "point", "position": [0, 10, 0]}],
              camera={"position": [0, 1, -6], "look_at": [0, 0, 0], "resolution": [1, 1]})
    P = np.array([[0.0, 0.0, 0.0]])
    r = workbench.render(sc, "raycast", transmissive_shadows=transmissive)
    # the single pixel sees the floor's centre (not the sheet), which is in the sheet's shadow
    t, n, obj = workbench.raytrace.intersect(sc, np.array([[0, 1, -6.0]]), np.array([[0, -1, 6.0]]))
    assert obj[0] == 0
    lit = local_model.shade(P, np.array([[0, 1.0, 0]]), np.array([[0, 1, -6.0]]) / np.sqrt(37),
                            np.ones(3), sc.materials["floor"], sc.point_lights(), sc.ambient)
    assert r.image[0, 0] == pytest.approx(lit[0] * (0.5 if transmissive else 0.0), rel=1e-6, abs=1e-9)
    assert r.stats["shadow_rays"] == 1


@pytest.mark.parametrize("shininess,blinn", [(0.0, False), (20.0, False), (20.0, True), (1e4, False)])
def test_raycast_equals_the_local_model(shininess, blinn):
    """The kernel's local model is local_model.shade at the hit points (two lights, one with
    inverse-square falloff, ambient, two-sided)."""
    sc = make([{"type": "sphere", "radius": 1.5, "material": "m"}],
              {"m": {"color": [0.9, 0.5, 0.2], "ka": 0.3, "kd": 0.7, "ks": 0.5, "shininess": shininess}},
              lights=[{"type": "point", "position": [3, 4, -5], "intensity": 0.8},
                      {"type": "point", "position": [-3, 1, -2], "intensity": 9.0, "falloff": "inverse_square"}],
              camera={"position": [0, 0, -6], "look_at": [0, 0, 0], "resolution": [24, 18]},
              ambient=[0.2, 0.2, 0.2])
    r = workbench.render(sc, "raycast", blinn=blinn)
    O, D = sc.camera.rays()
    t, n, obj = workbench.raytrace.intersect(sc, O.reshape(-1, 3), D.reshape(-1, 3))
    hit = obj >= 0
    P = O.reshape(-1, 3)[hit] + t[hit, None] * D.reshape(-1, 3)[hit]
    ref = local_model.shade(P, n[hit], -D.reshape(-1, 3)[hit], np.array([0.9, 0.5, 0.2]), sc.materials["m"],
                            sc.point_lights(), sc.ambient, blinn=blinn)
    assert np.allclose(r.image.reshape(-1, 3)[hit], ref, atol=2e-6)
    assert np.allclose(r.image.reshape(-1, 3)[~hit], 0.0)


# --------------------------------------------------------------------------- opacity and shadows
def _occluded_floor(opacity, kt=0.0):
    """A floor lit by a slanted directional light and a point light, with a square occluder
    out of the camera's view whose shadows fall in the picture; ``opacity``: the occluder's
    opacity map (None: opaque), or the string "none" for no occluder; ``kt`` its
    transmission."""
    mats = {"floor": {"color": [0.8, 0.8, 0.8], "ka": 0.2, "kd": 0.8},
            "occ": {"color": [0.5, 0.2, 0.1], "kt": kt} | ({} if opacity in (None, "none") else {"opacity": opacity})}
    objects = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [6, 6], "material": "floor"}]
    if opacity != "none":
        objects.append({"type": "plane", "point": [-2, 2, 0], "normal": [0, 1, 0], "size": [1.2, 1.2],
                        "material": "occ"})
    return make(objects, mats, lights=[{"type": "directional", "direction": [1, -1, 0]},
                                       {"type": "point", "position": [-3.5, 4.0, 1.0], "intensity": 0.7}],
                camera={"position": [0, 3, 0.5], "look_at": [0, 0, 0], "fov_y": 40, "resolution": [24, 18]},
                ambient=[0.3, 0.3, 0.3])


@pytest.mark.parametrize("method", ["raycast", "raytrace"])
def test_shadow_of_an_opacity_mapped_surface_lets_one_minus_alpha_through(method):
    """A shadow feeler crossing a surface of opacity alpha carries 1 - alpha of the light (as
    the ray it blends with the surface behind); a cut-out (alpha < 0.5) casts no shadow; a grid
    map casts the grid's shadow: lit under its holes, dark under its bars."""
    render = lambda op: workbench.render(_occluded_floor(op), method).image  # noqa: E731
    lit, dark = render("none"), render(None)
    shadow = np.abs(lit - dark).max(-1) > 1e-3
    assert 0.05 < shadow.mean() < 0.6  # the shadow is in the picture, not all of it
    blend = render({"type": "constant", "value": 0.6})
    assert np.allclose(blend, dark + 0.4 * (lit - dark), atol=1e-9)
    assert np.allclose(render({"type": "constant", "value": 0.3}), lit, atol=1e-12)
    grid = render({"type": "grid", "projection": "planar", "scale": 2.0, "width": 0.3,
                   "pole": [0, 1, 0], "equator": [1, 0, 0]})
    under_hole = np.isclose(grid, lit, atol=1e-9).all(-1) & shadow
    under_bar = np.isclose(grid, dark, atol=1e-9).all(-1) & shadow
    assert under_hole.sum() > 5 and under_bar.sum() > 5
    assert (under_hole | under_bar)[shadow].mean() > 0.9  # pixels straddling an edge aside
    # with transmissive shadows the covered part also lets kt through: 1 - 0.6 + 0.6 x 0.5
    half = {"type": "constant", "value": 0.6}
    trans = workbench.render(_occluded_floor(half, kt=0.5), method, transmissive_shadows=True).image
    assert np.allclose(trans, dark + 0.7 * (lit - dark), atol=1e-6)
    # the numba kernel against the readable reference
    depth = 1 if method == "raycast" else 5
    assert np.allclose(blend, reference.render(_occluded_floor(half), 24, 18, max_depth=depth), atol=1e-6)
    ref = reference.render(_occluded_floor(half, kt=0.5), 24, 18, max_depth=depth, transmissive_shadows=True)
    assert np.allclose(trans, ref, atol=1e-6)


# --------------------------------------------------------------------------- camera inside a medium
CAM_IN_GLASS = np.array([0.8, 0.3, -0.2])


def _camera_in_glass(ior, absorption, sphere=True):
    """The camera off the centre of a glass sphere of radius 2 (no local shading, all
    transmitted) looking at a white wall outside it."""
    mats = {"glass": {"color": [1, 1, 1], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kt": 1.0, "ior": ior,
                      "absorption": [absorption, 0.5 * absorption, 0.0]},
            "wall": {"color": [0.9, 0.9, 0.9], "ka": 0.3, "kd": 0.7}}
    objects = [{"type": "plane", "point": [0, 0, 5], "normal": [0, 0, -1], "size": [40, 40], "material": "wall"}]
    if sphere:
        objects.append({"type": "sphere", "center": [0, 0, 0], "radius": 2.0, "material": "glass"})
    return make(objects, mats, lights=[{"type": "point", "position": [0, 3, 0.5], "intensity": 1.0}],
                camera={"position": CAM_IN_GLASS.tolist(), "look_at": [0.8, 0.3, 1], "fov_y": 50,
                        "resolution": [16, 12]}, ambient=[0.2, 0.2, 0.2])


def test_a_camera_inside_an_absorbing_medium_sees_through_it():
    """Primary rays start inside the solids that enclose the camera: Beer-Lambert applies from
    the camera: a ray crossing d of glass keeps exp(-a d) of the wall's radiance), and with the
    same index as air the wall is seen unbent."""
    opts = dict(max_depth=5, threshold=0.0, shadows=False)
    sc = _camera_in_glass(1.0, 0.3)
    bare = workbench.render(_camera_in_glass(1.0, 0.3, sphere=False), "raytrace", **opts).image
    inside = workbench.render(sc, "raytrace", **opts).image
    _, D = sc.camera.rays()
    cd = D @ CAM_IN_GLASS
    d = -cd + np.sqrt(cd ** 2 - CAM_IN_GLASS @ CAM_IN_GLASS + 4.0)  # to the sphere, radius 2
    expected = bare * np.exp(-np.array([0.3, 0.15, 0.0]) * d[..., None])
    assert np.allclose(inside, expected, rtol=1e-5, atol=1e-7)  # float32 images
    assert [m.name for m in enclosing_media(sc, CAM_IN_GLASS)] == ["glass"]
    assert enclosing_media(sc, [0, 0, 3]) == []


def test_camera_inside_refracting_glass_equals_the_reference():
    """Leaving the glass the ray bends from n = 1.5 to 1 (total internal reflection beyond the
    critical angle), as in the readable reference."""
    sc = _camera_in_glass(1.5, 0.2)
    opts = dict(max_depth=4, threshold=0.0)
    img = workbench.render(sc, "raytrace", **opts).image
    ref = reference.render(sc, 16, 12, **opts)
    assert np.allclose(img, ref, atol=1e-6)
    flat = workbench.render(_camera_in_glass(1.0, 0.2), "raytrace", **opts).image
    assert np.abs(img - flat).max() > 1e-3  # the index matters


def test_enclosing_media_by_point_in_solid():
    """The solids around a point, by inside tests: nested spheres outermost first, a CSG shell
    (glass ball minus an opaque core) only in its glass, a closed glass mesh by its winding
    number, an open glass pane never (a pane crossed by some ray must not fill the view with
    glass), nothing on a surface."""
    from workbench.scene.generate import generate_mesh
    g = lambda kt=1.0: {"color": [1, 1, 1], "kt": kt, "ior": 1.5}  # noqa: E731
    mats = {f"g{i}": g() for i in range(1, 6)} | {"opaque": g(0.0)}
    names = lambda sc, p: [mt.name for mt in enclosing_media(sc, p)]  # noqa: E731
    nested = make([{"type": "sphere", "center": [0, 0, 0], "radius": r, "material": f"g{r}"} for r in (3, 1, 5, 2, 4)], mats)
    assert names(nested, [0.1, 0.2, 0.0]) == ["g5", "g4", "g3", "g2", "g1"]
    assert names(nested, [0.0, 2.5, 0.0]) == ["g5", "g4", "g3"]
    assert names(nested, [0.0, 2.0, 0.0]) == ["g5", "g4", "g3"]  # on the radius-2 sphere: outside it
    shell = make([{"type": "csg", "op": "difference", "material": "g1",
                   "left": {"type": "sphere", "radius": 3, "material": "g1"},
                   "right": {"type": "sphere", "radius": 1, "material": "opaque"}}], mats)
    for p in ([2, 0, 0], [-2, 0, 0], [0, 0, -2.5]):
        assert names(shell, p) == ["g1"]
    assert names(shell, [0.5, 0, 0]) == [] and names(shell, [4, 0, 0]) == []
    blob = generate_mesh("blob", subdivisions=2)
    closed = make([{"type": "mesh", "vertices": np.asarray(blob.vertices).tolist(),
                    "faces": np.asarray(blob.faces).tolist(), "material": "g2",
                    "transform": {"translate": [1.0, 0.0, 0.0]}}], mats)
    assert names(closed, [1.1, 0.1, 0.0]) == ["g2"] and names(closed, [3.0, 0.0, 0.0]) == []
    pane = make([{"type": "mesh", "vertices": [[-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]],
                  "faces": [[0, 1, 2], [0, 2, 3]], "material": "g3"}], mats)
    assert names(pane, [0.0, 0.0, 0.0]) == [] and names(pane, [0.0, 0.0, 2.0]) == []
