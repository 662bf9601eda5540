"""Scene files: every bundled scene loads; every kind of bad input gets one clear message."""
from __future__ import annotations

import copy
import textwrap

import numpy as np
import pytest

from workbench.scene import library
from workbench.scene.io import SceneError, load_scene, scene_from_dict
from workbench.scene.features import scene_needs

BASE = {
    "scene": {"name": "t"},
    "camera": {"position": [0, 0, -5], "look_at": [0, 0, 0]},
    "lights": [{"type": "point", "position": [0, 5, -5]}],
    "materials": {"m": {"color": [1, 0, 0]}},
    "objects": [{"type": "sphere", "radius": 1.0, "material": "m"}],
}


def _with(path, value):
    d = copy.deepcopy(BASE)
    t = d
    for k in path[:-1]:
        t = t[k]
    t[path[-1]] = value
    return d


@pytest.mark.parametrize("path", library.bundled(), ids=lambda p: p.stem)
def test_bundled_scene_loads_with_header(path):
    s = load_scene(path)
    assert s.objects and scene_needs(s)
    assert len(library.header(path)) > 40, "each bundled scene says what it demonstrates"


def test_minimal_scene_is_built():
    s = scene_from_dict(BASE)
    assert s.objects[0].radius == 1.0 and s.materials["m"].color == (1.0, 0.0, 0.0)
    assert {"spheres", "point_lights"} <= scene_needs(s)


