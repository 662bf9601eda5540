"""The path tracer's matched-reference options: ``transport`` (``full``, ``diffuse``: radiosity's
physics, ``eye_specular``: the hybrid's) and ``pixel_filter`` (``box``, ``center``), against
radiosity, against scenes rewritten to the physics they stand for, and kernel against its
readable twin."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import workbench
from pathtrace_scenes import PLANE, scene
from scipy.stats import chi2
from statistics_budget import ALPHA, band
from workbench.core.errors import NotApplicable
from workbench.renderers.pathtrace import reference
from workbench.renderers.pathtrace.session import PathTraceSession
from workbench.scene.model import AreaLight

SCENES = Path(workbench.__file__).resolve().parents[1] / "scenes"


def _light_pixels(scene, width, height):
    """(H, W) bool: the projected bounding boxes of the area lights, grown by one pixel."""
    cam = scene.camera.with_resolution(width, height)
    mask = np.zeros((height, width), bool)
    for light in scene.lights:
        if isinstance(light, AreaLight):
            xy, _ = cam.project(np.asarray(light.vertices))
            lo, hi = np.floor(xy.min(0)).astype(int) - 1, np.ceil(xy.max(0)).astype(int) + 1
            mask[max(lo[1], 0):max(hi[1], 0), max(lo[0], 0):max(hi[0], 0)] = True
    return mask


def _consistent(a, b):
    """Mean over pixels and channels of (a - b)^2 / (se_a^2 + se_b^2) where either is noisy:
    about 1 for two independent estimates of one image (a robust form of the per-pixel test:
    one-degree-of-freedom noise estimates have heavy tails), and pixels without noise equal."""
    d2 = (a.image.astype(np.float64) - b.image) ** 2
    v = a.std_error.astype(np.float64) ** 2 + b.std_error.astype(np.float64) ** 2
    noisy = v > 0
    assert np.all(d2[~noisy] <= 1e-10)
    return float(np.mean(d2[noisy] / v[noisy]))


@pytest.mark.slow
def test_diffuse_transport_agrees_with_radiosity_on_cornell():
    """Radiosity at its finest knob (patch size 0.025 of the diagonal, 3,524 patches) and the
    diffuse-transport path tracer (64x64, 512 spp) on the Cornell box: mean radiance of the
    pixels off the light within 1 % (radiosity's discretisation and hemicube bias;
    bench/radiosity_floor.py measures -0.09 % at 128 x 128) plus the normal band of the path
    tracer's mean."""
    sc = workbench.load_scene("cornell")
    W = H = 64
    rad = workbench.render(sc, "radiosity", width=W, height=H, patch_size=0.025)
    pt = workbench.render(sc, "pathtrace", width=W, height=H, spp=512, transport="diffuse")
    off = ~_light_pixels(sc, W, H)
    m_rad = float(rad.image[off].mean())
    m_pt = float(pt.image[off].mean())
    se_mean = float(np.sqrt(np.sum(pt.std_error[off].astype(np.float64) ** 2)) / pt.std_error[off].size)
    assert abs(m_rad - m_pt) <= 0.01 * m_pt + band("test_pathtrace_modes::radiosity_cornell (slow)") * se_mean
    # and the full transport adds nothing on this all-diffuse scene (the same random numbers)
    full = workbench.render(sc, "pathtrace", width=W, height=H, spp=512)
    assert np.array_equal(full.image, pt.image)


_BOX_WITH_SPHERES = (SCENES / "cornell_spheres.toml").read_text()
_MIRROR = """[materials.mirror]
color = [0.95, 0.95, 0.95]
ka = 0.0
kd = 0.0
ks = 0.0
kr = 0.9
"""
_SHINY = """[materials.mirror]
color = [0.8, 0.6, 0.4]
ka = 0.0
kd = 0.5
ks = 0.3
shininess = 30.0
kr = 0.4
"""
_MATTE = """[materials.mirror]
color = [0.8, 0.6, 0.4]
ka = 0.0
kd = 0.5
"""
_POINT = '\n[[lights]]\ntype = "point"\nposition = [278.0, 400.0, 200.0]\nintensity = 0.5\n'


