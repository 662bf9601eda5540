"""Furs (Kajiya-Kay texels) in the raster methods as layered shells (``raster_fur``) and in
their CPU twin, the Z-buffer (``zbuffer_fur``): the GLSL hash is the numpy one, the two
agree, the shells converge to the ray caster's march as their number grows, bad options are
one line and exit 2, and no image has a NaN."""
from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

import workbench
from workbench.core.errors import WorkbenchError
from workbench.core.noise import _hash3
from workbench.renderers import gl
from workbench.renderers.base import get_renderer
from workbench.renderers.raster_shaders import INCLUDE_DIR
from workbench.renderers.support import Status
from workbench.scene import features as ft

TWIN = {"interpolation": "screen", "standins": "off"}
"""The GL options whose images the Z-buffer twins: the bare local model (no shadow maps),
the base's varyings linear in screen space (the shells are perspective-correct in both)."""


def _fur_alone(base: str = "sphere"):
    """The bundled fur scene without its floor (nothing shadows the fur: the march's feelers
    all see the light, as the raster's shells assume); ``base = "box"``: a box base."""
    s = workbench.load_scene("fur")
    objs = [o for o in s.objects if o.kind == "fur"]
    if base == "box":
        objs = [replace(o, base="box", size=(0.45, 0.35, 0.4)) for o in objs]
    return replace(s, objects=type(s.objects)(objs))


def test_glsl_hash_is_the_numpy_hash(gl_ctx):
    """``shaders/include/hash.glsl`` (the value noise's and the fur roots' lattice hash) against
    :func:`workbench.core.noise._hash3` on a 32 x 32 grid of lattice points, negative and
    large coordinates included: equal to the last bit (h >> 8 over 2^24 is exact in float32)."""
    ctx = gl_ctx
    frag = ("#version 330 core\n" + (INCLUDE_DIR / "hash.glsl").read_text() + """
out vec4 colour;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy) - 16;
    colour = vec4(hash3(ivec3(p.x, p.y, 7)), hash3(ivec3(p.x * 1000003, -p.y, p.x + 1013)),
                  hash3(ivec3(p.y, 2027, -p.x * 77777)), 1.0);
}
""")
    vert = """#version 330 core
void main() { gl_Position = vec4(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0, 0.0, 1.0); }
"""
    prog = ctx.program(vertex_shader=vert, fragment_shader=frag)
    tex = ctx.texture((32, 32), 4, dtype="f4")
    fbo = ctx.framebuffer([tex])
    vao = ctx.vertex_array(prog, [])
    try:
        fbo.use()
        vao.render(vertices=3)
        got = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype=np.float32).reshape(32, 32, 4)
    finally:
        gl.release_framebuffer(fbo)  # not left bound (gl.release_framebuffer's docstring)
        for o in (vao, tex, prog):
            o.release()
    y, x = np.mgrid[0:32, 0:32] - 16
    want = np.stack([_hash3(x, y, np.full_like(x, 7)), _hash3(x * 1000003, -y, x + 1013),
                     _hash3(y, np.full_like(x, 2027), -x * 77777)], -1)
    assert np.array_equal(got[..., :3].astype(np.float64), want)


@pytest.mark.parametrize("base", ["sphere", "box"])
def test_gl_shells_and_cpu_twin_agree(base, gl_ctx):
    """Phong (GL, float32) and the Z-buffer (numpy, float64) on the fur alone at 48x36, 8
    shells.  They can differ where a fragment's point lies within float32 rounding of a strand's
    edge or a lattice cell's boundary (D flips between 0 and 1), and where GL and the scan give
    a pixel centre on a triangle edge to different triangles.  Measured: RMSE 1.3e-7 (sphere),
    1.6e-7 (box), no pixel off by 1e-3; at 160x120 the box had one pixel in 19200 off by 0.26.
    Bounds: RMSE 5e-3, at most 1 % of the pixels off by more than 0.02."""
    s = _fur_alone(base)
    a = workbench.render(s, "phong", width=48, height=36, shells=8, **TWIN)
    b = workbench.render(s, "zbuffer", width=48, height=36, shading="phong", shells=8)
    assert a.stats["shells"] == 8 and b.stats["shells"] == 8
    assert a.stats["nonfinite_pixels"] == 0 and b.stats["nonfinite_pixels"] == 0
    d = np.abs(a.image.astype(np.float64) - b.image).max(-1)
    assert math.sqrt(float((d ** 2).mean())) < 5e-3
    assert (d > 0.02).mean() < 0.01
    hair = np.abs(b.image - workbench.render(s, "zbuffer", width=48, height=36, shading="phong",
                                             shells=1).image).max(-1)
    assert (hair > 0.02).mean() > 0.05  # the shells are drawn (8 layers differ from one)


