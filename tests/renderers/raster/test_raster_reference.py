"""GLSL against the numpy references (local model and texturing) at a few pixels, and the GL
projection against Camera.project."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.core.transform import normalize
from workbench.renderers import local_model as lm
from workbench.renderers import texturing as tx
from workbench.scene.io import scene_from_dict

W, H = 64, 48
# float32 in the shader vs float64 in numpy: relative agreement expected
RTOL = 2e-3


def _plane_scene(material: dict, lights=None, environment=None, camera=None):
    d = {
        "scene": {"ambient": [0.2, 0.25, 0.3], "background": [0.0, 0.0, 0.0]},
        "camera": camera or {"position": [0.4, 0.3, 4.0], "look_at": [0.0, 0.0, 0.0], "fov_y": 50.0,
                             "resolution": [W, H]},
        "lights": lights or [
            {"type": "point", "position": [1.0, 2.0, 3.0], "intensity": 6.0, "falloff": "inverse_square"},
            {"type": "directional", "direction": [-0.3, -0.2, -1.0], "color": [0.9, 0.8, 0.7], "intensity": 0.6},
            {"type": "point", "position": [-2.0, -1.0, 2.0], "color": [0.2, 0.4, 1.0], "intensity": 0.5},
        ],
        "materials": {"m": material},
        "objects": [{"type": "plane", "material": "m", "point": [0, 0, 0], "normal": [0, 0, 1],
                     "size": [6.0, 6.0], "u_axis": [1, 0, 0]}],
    }
    if environment:
        d["environment"] = environment
    return scene_from_dict(d)


def _expected(scene, pixels, blinn=False):
    """numpy: ray through each pixel centre hits z = 0; texture, bump, local model."""
    o, d = scene.camera.rays()
    o, d = o[tuple(pixels.T)], d[tuple(pixels.T)]
    P = o - (o[:, 2] / d[:, 2])[:, None] * d
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    mat = next(iter(scene.materials.values()))
    C = tx.surface_color(mat, P, N)
    Nb = tx.bump_normal(mat, P, N, N, np.eye(4))
    S = normalize(np.asarray(scene.camera.position) - P)
    out = lm.shade(P, Nb, S, C, mat, scene.point_lights(), scene.ambient, blinn=blinn)
    if mat.environment:
        Nf = np.where((np.sum(Nb * S, -1) < 0)[:, None], -Nb, Nb)
        R = 2 * np.sum(Nf * S, -1)[:, None] * Nf - S
        out = out + mat.kr * tx.environment(scene.environment, R)
    return out


PIXELS = np.array([[5, 7], [20, 30], [24, 32], [40, 10], [33, 55], [12, 50]])

MATERIALS = {
    "plain": {"color": [0.8, 0.6, 0.4], "ka": 0.3, "kd": 0.7, "ks": 0.5, "shininess": 12.0},
    "shininess0": {"color": [0.5, 0.5, 0.5], "ka": 0.1, "kd": 0.5, "ks": 0.2, "shininess": 0.0},
    "marble": {"color": [1, 1, 1], "ks": 0.3, "shininess": 30.0,
               "texture": {"type": "marble", "projection": "solid", "scale": 1.3,
                           "colors": [[0.9, 0.9, 0.85], [0.2, 0.25, 0.4]]}},
    "wood_spherical": {"ks": 0.2, "texture": {"type": "wood", "projection": "spherical", "scale": 2.0,
                                              "center": [0.1, 0.2, -1.0], "colors": [[0.8, 0.5, 0.2], [0.4, 0.2, 0.1]]}},
    "waves_bump": {"ks": 0.6, "shininess": 40.0,
                   "bump": {"type": "waves", "projection": "planar", "pole": [0, 0, 1], "scale": 0.7, "strength": 0.3}},
    "noise_bump_cyl": {"ks": 0.4, "bump": {"type": "noise", "projection": "cylindrical", "pole": [0, 1, 0],
                                           "equator": [0, 0, 1], "center": [0, 0, -2], "scale": 3.0, "strength": 0.2},
                       "texture": {"type": "marble", "projection": "cylindrical", "pole": [0, 1, 0],
                                   "equator": [0, 0, 1], "center": [0, 0, -2]}},
    "env_sky": {"ks": 0.3, "kr": 0.6, "environment": True},
}


@pytest.mark.parametrize("name", list(MATERIALS))
@pytest.mark.parametrize("blinn", [False, True])
def test_phong_glsl_equals_numpy_reference(gl_ctx, name, blinn):
    env = {"type": "sky", "zenith": [0.1, 0.2, 0.9], "horizon": [0.9, 0.9, 0.8]} if "env" in name else None
    scene = _plane_scene(MATERIALS[name], environment=env)
    r = workbench.render(scene, "phong", blinn=blinn)
    got = r.image[tuple(PIXELS.T)]
    want = _expected(scene, PIXELS, blinn)
    assert np.allclose(got, want, rtol=RTOL, atol=RTOL * np.abs(want).max()), (got, want)


@pytest.mark.parametrize("blinn", [False, True])
@pytest.mark.parametrize("method", ["phong", "gouraud"])
def test_area_light_stand_ins_match_numpy_reference(gl_ctx, blinn, method):
    """Each light kind is compiled in separately (raster_shaders.light_list): area-light
    stand-ins (inverse square and emitter lobe) beside a directional and an unattenuated point
    light.  Phong per pixel; Gouraud (vertex colours of a fine grid, interpolated) loosely."""
    # the emitter out of the camera's view (its polygon would hide the pixels), facing -z
    lights = [{"type": "area", "vertices": [[2.5, -0.5, 1.5], [2.5, 0.5, 1.5], [3.5, 0.5, 1.5], [3.5, -0.5, 1.5]],
               "color": [8.0, 7.0, 6.0], "intensity": 1.0, "stand_in": 2},
              {"type": "directional", "direction": [-0.3, -0.2, -1.0], "intensity": 0.4},
              {"type": "point", "position": [-2.0, -1.0, 2.0], "color": [0.2, 0.4, 1.0], "intensity": 0.5}]
    scene = _plane_scene(MATERIALS["plain"], lights=lights)
    assert sum(getattr(lt, "cosine_normal", None) is not None for lt in scene.point_lights()) == 4
    r = workbench.render(scene, method, blinn=blinn, tessellation=16)
    got = r.image[tuple(PIXELS.T)]
    want = _expected(scene, PIXELS, blinn)
    if method == "phong":
        assert np.allclose(got, want, rtol=RTOL, atol=RTOL * np.abs(want).max()), (got, want)
    else:  # interpolated vertex colours of a fine grid: close to the per-pixel model
        assert np.allclose(got, want, rtol=0.1, atol=0.05 * np.abs(want).max()), (got, want)


def test_material_no_light_changes_compiles_no_light_terms(gl_ctx):
    """kd = ks = 0: no light term is compiled; the image is E + ka C Ia exactly as numpy."""
    from workbench.renderers.raster_shaders import material_defines
    mat = {"color": [0.8, 0.6, 0.4], "ka": 0.5, "kd": 0.0, "ks": 0.0, "emission": [0.1, 0.0, 0.05]}
    scene = _plane_scene(mat)
    kw = dict(n_lights=3, has_uv=False, blinn=False, depth_bits=24, allow_bump=True)
    assert "FOR_EACH_LIGHT(X)" not in material_defines(scene, scene.materials["m"], "phong", **kw)
    lit = _plane_scene({**mat, "kd": 0.5})
    assert material_defines(lit, lit.materials["m"], "phong", **kw)["FOR_EACH_LIGHT(X)"].count("X(") == 3
    r = workbench.render(scene, "phong")
    want = _expected(scene, PIXELS)
    assert np.allclose(r.image[tuple(PIXELS.T)], want, rtol=RTOL)


def test_flat_is_the_local_model_at_the_polygon_centroid(gl_ctx):
    scene = _plane_scene(MATERIALS["plain"])
    r = workbench.render(scene, "flat")
    P = np.zeros((1, 3))  # the plane's centroid
    N = np.array([[0.0, 0.0, 1.0]])
    S = normalize(np.asarray(scene.camera.position) - P)
    mat = scene.materials["m"]
    want = lm.shade(P, N, S, np.asarray(mat.color), mat, scene.point_lights(), scene.ambient)[0]
    img = r.image[r.depth < np.inf]
    assert np.allclose(img, want, rtol=RTOL), "flat shading must give one colour per polygon"


def test_gouraud_equals_reference_at_vertices_of_a_plane(gl_ctx):
    """Gouraud interpolates vertex colours; on a plane with a directional light only (constant
    N.L) and no specular it equals the local model everywhere."""
    lights = [{"type": "directional", "direction": [-0.3, -0.2, -1.0], "intensity": 0.8}]
    scene = _plane_scene({"color": [0.3, 0.6, 0.9], "ka": 0.2, "kd": 0.7}, lights=lights)
    r = workbench.render(scene, "gouraud")
    assert np.allclose(r.image[tuple(PIXELS.T)], _expected(scene, PIXELS), rtol=RTOL)


def test_light_behind_surface_gives_ambient_only(gl_ctx):
    lights = [{"type": "point", "position": [0.0, 0.0, -3.0], "intensity": 5.0}]
    scene = _plane_scene(MATERIALS["plain"], lights=lights)
    for method in ("flat", "gouraud", "phong"):
        r = workbench.render(scene, method)
        ambient = 0.3 * np.array([0.8, 0.6, 0.4]) * np.array([0.2, 0.25, 0.3])
        assert np.allclose(r.image[r.depth < np.inf], ambient, rtol=RTOL), method


def test_gl_projection_matches_camera_project(gl_ctx):
    """A small emissive square around a point lands where Camera.project puts the point."""
    cam = {"position": [1.0, 2.0, 6.0], "look_at": [0.0, 0.5, 0.0], "fov_y": 40.0, "resolution": [80, 60]}
    centre = np.array([0.7, 0.9, 0.3])
    half = 0.05
    verts = [(centre + half * np.array(o)).tolist() for o in [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]]
    d = {"camera": cam, "materials": {"e": {"color": [0, 0, 0], "ka": 0, "kd": 0, "emission": [1, 1, 1]}},
         "objects": [{"type": "polygon", "material": "e", "vertices": verts}]}
    scene = scene_from_dict(d)
    r = workbench.render(scene, "flat")
    lit = r.image[..., 0] > 0.5
    assert lit.sum() >= 4
    rows, cols = np.nonzero(lit)
    xy, depth = scene.camera.project(centre[None])
    # pixel (i, j) covers [j, j+1) x [i, i+1): its centre is (j + 0.5, i + 0.5)
    assert abs(cols.mean() + 0.5 - xy[0, 0]) < 0.5 and abs(rows.mean() + 0.5 - xy[0, 1]) < 0.5
    finite = r.depth[lit]
    assert np.allclose(finite, depth[0], rtol=1e-2)  # the square spans +-0.05 in depth


def test_image_texture_and_image_environment_match_numpy(gl_ctx):
    from workbench.scene.library import SCENES_DIR
    earth = str(SCENES_DIR / "assets" / "earth_latlong.png")
    sky = str(SCENES_DIR / "assets" / "sky_latlong.png")
    mat = {"ks": 0.2, "kr": 0.4, "environment": True,
           "texture": {"type": "image", "path": earth, "projection": "planar", "pole": [0, 0, 1], "scale": 0.3}}
    scene = _plane_scene(mat, environment={"type": "image", "path": sky})
    r = workbench.render(scene, "phong")
    got = r.image[tuple(PIXELS.T)]
    want = _expected(scene, PIXELS)
    # GL_LINEAR on llvmpipe weights texels with 8-bit fractions: about 1 % of a texel step
    assert np.allclose(got, want, rtol=2e-2, atol=2e-2 * np.abs(want).max()), (got, want)


def test_opacity_grid_cut_out_matches_numpy_alpha(gl_ctx):
    mat = {"color": [1, 1, 1], "ka": 1.0, "kd": 0.0,
           "opacity": {"type": "grid", "projection": "planar", "pole": [0, 0, 1], "scale": 2.0, "width": 0.3}}
    scene = _plane_scene(mat)
    r = workbench.render(scene, "phong")
    o, d = scene.camera.rays()
    P = (o - (o[..., 2] / d[..., 2])[..., None] * d).reshape(-1, 3)
    a = tx.alpha(scene.materials["m"], P, None).reshape(H, W)
    drawn = r.depth < np.inf
    # away from the grid lines' edges (a pixel's footprint), GL keeps exactly the alpha >= 0.5 part
    s = P[:, :2].reshape(H, W, 2) * 2.0
    f = s - np.floor(s)
    edge = (np.abs(f - 0.3) < 0.05) | (f < 0.05) | (f > 0.95)
    clear = ~edge.any(-1)
    assert clear.sum() > 500
    assert np.array_equal(drawn[clear], (a >= 0.5)[clear])


def test_mesh_uvs_drive_uv_projection(gl_ctx):
    """A quad mesh with uvs = affine function of position: the GLSL's interpolated uvs (and the
    uv-projected bump, constant along object offsets) agree with numpy given the same uvs."""
    from dataclasses import replace as dc_replace
    scene = _plane_scene({"ks": 0.3, "texture": {"type": "checker", "projection": "uv", "scale": 3.0,
                                                  "colors": [[0.9, 0.8, 0.1], [0.1, 0.3, 0.8]]}})
    V = np.array([[-3.0, -3.0, 0.0], [3.0, -3.0, 0.0], [3.0, 3.0, 0.0], [-3.0, 3.0, 0.0]])
    uv_of = lambda P: (P[:, :2] + 3.0) / 6.0
    from workbench.scene.model import Mesh
    mesh = Mesh("m", vertices=V, faces=np.array([[0, 1, 2], [0, 2, 3]]), normals=np.tile([0.0, 0.0, 1.0], (4, 1)),
                uvs=uv_of(V))
    scene = dc_replace(scene, objects=(mesh,))
    r = workbench.render(scene, "phong")
    o, d = scene.camera.rays()
    P = (o - (o[..., 2] / d[..., 2])[..., None] * d).reshape(-1, 3)
    mat = scene.materials["m"]
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    C = tx.surface_color(mat, P, N, uv_of(P))
    S = normalize(np.asarray(scene.camera.position) - P)
    want = lm.shade(P, N, S, C, mat, scene.point_lights(), scene.ambient).reshape(H, W, 3)
    s = uv_of(P).reshape(H, W, 2) * 3.0
    f = s - np.floor(s)
    clear = ((f > 0.05) & (f < 0.95)).all(-1)  # away from checker edges
    assert clear.sum() > 500
    assert np.allclose(r.image[clear], want[clear], rtol=RTOL, atol=RTOL)


@pytest.mark.parametrize("level, drawn", [(140, True), (110, False)])
def test_opacity_image_is_read_as_data_not_srgb(gl_ctx, tmp_path, level, drawn):
    # a uniform opaque grey opacity map: its luminance is the opacity, level / 255 (0.55 kept and
    # blended over the black background, 0.43 cut out at the 0.5 threshold); decoded as sRGB, 140
    # would be 0.26 and cut out too
    from PIL import Image
    path = str(tmp_path / "grey.png")
    Image.fromarray(np.full((4, 4, 3), level, dtype=np.uint8)).save(path)
    mat = {"color": [1, 1, 1], "ka": 1.0, "kd": 0.0,
           "opacity": {"type": "image", "path": path, "projection": "planar", "pole": [0, 0, 1]}}
    scene = _plane_scene(mat)
    r = workbench.render(scene, "phong")
    seen = np.median(r.image.reshape(-1, 3), 0)  # the plane fills most of the frame
    want = np.asarray(scene.ambient) * (level / 255 if drawn else 0.0)
    assert np.allclose(seen, want, atol=2e-3), (seen, want)