def test_diffuse_mode_is_the_scene_with_lambertian_materials(tmp_path):
    check_diffuse_mode(0, tmp_path)


CONSISTENT_MAX = 1.5


def check_diffuse_mode(seed: int, tmp_path) -> None:
    """``cornell_spheres`` with a partly mirroring, glossy sphere (kd 0.5, ks 0.3, kr 0.4) and
    a point light, path-traced with ``transport=diffuse``, against the same box with that
    sphere Lambertian kd * colour and no point light, path-traced with full transport (the glass
    sphere, kd = 0, is black and opaque in both): the same image within the combined noise:
    :func:`_consistent` at most :data:`CONSISTENT_MAX`, whose chi-square(N) / N probability
    (N noisy values, normal theory) is checked against the test's alpha."""
    assert _MIRROR in _BOX_WITH_SPHERES
    shiny = scene(tmp_path, _BOX_WITH_SPHERES.replace(_MIRROR, _SHINY) + _POINT, "shiny")
    matte = scene(tmp_path, _BOX_WITH_SPHERES.replace(_MIRROR, _MATTE).replace("kt = 0.9", "kt = 0.0")
                   .replace("kr = 0.08", "kr = 0.0"), "matte")
    kw = dict(width=20, height=20, spp=512)
    diffuse = workbench.render(shiny, "pathtrace", transport="diffuse", seed=2 * seed + 1, **kw)
    lambert = workbench.render(matte, "pathtrace", seed=2 * seed + 2, **kw)
    n = int(((diffuse.std_error > 0) | (lambert.std_error > 0)).sum())
    assert n > 500 and chi2.sf(CONSISTENT_MAX * n, n) <= ALPHA["test_pathtrace_modes::diffuse_mode"]
    assert _consistent(diffuse, lambert) <= CONSISTENT_MAX
    assert diffuse.stats["nonfinite_samples"] == 0
    # the check can fail: the full transport of the shiny scene is another image
    full = workbench.render(shiny, "pathtrace", seed=2 * seed + 1, **kw)
    assert _consistent(full, lambert) > 5.0
    assert any(str(e).startswith("point_lights: transport=diffuse") for e in diffuse.left_out)


def test_pixel_filter_center_on_a_flat_lit_wall_and_at_the_pixel_centre(tmp_path):
    """A plane under a directional light (uniform radiance, no variance): ``center`` equals
    ``box``.  Under a point light (radiance varies across a pixel), ``center`` is the
    radiance at the pixel centre: the ray caster's one centre sample, while the box-filtered
    pixel differs from it."""
    flat = scene(tmp_path, PLANE + '[[lights]]\ntype = "directional"\ndirection = [0.3, -1.0, 0.2]\nintensity = 0.8\n')
    c = workbench.render(flat, "pathtrace", spp=4, pixel_filter="center")
    b = workbench.render(flat, "pathtrace", spp=4, pixel_filter="box")
    assert c.image.max() > 0.0
    assert np.allclose(c.image, b.image, rtol=1e-5, atol=0.0)
    lit = scene(tmp_path, PLANE + '[[lights]]\ntype = "point"\nposition = [0.5, 1.5, 0.3]\n'
                 'intensity = 2.0\nfalloff = "inverse_square"\n')
    c = workbench.render(lit, "pathtrace", spp=2, pixel_filter="center")
    b = workbench.render(lit, "pathtrace", spp=2, pixel_filter="box")
    ray = workbench.render(lit, "raycast")
    assert ray.image.max() > 0.0
    assert np.allclose(c.image, ray.image, rtol=1e-5, atol=1e-7)
    assert np.abs(b.image - ray.image).max() > 1e-3 * ray.image.max()