@pytest.mark.slow
def test_shells_converge_to_the_ray_march(gl_ctx):
    """Phong with N shells against the ray caster (march step a quarter of the fur's: its own
    error 2e-3 RMSE against a 16x finer step) on the fur alone (no floor: the march's feelers
    all see the light, so vis = 1 as in the raster), 64x48: the RMSE falls as N grows.
    Measured here (64x48): N = 1, 4, 16, 64, 256: 0.083, 0.060, 0.038, 0.022, 0.011; at
    96x72, N = 1024: 0.007.  What is left at large N sits on the silhouette (grazing
    rays: one sample per layer where the ray runs far through it, so the layers alias along the
    ray once length / N times tan(angle) exceeds a strand's width) and the polygonal base.
    Slow: the ray caster's fur kernels compile in about 30 s when the cache is cold (1 s warm)."""
    s = _fur_alone()
    ref = workbench.render(s, "raycast", width=64, height=48, step_scale=0.25).image.astype(np.float64)
    errors = []
    for n in (4, 16, 64):
        img = workbench.render(s, "phong", width=64, height=48, shells=n, standins="off", tessellation=12).image
        errors.append(math.sqrt(float(((img - ref) ** 2).mean())))
    assert all(b < 0.85 * a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 0.03, errors


def test_console_script_exits_0(tmp_path):
    """The README's command for the fur: ``workbench render fur -m phong --set shells=8``."""
    p = subprocess.run([sys.executable, "-m", "workbench", "render", "fur", "-m", "phong", "--size", "48x36",
                        "--set", "shells=8", "-o", str(tmp_path / "f.png")],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert p.returncode == 0, p.stderr[-2000:]
    assert (tmp_path / "f.png").exists() and "shells: 8" in p.stdout and "nonfinite_pixels: 0" in p.stdout


@pytest.mark.parametrize("method", ["phong", "zbuffer"])
def test_bad_shells_is_one_line_and_exit_2(method, tmp_path):
    for value in ("0", "5000", "2.5"):
        p = subprocess.run([sys.executable, "-m", "workbench", "render", "fur", "-m", method, "--size", "16x12",
                            "--set", f"shells={value}", "-o", str(tmp_path / "x.png")],
                           capture_output=True, text=True, timeout=300, cwd=tmp_path)
        lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
        assert p.returncode == 2, p.stderr[-2000:]
        assert len(lines) == 1 and "shells" in lines[0], lines
        assert not (tmp_path / "x.png").exists()


def test_bad_shells_refused_by_the_api():
    s = _fur_alone()
    for method in ("gouraud", "zbuffer"):
        with pytest.raises(WorkbenchError, match="shells"):
            get_renderer(method).estimate_bytes(s, 8, 6, shells=4096)


def test_estimate_grows_with_the_shells_for_the_zbuffer():
    """The Z-buffer scans one shell at a time: its estimate holds one shell's triangles and the
    per-pixel composite, whatever N; GL instances one mesh."""
    s = _fur_alone()
    z = get_renderer("zbuffer")
    plain = z.estimate_bytes(replace(s, objects=type(s.objects)()), 64, 48)
    assert z.estimate_bytes(s, 64, 48, shells=8) > plain


def test_support_tables_say_approximated():
    for method in ("flat", "gouraud", "phong", "zbuffer"):
        cell = get_renderer(method).support[ft.TEXELS]
        assert cell.status is Status.APPROXIMATED and "shells" in cell.reason and "no shadows" in cell.reason


@pytest.mark.parametrize("method", ["flat", "gouraud"])
def test_every_mode_draws_the_fur_without_nan(method, gl_ctx):
    r = workbench.render(workbench.load_scene("fur"), method, width=32, height=24, shells=4)
    assert r.stats["nonfinite_pixels"] == 0 and ft.TEXELS in r.features_used and r.stats["shells"] == 4
