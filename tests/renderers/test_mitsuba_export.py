"""The Mitsuba exporter as data (no Mitsuba needed): material lobes sum to the workbench's
coefficients, lights carry the workbench's radiometry, the camera frame, PLY files, left_out."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

import workbench
from workbench.core.errors import NotApplicable
from workbench.renderers import mitsuba_export as mx
from workbench.scene import model as m


def _leaves(bsdf: dict, w: float = 1.0):
    """(effective weight x strength, leaf type) of every lobe of a (nested) exported BSDF."""
    t = bsdf["type"]
    if t == "blendbsdf":
        return _leaves(bsdf["bsdf_0"], w * (1.0 - bsdf["weight"])) + _leaves(bsdf["bsdf_1"], w * bsdf["weight"])
    if t == "twosided":
        return _leaves(bsdf["bsdf"], w)
    if t == "mask":
        return _leaves(bsdf["bsdf"], w * bsdf["opacity"])
    if t == "diffuse":
        return [(w * np.asarray(bsdf["reflectance"]["value"]), "diffuse")]
    if t == "conductor":
        assert bsdf["material"] == "none"
        return [(w * np.full(3, bsdf["specular_reflectance"]), "conductor")]
    assert bsdf["specular_reflectance"] == bsdf["specular_transmittance"]
    return [(w * np.full(3, bsdf["specular_reflectance"]), t)]


@pytest.mark.parametrize("kd,kr,kt", [(0.7, 0.0, 0.0), (0.6, 0.3, 0.0), (0.0, 0.9, 0.0), (0.0, 0.08, 0.9),
                                      (0.2, 0.1, 0.6), (0.0, 0.0, 0.5)])
def test_material_lobes_sum_to_the_workbench_coefficients(kd, kr, kt):
    mat = m.Material("x", color=(0.9, 0.5, 0.25), kd=kd, kr=kr, kt=kt, ior=1.5)
    got = {t: v for v, t in _leaves(mx.material_bsdf(mat))}
    want = {}
    if kd > 0:
        want["diffuse"] = kd * np.array([0.9, 0.5, 0.25])
    if kr > 0:
        want["conductor"] = np.full(3, kr)
    if kt > 0:
        want["dielectric"] = np.full(3, kt)
    assert sorted(got) == sorted(want)
    for k in want:
        assert np.allclose(got[k], want[k], rtol=1e-12, atol=0.0), k


def test_open_surfaces_get_a_thin_dielectric_and_constant_opacity_a_mask():
    mat = m.Material("x", kd=0.0, kt=0.5, ior=1.3, opacity=m.Opacity("constant", value=0.75))
    b = mx.material_bsdf(mat, open_surface=True)
    assert b["type"] == "mask" and b["opacity"] == 0.75 and b["bsdf"]["type"] == "thindielectric"
    assert b["bsdf"]["int_ior"] == 1.3 and b["bsdf"]["ext_ior"] == 1.0


def _small_scene(**kw) -> m.Scene:
    cam = m.Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, 0.0), fov_y=40.0, width=32, height=24)
    mats = {"white": m.Material("white", color=(1.0, 1.0, 1.0), kd=0.5)}
    objs = (m.Sphere("white", center=(0.5, 0.2, 0.0), radius=0.4, name="ball"),)
    args = dict(name="t", camera=cam, materials=mats, objects=objs, lights=(m.PointLight((0.0, 3.0, 3.0),
                intensity=2.0, falloff="inverse_square"),), ambient=(0.0, 0.0, 0.0))
    args.update(kw)
    return m.Scene(**args)


def test_point_and_directional_lights_carry_pi_times_the_workbench_intensity(tmp_path):
    """Local model: L = kd C I cos (no 1/pi); Mitsuba's Lambert BRDF is kd C / pi."""
    s = _small_scene(lights=(m.PointLight((0.0, 3.0, 3.0), color=(1.0, 0.5, 0.25), intensity=2.0,
                                          falloff="inverse_square"),
                             m.DirectionalLight((0.0, -1.0, 0.0), intensity=0.5)))
    d = mx.export_scene(s, str(tmp_path), 4).scene_dict
    assert np.allclose(d["light_000"]["intensity"]["value"], np.pi * 2.0 * np.array([1.0, 0.5, 0.25]))
    assert np.allclose(d["light_001"]["irradiance"]["value"], np.pi * 0.5)
    assert d["light_001"]["direction"] == [0.0, -1.0, 0.0]


def test_unattenuated_point_light_matches_at_the_scene_centre_and_says_so(tmp_path):
    s = _small_scene(lights=(m.PointLight((0.5, 3.2, 0.0), intensity=1.0, falloff="none"),))
    ex = mx.export_scene(s, str(tmp_path), 4)
    r0 = 3.0  # light to the sphere's centre (the bounds' centre)
    assert np.allclose(ex.scene_dict["light_000"]["intensity"]["value"], np.pi * r0 * r0)
    assert any(str(x).startswith("point_lights: falloff 'none'") for x in ex.left_out)


