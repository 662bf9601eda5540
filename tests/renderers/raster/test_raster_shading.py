"""The course's comparisons, measured: Phong converges to the analytic local model as the
tessellation grows; Gouraud misses a sharp highlight Phong catches; extreme inputs stay finite."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.renderers import local_model as lm
from workbench.scene.io import scene_from_dict

W, H = 96, 72


def _sphere_scene(shininess=60.0, ks=0.6, light=(2.0, 3.0, 4.0), extra=None):
    d = {"scene": {"ambient": [0.1, 0.1, 0.1]},
         "camera": {"position": [0.0, 0.0, 4.0], "look_at": [0.0, 0.0, 0.0], "fov_y": 40.0, "resolution": [W, H]},
         "lights": [{"type": "point", "position": list(light), "intensity": 1.0}],
         "materials": {"m": {"color": [0.8, 0.3, 0.2], "ka": 0.2, "kd": 0.6, "ks": ks, "shininess": shininess}},
         "objects": [{"type": "sphere", "material": "m", "center": [0.1, -0.05, 0.0], "radius": 1.0}]}
    if extra:
        d["objects"] += extra
    return scene_from_dict(d)


def _analytic(scene):
    """Ray-cast sphere + local model at each pixel centre; mask of hits."""
    o, d = scene.camera.rays()
    s = scene.objects[0]
    c = np.asarray(s.center)
    oc = o - c
    b = np.sum(d * oc, -1)
    disc = b * b - (np.sum(oc * oc, -1) - s.radius ** 2)
    hit = disc > 0
    t = -b - np.sqrt(np.maximum(disc, 0))
    P = o + t[..., None] * d
    N = (P - c) / s.radius
    mat = scene.materials["m"]
    img = lm.shade(P.reshape(-1, 3), N.reshape(-1, 3), -d.reshape(-1, 3), np.asarray(mat.color), mat,
                   scene.point_lights(), scene.ambient).reshape(H, W, 3)
    return img, hit


def test_phong_converges_to_the_analytic_model(gl_ctx):
    scene = _sphere_scene()
    ref, hit = _analytic(scene)
    # compare inside the silhouette, one pixel away from it (coverage differs at the edge)
    inner = hit.copy()
    for ax in (0, 1):
        for sh in (1, -1):
            inner &= np.roll(hit, sh, axis=ax)
    errors = []
    for level in (1, 2, 4, 8):
        img = workbench.render(scene, "phong", tessellation=level).image
        errors.append(float(np.sqrt(np.mean((img[inner] - ref[inner]) ** 2))))
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 0.1 * errors[0], errors
    assert errors[-1] < 5e-3, errors


def test_gouraud_misses_a_sharp_highlight_that_phong_catches(gl_ctx):
    scene = _sphere_scene(shininess=400.0, ks=0.8, light=(1.3, 1.7, 4.0))
    ref, hit = _analytic(scene)
    spec_ref = ref[hit].max()
    phong = workbench.render(scene, "phong", tessellation=2).image
    gouraud = workbench.render(scene, "gouraud", tessellation=2).image
    diffuse_peak = np.max(_analytic(_sphere_scene(ks=0.0, light=(1.3, 1.7, 4.0)))[0])
    # Phong reaches the highlight's peak; Gouraud's interpolated vertex colours fall far short
    assert phong.max() > diffuse_peak + 0.8 * (spec_ref - diffuse_peak)
    assert gouraud.max() < diffuse_peak + 0.5 * (spec_ref - diffuse_peak)


@pytest.mark.parametrize("shininess", [0.0, 1e4])
@pytest.mark.parametrize("method", ["flat", "gouraud", "phong"])
def test_extreme_shininess_is_finite_and_matches_reference(gl_ctx, shininess, method):
    scene = _sphere_scene(shininess=shininess, ks=0.5)
    r = workbench.render(scene, method, tessellation=4)
    assert r.stats["nonfinite_pixels"] == 0 and np.isfinite(r.image).all()
    if method == "phong":
        ref, hit = _analytic(scene)
        inner = hit & np.roll(hit, 2, 0) & np.roll(hit, -2, 0) & np.roll(hit, 2, 1) & np.roll(hit, -2, 1)
        # shininess 0: x^0 = 1 wherever N.L > 0 (no black speckles where R.S = 0)
        assert np.median(np.abs(r.image[inner] - ref[inner])) < 0.02


def _mesh_scene(vertices, faces, normals_from_faces=False):
    d = {"camera": {"position": [0.0, 0.0, 3.0], "look_at": [0.0, 0.0, 0.0], "resolution": [48, 36]},
         "lights": [{"type": "point", "position": [1.0, 1.0, 3.0]}],
         "materials": {"m": {"ks": 0.5}},
         "objects": [{"type": "mesh", "material": "m", "vertices": vertices, "faces": faces}]}
    return scene_from_dict(d)


def test_cancelling_normals_fall_back_to_the_face_normal(gl_ctx):
    """Two vertices of a triangle with opposite normals: the interpolated normal passes through
    zero; the fragment uses the face normal instead of a NaN."""
    from dataclasses import replace
    scene = _mesh_scene([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], [[0, 1, 2]])
    mesh = scene.objects[0]
    normals = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    scene = replace(scene, objects=(replace(mesh, normals=normals),))
    for method in ("gouraud", "phong"):
        r = workbench.render(scene, method)
        assert r.stats["nonfinite_pixels"] == 0
        drawn = r.depth < np.inf
        assert drawn.sum() > 50
        # on the column where the normal cancels (x = 0) the surface is still lit, not black
        assert r.image[drawn].min() > 0.0


def test_degenerate_triangles_are_harmless(gl_ctx):
    verts = [[-1, -1, 0], [1, -1, 0], [0, 1, 0], [0.5, 0.5, 0], [0.5, 0.5, 0], [2, 2, 0]]
    faces = [[0, 1, 2], [3, 4, 5], [3, 3, 3], [0, 1, 0]]
    scene = _mesh_scene(verts, faces)
    for method in ("flat", "gouraud", "phong"):
        r = workbench.render(scene, method)
        assert r.stats["nonfinite_pixels"] == 0
        assert (r.depth < np.inf).sum() > 50


@pytest.mark.parametrize("view", ["pole", "seam"])
def test_spherical_texture_pole_and_seam_have_no_speckles(gl_ctx, view):
    """Looking straight at a pole, or at the seam (u = 0 = 1): every sphere pixel is lit and
    textured (no NaN, no black speckles)."""
    eye = [0.0, 4.0, 0.0] if view == "pole" else [-4.0, 0.0, 0.0]  # seam: -Se side (u = 0)
    d = {"scene": {"ambient": [0.3, 0.3, 0.3]},
         "camera": {"position": eye, "look_at": [0, 0, 0], "up": [0, 0, 1] if view == "pole" else [0, 1, 0],
                    "fov_y": 40.0, "resolution": [W, H]},
         "lights": [{"type": "point", "position": [e * 2 for e in eye]}],
         "materials": {"m": {"ka": 0.5, "kd": 0.5, "ks": 0.3, "texture": {
             "type": "checker", "projection": "spherical", "scale": 8.0,
             "colors": [[0.9, 0.2, 0.2], [0.2, 0.2, 0.9]]}}},
         "objects": [{"type": "sphere", "material": "m", "radius": 1.0}]}
    scene = scene_from_dict(d)
    for method in ("flat", "gouraud", "phong"):
        r = workbench.render(scene, method)
        assert r.stats["nonfinite_pixels"] == 0
        on = r.depth < np.inf
        # darkest possible lit texel: ambient 0.5 * 0.3 * 0.2
        assert r.image[on].max(-1).min() > 0.5 * 0.3 * 0.2 * 0.99, method
        # both checker colours show (the projection is not collapsed to one texel)
        red = on & (r.image[..., 0] > 1.5 * r.image[..., 2])
        blue = on & (r.image[..., 2] > 1.5 * r.image[..., 0])
        assert red.sum() > 0.2 * on.sum() and blue.sum() > 0.2 * on.sum(), method


def test_area_light_is_drawn_with_its_radiance(gl_ctx):
    """Cornell: the emitter is a polygon of radiance color * intensity = (17, 12, 4) in every
    mode (emission adds; the local model's other terms are zero for it)."""
    scene = workbench.load_scene("cornell")
    light = scene.lights[0]
    xy, _ = scene.camera.with_resolution(64, 64).project(light.vertices.mean(0)[None])
    j, i = int(xy[0, 0]), int(xy[0, 1])
    for method in ("flat", "gouraud", "phong"):
        img = workbench.render(scene, method, width=64, height=64).image
        assert np.allclose(img[i, j], light.radiance, rtol=1e-5), method