def test_diffuse_modes_need_an_emitting_surface(tmp_path):
    """A scene lit by a point light only: the full transport renders it, the diffuse ones
    say there is nothing to distribute (as radiosity)."""
    sc = scene(tmp_path, PLANE + '[[lights]]\ntype = "point"\nposition = [0.5, 1.5, 0.3]\nintensity = 2.0\n')
    assert workbench.render(sc, "pathtrace", spp=2).image.max() > 0.0
    for transport in ("diffuse", "eye_specular"):
        with pytest.raises(NotApplicable, match="no emitting surface"):
            workbench.render(sc, "pathtrace", spp=2, transport=transport)


_ROOM = """
[scene]
name = "room"
background = [0.05, 0.05, 0.1]
ambient = [0.3, 0.3, 0.3]
[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 0.4, 0.0]
fov_y = 50.0
resolution = [8, 6]
[[lights]]
type = "point"
position = [1.0, 2.0, 1.0]
intensity = 0.6
[[lights]]
type = "area"
vertices = [[0.0, 2.0, -1.0], [0.0, 2.0, 0.0], [-1.0, 2.0, 0.0], [-1.0, 2.0, -1.0]]
color = [2.0, 2.0, 1.5]
[materials.floor]
color = [0.6, 0.7, 0.8]
kd = 0.6
ks = 0.5
shininess = 20.0
[materials.ball]
color = [0.9, 0.3, 0.2]
kd = 0.5
ks = 0.3
shininess = 60.0
kr = 0.3
[materials.glass]
color = [1.0, 1.0, 1.0]
kd = 0.0
kr = 0.1
kt = 0.9
ior = 1.5
absorption = [0.2, 0.5, 1.0]
[materials.wall]
color = [0.3, 0.8, 0.4]
kd = 0.8
[materials.lamp]
color = [0.0, 0.0, 0.0]
kd = 0.0
emission = [0.6, 0.5, 0.2]
[[objects]]
type = "plane"
material = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
size = [6.0, 6.0]
[[objects]]
type = "sphere"
material = "ball"
center = [-0.5, 0.4, 0.0]
radius = 0.4
[[objects]]
type = "sphere"
material = "glass"
center = [0.5, 0.35, 0.3]
radius = 0.35
[[objects]]
type = "polygon"
name = "wall_facing_away"
material = "wall"
vertices = [[-1.5, 0.0, -0.3], [-1.5, 1.2, -0.3], [1.5, 1.2, -0.3], [1.5, 0.0, -0.3]]
[[objects]]
type = "polygon"
name = "lamp_facing_away"
material = "lamp"
vertices = [[1.2, 0.1, 0.0], [1.2, 0.5, 0.0], [1.6, 0.5, 0.0], [1.6, 0.1, 0.0]]
"""
"""A downward area light, a point light, a glossy floor, a mirroring glossy ball, an absorbing
glass ball, a wall whose back faces the camera (lit on its front by the area light) and an
emissive panel whose (two-sided in ``full``) emission is one-sided in the diffuse modes."""


MODES = [("diffuse", "box"), ("eye_specular", "center"), ("eye_specular", "box")]
REFERENCE_SPP = 160


@pytest.mark.parametrize("transport,pixel_filter", MODES)
def test_kernel_agrees_with_readable_reference_in_every_mode(tmp_path, transport, pixel_filter):
    check_kernel_reference(0, tmp_path, [(transport, pixel_filter)])


def check_kernel_reference(seed: int, tmp_path, modes=tuple(MODES)) -> None:
    """At a few pixels (background, the wall's back, each ball, the floor, the lamp's back) the numba kernel and the
    readable twin agree within the t band of their combined standard errors (the twin's 159
    degrees of freedom; the test's alpha shared by the modes); the chosen pixels are lit."""
    for transport, pixel_filter in modes:
        _kernel_against_reference(seed, tmp_path, transport, pixel_filter)