@pytest.mark.parametrize("data, key, expect", [
    (_with(["materials", "m", "kdd"], 0.5), "[materials.m].kdd", "unknown key"),
    (_with(["objects", 0, "radius"], "big"), ".radius", "expected a number"),
    (_with(["objects", 0, "radius"], -1.0), ".radius", "> 0"),
    (_with(["objects", 0, "material"], "gold"), ".material", "unknown material 'gold'"),
    (_with(["camera", "up"], [0, 0, 0]), "[camera].up", "non-zero vector"),
    (_with(["lights", 0, "position"], [1, 2]), ".position", "list of 3"),
    (_with(["materials", "m", "ks"], 1.5), "[materials.m].ks", "<= 1"),
    (_with(["objects", 0], {"type": "quadric", "material": "m", "Q": [[1, 2, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, -1]],
                            "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]}}), ".Q", "not symmetric"),
    (_with(["objects", 0], {"type": "quadric", "material": "m", "shape": "cylinder"}), ".bounds", "unbounded"),
    (_with(["objects", 0], {"type": "mesh", "material": "m", "path": "nowhere.obj"}), ".path", "file not found"),
    (_with(["objects", 0], {"type": "polygon", "material": "m", "vertices": [[0, 0, 0], [1, 0, 0], [2, 0, 0]]}), ".vertices", "zero area"),
    (_with(["objects", 0], {"type": "box", "material": "m", "min": [0, 0, 0], "max": [1, 0, 1]}), ".max", "must exceed"),
    (_with(["objects", 0, "type"], "torus"), ".type", "expected one of"),
    (_with(["objects", 0, "transform"], {"scale": 0}), ".transform.scale", "non-zero"),
    (_with(["camera", "look_at"], [0, 0, -5]), "[camera].look_at", "zero-length"),
    (_with(["objects", 0], {"type": "csg", "op": "union", "material": "m",
                            "left": {"type": "sphere", "radius": 1},
                            "right": {"type": "plane", "normal": [0, 1, 0], "size": [1, 1]}}), ".right.type", "no inside"),
])
def test_bad_input_names_key_and_expectation(data, key, expect):
    with pytest.raises(SceneError) as e:
        scene_from_dict(data, source="bad.toml")
    msg = str(e.value)
    assert msg.startswith("bad.toml: ") and key in msg and expect in msg, msg


def test_file_errors_name_the_file(tmp_path):
    p = tmp_path / "broken.toml"
    p.write_text("[camera\nposition = 1")
    with pytest.raises(SceneError, match="broken.toml: not valid TOML"):
        load_scene(p)
    with pytest.raises(SceneError, match="no such scene file"):
        load_scene(tmp_path / "absent.toml")


def test_mesh_from_obj_file_and_relative_path(tmp_path):
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n")
    (tmp_path / "s.toml").write_text(textwrap.dedent("""
        [camera]
        position = [0, 0, -5]
        look_at = [0, 0, 0]
        [materials.m]
        [[objects]]
        type = "mesh"
        material = "m"
        path = "tri.obj"
    """))
    s = load_scene(tmp_path / "s.toml")
    assert s.objects[0].faces.shape == (2, 3) and "meshes" in scene_needs(s)


def test_nothing_half_loaded_scene_is_immutable():
    s = scene_from_dict(BASE)
    with pytest.raises(Exception):
        s.objects[0].world_from_object[0, 0] = 2.0
    with pytest.raises(Exception):
        s.name = "x"


def test_needs_follow_materials_and_lights():
    d = _with(["materials", "m"], {"kr": 0.5, "kt": 0.5, "ior": 1.5, "texture": {"type": "checker", "projection": "planar"}})
    f = scene_needs(scene_from_dict(d))
    assert {"reflection", "refraction", "textures"} <= f and "bump" not in f and "emitters" not in f
    d = _with(["lights"], [])
    assert "shadows" not in scene_needs(scene_from_dict(d))


def test_area_light_stand_ins_carry_its_power():
    s = load_scene("cornell")
    light = s.lights[0]
    stand = s.point_lights()
    assert len(stand) == light.stand_in ** 2
    total = sum(p.intensity for p in stand)
    assert total == pytest.approx(light.intensity * light.area / np.pi)
    assert np.allclose(light.normal, [0, -1, 0])


@pytest.mark.parametrize("data, key, expect", [
    (_with(["objects", 0, "radius"], 1e39), "[[objects]] #1.radius", "outside the float32 range"),
    (_with(["lights", 0, "position"], [0, -1e39, 0]), "[[lights]] #1.position[1]", "float32 range"),
    (_with(["materials", "m", "emission"], [0, 0, 4e38]), "[materials.m].emission[2]", "float32 range"),
    (_with(["objects", 0, "transform"], {"matrix": [[1e39, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}),
     "[[objects]] #1.transform.matrix[0][0]", "float32 range"),
    (_with(["objects", 0, "radius"], float("nan")), "[[objects]] #1.radius", "finite"),
    (_with(["objects", 0, "radius"], 2 ** 64), "[[objects]] #1.radius", "too large"),
    (_with(["camera", "resolution"], [2 ** 64, 10]), "[camera].resolution[0]", "too large"),
    (_with(["objects", 0, "tessellation"], -(2 ** 70)), "[[objects]] #1.tessellation", "too large"),
    (_with(["objects", 0], {"type": "mesh", "material": "m", "generate": {"kind": "blob", "seed": 2 ** 40}}),
     ".generate.seed", "<= 4294967295"),
    (_with(["materials", "m", "kr"], 0.5) | {"materials": {"m": {"kr": 0.5, "kt": 0.6}}}, "[materials.m].kt",
     "kr + kt = 0.5 + 0.6 = 1.1 > 1"),
])
def test_values_that_would_fail_later_are_refused_at_load(data, key, expect):
    """Float32 range for what the GPU sees, integer sizes, kr + kt <= 1 (DESIGN erratum 9)."""
    with pytest.raises(SceneError) as e:
        scene_from_dict(data, source="bad.toml")
    msg = str(e.value)
    assert msg.startswith("bad.toml: ") and key in msg and expect in msg, msg


def test_kr_plus_kt_equal_to_one_is_accepted():
    s = scene_from_dict(_with(["materials", "m"], {"kr": 0.25, "kt": 0.75}))
    assert s.materials["m"].kr + s.materials["m"].kt == 1.0


def test_huge_integer_in_a_file_is_one_line(tmp_path):
    p = tmp_path / "big.toml"
    p.write_text("[camera]\nposition = [0, 0, -5]\nlook_at = [0, 0, 0]\nresolution = [18446744073709551616, 2]\n"
                 "[[objects]]\ntype = \"sphere\"\nradius = 1\n")
    with pytest.raises(SceneError, match=r"big.toml: \[camera\].resolution\[0\]: integer 18446744073709551616 is too large"):
        load_scene(p)


@pytest.mark.parametrize("table", ["texture", "bump", "opacity", "environment"])
def test_image_maps_must_be_readable_images_at_load(table, tmp_path):
    bad = tmp_path / "notes.png"
    bad.write_text("this is not an image")
    trunc = tmp_path / "trunc.png"
    from PIL import Image
    Image.new("RGB", (64, 64), (200, 10, 10)).save(trunc)
    trunc.write_bytes(trunc.read_bytes()[:60])
    for path in (bad, trunc):
        spec = {"type": "image", "path": str(path)}
        if table == "environment":
            data = copy.deepcopy(BASE) | {"environment": spec}
            key = "[environment].path"
        else:
            data = _with(["materials", "m", table], spec | {"projection": "spherical"})
            key = f"[materials.m].{table}.path"
        with pytest.raises(SceneError) as e:
            scene_from_dict(data, source="bad.toml")
        assert key in str(e.value) and "not a readable image" in str(e.value), str(e.value)


def test_mesh_file_vertices_must_fit_float32(tmp_path):
    (tmp_path / "huge.obj").write_text("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n")
    data = _with(["objects", 0], {"type": "mesh", "material": "m", "path": str(tmp_path / "huge.obj")})
    with pytest.raises(SceneError, match="outside the float32 range"):
        scene_from_dict(data, source="bad.toml")