def test_area_light_exports_its_radiance_on_a_front_facing_black_polygon(tmp_path):
    v = np.array([[-1.0, 2.0, -1.0], [1.0, 2.0, -1.0], [1.0, 2.0, 1.0], [-1.0, 2.0, 1.0]])
    light = m.AreaLight(v, color=(2.0, 1.0, 0.5), intensity=3.0)
    assert np.allclose(light.normal, [0.0, -1.0, 0.0])  # faces down, into the scene
    s = _small_scene(lights=(light,))
    ex = mx.export_scene(s, str(tmp_path), 4)
    lamps = [sh for sh in ex.scene_dict.values() if isinstance(sh, dict) and "emitter" in sh]
    assert len(lamps) == 1
    assert np.allclose(lamps[0]["emitter"]["radiance"]["value"], [6.0, 3.0, 1.5])
    assert lamps[0]["bsdf"]["reflectance"]["value"] == [0.0, 0.0, 0.0]
    mesh = trimesh.load(lamps[0]["filename"], process=False)
    assert np.allclose(mesh.face_normals, [0.0, -1.0, 0.0])  # faces the area light's own normal
    assert np.isclose(mesh.area, 4.0)


def test_ply_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    P = rng.normal(size=(7, 3))
    Fc = np.array([[0, 1, 2], [2, 3, 4], [4, 5, 6]])
    N = rng.normal(size=(7, 3))
    mx.write_ply(str(tmp_path / "a.ply"), P, Fc, N)
    mesh = trimesh.load(str(tmp_path / "a.ply"), process=False)
    assert np.allclose(mesh.vertices, P, atol=1e-6) and (mesh.faces == Fc).all()


def test_spheres_are_analytic_and_non_uniformly_scaled_ones_tessellated(tmp_path):
    M = np.diag([1.0, 2.0, 1.0, 1.0])
    s = _small_scene(objects=(m.Sphere("white", center=(0.5, 0.2, 0.0), radius=0.4),
                              m.Sphere("white", world_from_object=M, radius=0.3)))
    ex = mx.export_scene(s, str(tmp_path), 4)
    kinds = [v["type"] for k, v in ex.scene_dict.items() if k.startswith("shape_")]
    assert kinds == ["sphere", "ply"]
    T = np.array(ex.scene_dict["shape_00000"]["to_world"])
    assert np.allclose(T @ [1.0, 0.0, 0.0, 1.0], [0.9, 0.2, 0.0, 1.0])  # unit sphere -> radius 0.4 at centre
    assert ex.triangles > 0


def test_camera_frame_is_mitsubas_looking_down_plus_z_with_x_to_the_left():
    cam = m.Camera(position=(1.0, 2.0, 3.0), look_at=(1.0, 2.0, 0.0), fov_y=40.0)
    T = mx.camera_to_world(cam)
    assert np.allclose(T[:3, 3], [1.0, 2.0, 3.0])
    assert np.allclose(T[:3, 2], [0.0, 0.0, -1.0])   # +z = viewing direction
    assert np.allclose(T[:3, 1], [0.0, 1.0, 0.0])    # +y = up
    right = np.cross(T[:3, 2], T[:3, 1])              # the image's right in world space
    assert np.allclose(T[:3, 0], -right)             # +x = image left


def test_a_scene_without_light_is_not_applicable(tmp_path):
    with pytest.raises(NotApplicable, match="no light"):
        mx.export_scene(_small_scene(lights=()), str(tmp_path), 4)
    lit_by_sky = _small_scene(lights=(), background=(0.2, 0.3, 0.5))
    d = mx.export_scene(lit_by_sky, str(tmp_path), 4)
    assert d.scene_dict["background"]["radiance"]["value"] == [0.2, 0.3, 0.5]
    with pytest.raises(NotApplicable, match="no light"):
        mx.export_scene(lit_by_sky, str(tmp_path), 4, background_light=False)


@pytest.mark.parametrize("name,expected", [
    ("globe", ["textures:"]), ("bricks", ["bump:", "textures:"]),
    ("whitted", ["specular:", "ambient:", "background:"]), ("envmap", ["environment:", "opacity:"]),
    ("cornell", []), ("cornell_spheres", ["refraction: exact Fresnel"])])
def test_left_out_lists_what_is_dropped(tmp_path, name, expected):
    ex = mx.export_scene(workbench.load_scene(name), str(tmp_path), 2)
    for prefix in expected:
        assert any(str(x).startswith(prefix) for x in ex.left_out), (prefix, ex.left_out)
    if not expected:
        assert ex.left_out == []


def test_memory_estimate_covers_the_triangles_of_the_new_kinds(tmp_path):
    # marching cubes grow with the surface, not as a sphere's rings: the old per-object guess
    # (2 (8 L)^2 4 triangles) held 33k at level 4 where the export writes 66k
    from workbench.renderers import mitsuba_method as mm
    from workbench.renderers.base import get_renderer
    scene = workbench.load_scene("kinds")
    ex = mx.export_scene(scene, str(tmp_path), 4)
    est = get_renderer("mitsuba").estimate_bytes(scene, 16, 12, tessellation=4)
    assert est >= mm.CHILD_BASE_BYTES + mm.BYTES_PER_PIXEL * 16 * 12 + mm.BYTES_PER_TRIANGLE * ex.triangles
    assert any(str(x).startswith("blobs: no blob primitive") for x in ex.left_out)
    assert {"isosurfaces", "lathes"} <= {x.feature for x in ex.left_out}