def _kernel_against_reference(seed: int, tmp_path, transport: str, pixel_filter: str) -> None:
    sc = scene(tmp_path, _ROOM, "room")
    w, h = 8, 6
    pixels = [(0, 0), (1, 3), (3, 2), (3, 5), (5, 3), (3, 6)]
    opts = dict(fresnel="exact", transport=transport, pixel_filter=pixel_filter)
    ses = PathTraceSession(sc, w, h, seed=2 * seed + 7, **opts)
    ses.add_samples(2048)
    idx = [i * w + j for i, j in pixels]
    km, ks = ses.image.reshape(-1, 3)[idx], ses.std_error.reshape(-1, 3)[idx]
    rm, rs = reference.render_pixels(sc, w, h, pixels, REFERENCE_SPP, seed=2 * seed + 11, **opts)
    assert (km > 0).any(axis=1).all()
    z = band("test_pathtrace_modes::kernel_reference", len(MODES) * km.size, dof=REFERENCE_SPP - 1)
    # + the float32 rounding of the kernel's image (pixels without variance: background, lamp)
    assert np.all(np.abs(km - rm) <= z * np.hypot(ks, rs) + 1e-6 * np.abs(rm) + 1e-9)


def test_eye_sees_the_front_radiance_on_a_back_face(tmp_path):
    check_back_face(0, tmp_path)


def check_back_face(seed: int, tmp_path) -> None:
    """The room's wall seen from its back (pixel centre ray, ``diffuse``) shows the radiance of its
    lit front at that point (radiosity's display draws a patch's value on both sides): the same
    as a narrow camera in front of the wall looking at that point, within the noise."""
    sc = scene(tmp_path, _ROOM, "room")
    back = workbench.render(sc, "pathtrace", width=8, height=6, spp=4096, seed=2 * seed + 3, transport="diffuse",
                            pixel_filter="center")
    i, j = 1, 3
    cam = sc.camera.with_resolution(8, 6)
    # the wall point on the pixel centre's ray (the plane z = -0.3)
    o = np.asarray(cam.position, dtype=np.float64)
    ses = PathTraceSession(sc, 8, 6)
    from workbench.core.jit_options import python_twin
    from workbench.renderers.pathtrace.kernels import camera_ray_at
    d = np.array(python_twin(camera_ray_at)(ses.cam, i, j, 0.5, 0.5))
    q = o + (-0.3 - o[2]) / d[2] * d
    assert abs(q[0]) < 1.5 and 0.0 < q[1] < 1.2
    import dataclasses
    narrow = dataclasses.replace(sc.camera, position=(float(q[0]), float(q[1]), -2.0), look_at=tuple(q),
                                 fov_y=0.01, width=3, height=3)
    front = workbench.render(sc.with_camera(narrow), "pathtrace", width=3, height=3, spp=4096, seed=2 * seed + 5,
                             transport="diffuse", pixel_filter="center")
    a, sa = back.image[i, j].astype(np.float64), back.std_error[i, j]
    b, sb = front.image[1, 1].astype(np.float64), front.std_error[1, 1]
    assert a.sum() > 0.1
    assert np.all(np.abs(a - b) <= band("test_pathtrace_modes::back_face", 3, dof=4095) * np.hypot(sa, sb))


def test_noise_image_survives_the_reference_cache(tmp_path):
    """The per-pixel standard error travels in ``stats["stderr"]`` (and its RMS in
    ``stderr_rms``), so a cached path-traced reference keeps its noise estimate."""
    from workbench.compare.reference_cache import cached_render
    sc = workbench.load_scene("cornell")
    miss = cached_render(sc, "pathtrace", 8, 8, directory=tmp_path, spp=4, transport="diffuse",
                         pixel_filter="center")
    hit = cached_render(sc, "pathtrace", 8, 8, directory=tmp_path, spp=4, transport="diffuse",
                        pixel_filter="center")
    assert miss.stats["cache"] == "miss" and hit.stats["cache"] == "hit"
    assert np.array_equal(hit.stats["stderr"], miss.std_error) and hit.stats["stderr"].max() > 0.0
    assert hit.stats["stderr_rms"] == pytest.approx(miss.stats["noise_rmse"], rel=1e-12)
    assert hit.options["transport"] == "diffuse" and hit.options["pixel_filter"] == "center"
