"""Users' shading models as methods (``glsl:FILE``): the two examples against what they must
reproduce, the one-line errors (compile errors mapped to the user's file and line), options
from ``#pragma parameter``, and ``render`` / ``compare`` / ``study`` taking them by name."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import workbench
from workbench.core.errors import ShaderSourceError, WorkbenchError
from workbench.renderers.base import check_methods, file_stem, get_renderer
from workbench.renderers.user_shading import load_model, method_name

ROOT = Path(__file__).resolve().parents[2]
OREN_NAYAR = ROOT / "examples" / "shading" / "oren_nayar.glsl"
TOON = ROOT / "examples" / "shading" / "toon.glsl"

pytestmark = pytest.mark.gl

#: one white sphere lit by one directional light, no texture: the toon bands are flat colours
SPHERE = """
[scene]
name = "sphere"
description = "one sphere, one directional light"
background = [0.0, 0.0, 0.0]
ambient = [0.1, 0.1, 0.1]

[camera]
position = [0.0, 0.0, -4.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_y = 40.0
resolution = [96, 96]

[[lights]]
type = "directional"
direction = [-1.0, -1.0, 1.0]
color = [1.0, 1.0, 1.0]
intensity = 1.0

[materials.white]
color = [0.9, 0.6, 0.3]
ka = 0.3
kd = 0.7
ks = 0.4
shininess = 30.0

[[objects]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"
"""


def _cli(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "workbench", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=300)


def _one_error_line(r) -> str:
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    return lines[0]


def _no_specular(scene):
    return replace(scene, materials={k: replace(m, ks=0.0) for k, m in scene.materials.items()})


def test_oren_nayar_at_roughness_zero_is_lambert():
    """sigma = 0: A = 1, B = 0, so Oren-Nayar is kd C max(N.L, 0), the built-in local model
    with ks = 0.  Whitted's scene (checker texture, two point lights, ambient) with every ks
    set to 0.  The two shaders sum the same terms in a different order (ambient apart,
    colour x (kd C cos) against C x (colour kd cos)): float32 rounding, a few ulps of values
    below 2, so 1e-5 absolute."""
    scene = _no_specular(workbench.load_scene("whitted"))
    lambert = workbench.render(scene, "phong", width=160, height=120, standins="off").image
    on = workbench.render(scene, f"glsl:{OREN_NAYAR}", width=160, height=120, roughness=0.0).image
    assert np.abs(on - lambert).max() <= 1e-5
    # the test can fail: a rough surface is not Lambertian (A < 1 darkens, B > 0 brightens)
    rough = workbench.render(scene, f"glsl:{OREN_NAYAR}", width=160, height=120, roughness=0.5).image
    assert np.abs(rough - lambert).max() > 0.02


def test_oren_nayar_default_roughness_from_the_pragma():
    r = get_renderer(f"glsl:{OREN_NAYAR}")
    assert r.options["roughness"].default == pytest.approx(0.3)
    assert r.knob.name == "tessellation"


def test_toon_gives_few_colours_on_a_sphere(tmp_path):
    """One light, a plain material: at most bands + 1 diffuse levels, each with or without
    the highlight, so at most 2 (bands + 1) colours on the sphere; Phong gives hundreds."""
    path = tmp_path / "sphere.toml"
    path.write_text(SPHERE)
    scene = workbench.load_scene(path)
    bands = 3
    res = workbench.render(scene, f"glsl:{TOON}", width=96, height=96, bands=bands)
    on_sphere = np.isfinite(res.depth)
    assert on_sphere.sum() > 2000
    colours = np.unique(res.image[on_sphere].reshape(-1, 3), axis=0)
    assert bands <= len(colours) <= 2 * (bands + 1)
    phong = workbench.render(scene, "phong", width=96, height=96)
    assert len(np.unique(phong.image[np.isfinite(phong.depth)].reshape(-1, 3), axis=0)) > 100


def test_edited_file_is_recompiled(tmp_path):
    """The session cache keys a model by its text: an edit shows at the next render."""
    f = tmp_path / "m.glsl"
    f.write_text("vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) { return vec3(0.0); }\n")
    scene = workbench.load_scene("whitted")
    a = workbench.render(scene, f"glsl:{f}", width=32, height=24).image
    f.write_text("vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) { return vec3(0.5); }\n")
    b = workbench.render(scene, f"glsl:{f}", width=32, height=24).image
    assert np.abs(a - b).max() > 0.1


@pytest.mark.parametrize("text, line, what", [
    ("vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) {\n    float x = dot(N, L)\n    return m.color * x;\n}\n",
     3, "syntax error"),
    ("// a comment\nvec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) {\n  return no_such_name * m.color;\n}\n",
     3, "no_such_name"),
])
def test_compile_error_names_the_users_file_and_line(tmp_path, text, line, what):
    f = tmp_path / "broken.glsl"
    f.write_text(text)
    with pytest.raises(ShaderSourceError) as e:
        workbench.render(workbench.load_scene("whitted"), f"glsl:{f}", width=16, height=12)
    msg = str(e.value)
    assert msg.startswith(f"{f}:{line}: error:") and what in msg and "\n" not in msg
    out = tmp_path / "out.png"
    err = _one_error_line(_cli("render", "whitted", "-m", f"glsl:{f}", "-o", out, "--size", "16x12"))
    assert err == f"workbench: error: {msg}"
    assert not out.exists()


def test_wrong_signature_names_the_required_one(tmp_path):
    f = tmp_path / "sig.glsl"
    f.write_text("vec3 shade(vec3 P, vec3 N) { return N; }\n")
    with pytest.raises(ShaderSourceError, match=r"must be defined as vec3 shade\(vec3 P, vec3 N, vec3 V, vec3 L, Material m\)"):
        workbench.render(workbench.load_scene("whitted"), f"glsl:{f}", width=16, height=12)


@pytest.mark.parametrize("name, content, expected", [
    ("missing.glsl", None, "no such file"),
    ("folder.glsl", "DIR", "not a file"),
    ("latin1.glsl", b"\xff\xfe vec3", "not a UTF-8 text file"),
    ("nofunction.glsl", "// vec3 shade(\nvec3 other(vec3 P) { return P; }\n", "no function vec3 shade("),
    ("version.glsl", "#version 330 core\nvec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) { return N; }\n",
     ":1: no #version line"),
    ("pragma.glsl", "#pragma parameter rough\nvec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) { return N; }\n",
     ":1: expected '#pragma parameter NAME DEFAULT"),
    ("pragma2.glsl", "#pragma parameter rough abc\nvec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) { return N; }\n",
     "default 'abc' is not a number"),
    ("clash.glsl", "#pragma parameter tessellation 3\nvec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) { return N; }\n",
     "clashes with the method option"),
])
def test_unusable_file_is_one_line(tmp_path, name, content, expected):
    f = tmp_path / name
    if content == "DIR":
        f.mkdir()
    elif isinstance(content, bytes):
        f.write_bytes(content)
    elif content is not None:
        f.write_text(content)
    with pytest.raises(WorkbenchError, match=expected.replace("(", r"\(")):
        load_model(f)
    err = _one_error_line(_cli("render", "whitted", "-m", f"glsl:{f}", "-o", tmp_path / "o.png", "--size", "8x6"))
    assert expected in err and str(f) in err


def test_parameter_is_an_option(tmp_path):
    out = tmp_path / "on.png"
    r = _cli("render", "whitted", "-m", f"glsl:{OREN_NAYAR}", "--set", "roughness=0.6", "-o", out,
             "--size", "32x24", "--json", tmp_path / "on.json")
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "on.json").read_text())["options"]["roughness"] == "0.6"
    err = _one_error_line(_cli("render", "whitted", "-m", f"glsl:{OREN_NAYAR}", "--set", "rough=1",
                               "-o", out, "--size", "8x6"))
    assert "unknown option 'rough'" in err and "roughness" in err


def test_method_names_and_file_stems():
    name = method_name(TOON)
    assert name == f"glsl:{TOON.resolve()}" and file_stem(name) == "glsl_toon"
    assert file_stem("phong") == "phong"
    check_methods(["phong", name, f"glsl:{OREN_NAYAR}"])
    with pytest.raises(WorkbenchError, match=r"unknown method\(s\) nope"):
        check_methods(["phong", "nope"])
    with pytest.raises(WorkbenchError, match="would write the same files"):
        check_methods([name, f"glsl:{TOON}"])


def test_compare_and_study_take_glsl_methods(tmp_path):
    """Side by side like any built-in: compare's report lists the model with its files;
    study sweeps its knob.  (Reference phong: no numba compile in the default run.)"""
    out = tmp_path / "cmp"
    r = _cli("compare", "whitted", "--out", out, "--methods", f"phong,glsl:{TOON},glsl:{OREN_NAYAR}",
             "--size", "64x48", "--reference", "phong", "--repeat", "1")
    assert r.returncode == 0, r.stderr
    rep = json.loads((out / "report.json").read_text())
    entries = {e["method"]: e for e in rep["methods"]}
    assert entries[f"glsl:{TOON}"]["status"] == "ok"
    assert entries[f"glsl:{TOON}"]["metrics"]["rmse"] > 0.001  # toon is not Phong
    assert (out / entries[f"glsl:{TOON}"]["files"]["png"]) == out / "images" / "glsl_toon.png"
    assert (out / "images" / "glsl_oren_nayar.npy").is_file()
    st = tmp_path / "study"
    r = _cli("study", "whitted", "--out", st, "--methods", f"glsl:{TOON}", "--quick", "--size", "48x36",
             "--reference", "phong", "--repeat", "1")
    assert r.returncode == 0, r.stderr
    points = json.loads((st / "study.json").read_text())["points"]
    assert len(points) >= 2 and all(p["status"] == "ok" and p["knob"] == "tessellation" for p in points)


def test_compare_stops_on_a_compile_error(tmp_path):
    f = tmp_path / "broken.glsl"
    f.write_text("vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) {\n  return m.color\n}\n")
    out = tmp_path / "cmp"
    err = _one_error_line(_cli("compare", "whitted", "--out", out, "--methods", f"phong,glsl:{f}",
                               "--size", "32x24", "--reference", "phong", "--repeat", "1"))
    assert err.startswith(f"workbench: error: {f}:3:")
    assert not (out / "report.json").exists()


def test_bare_name_is_a_bundled_example(tmp_path, monkeypatch):
    """``glsl:toon`` works from any folder (a wheel's user has no checkout): the bundled
    example of that stem; a file of that name in the working folder wins; an unknown bare name
    lists the examples."""
    monkeypatch.chdir(tmp_path)
    assert load_model("toon").path == str(TOON.resolve())
    assert load_model("oren_nayar.glsl").path == str(OREN_NAYAR.resolve())
    own = tmp_path / "toon.glsl"
    own.write_text("vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) { return N; }\n")
    assert load_model("toon.glsl").path == str(own.resolve())
    with pytest.raises(WorkbenchError, match=r"'nope': no such file \(bundled examples: oren_nayar, toon\)"):
        load_model("nope")
    with pytest.raises(WorkbenchError, match=r"no such file$"):
        load_model("sub/nope.glsl")


def test_methods_lists_the_user_form_and_the_examples():
    out = subprocess.run([sys.executable, "-m", "workbench", "methods"], capture_output=True, text=True, check=True).stdout
    assert "glsl:FILE" in out
    assert f"glsl:toon = {TOON.resolve()}" in out and f"glsl:oren_nayar = {OREN_NAYAR.resolve()}" in out
