"""The path tracer (``pathtrace``): energy (furnaces), direct light against the Whitted ray
tracer, the kernel against its readable reference, its own noise estimate, determinism and
progressive accumulation, finite images on every bundled scene."""
from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import workbench
from pathtrace_scenes import PLANE, scene
from scipy.stats import chi2
from statistics_budget import ALPHA, band
from workbench.core.errors import NotApplicable
from workbench.renderers.kernels.layout import marker_features
from workbench.renderers.pathtrace import reference
from workbench.renderers.pathtrace.session import PathTraceSession
from workbench.scene.library import bundled

FURNACE = 0.25 / (1.0 - 0.8)   # E / (1 - rho) of scenes/furnace.toml


def _furnace_with(tmp_path, material, obj):
    """The bundled furnace with one more material and object inside."""
    from pathlib import Path
    src = Path(workbench.__file__).resolve().parents[1] / "scenes" / "furnace.toml"
    return scene(tmp_path, src.read_text() + material + obj, "furnace_plus")


def _within_furnace(r, test: str, spp: int, checks: int) -> None:
    """Every pixel within the t band of its own standard error of E / (1 - rho), and the image
    mean within the normal band of its standard error (pixels, not channels: grey, are
    independent: noise_rmse / sqrt(pixels))."""
    se = r.std_error
    assert se is not None and se.shape == r.image.shape and (se > 0).all()
    assert np.all(np.abs(r.image - FURNACE) <= band(test, checks, dof=spp - 1) * se)
    n = r.image.shape[0] * r.image.shape[1]
    assert abs(r.image.mean() - FURNACE) <= band(test, checks) * r.stats["noise_rmse"] / np.sqrt(n)
    assert r.stats["nonfinite_samples"] == 0


def check_furnace(seed: int, tmp_path) -> None:
    r = workbench.render(workbench.load_scene("furnace"), "pathtrace", width=16, height=16, spp=64, seed=seed)
    _within_furnace(r, "test_pathtrace::furnace", 64, 16 * 16 * 3 + 1)


def test_furnace_radiance_everywhere(tmp_path):
    check_furnace(0, tmp_path)


SPECULAR_SPHERES = [("kt = 1.0\nior = 1.5", "exact"), ("kt = 1.0\nior = 1.5", "none"), ("kr = 1.0", "none"),
                    ("kr = 0.3\nkt = 0.7\nior = 1.33", "schlick")]


def check_white_furnace(seed: int, tmp_path, cases=tuple(SPECULAR_SPHERES)) -> None:
    """A lossless specular sphere in the furnace changes nothing: every pixel stays E / (1 - rho)
    (BSDF sampling of the delta lobes conserves energy, refraction into and out of the medium).
    The test's alpha is shared by the four spheres."""
    for kind, fresnel in cases:
        sc = _furnace_with(tmp_path, f"\n[materials.glass]\ncolor = [1.0, 1.0, 1.0]\nka = 0.0\nkd = 0.0\n{kind}\n",
                           '\n[[objects]]\ntype = "sphere"\nmaterial = "glass"\ncenter = [0.5, 0.5, 0.6]\nradius = 0.25\n')
        r = workbench.render(sc, "pathtrace", width=12, height=12, spp=64, fresnel=fresnel, seed=seed)
        _within_furnace(r, "test_pathtrace::white_furnace", 64, len(SPECULAR_SPHERES) * (12 * 12 * 3 + 1))


@pytest.mark.parametrize("case", SPECULAR_SPHERES)
def test_white_furnace_with_specular_sphere(tmp_path, case):
    check_white_furnace(0, tmp_path, [case])


def test_directional_light_on_a_plane_is_exact(tmp_path):
    """One diffuse plane under a directional light: every path ends after one bounce, so the
    estimate has no variance: kd C I cos, the course's diffuse term, as the Whitted tracer."""
    sc = scene(tmp_path, PLANE + '[[lights]]\ntype = "directional"\ndirection = [0.3, -1.0, 0.2]\nintensity = 0.8\n')
    pt = workbench.render(sc, "pathtrace", spp=4)
    wh = workbench.render(sc, "raytrace", spp=1)
    d = np.array([0.3, -1.0, 0.2]) / np.linalg.norm([0.3, -1.0, 0.2])
    expect = 0.7 * np.array([1.0, 0.5, 0.25]) * 0.8 * -d[1]
    assert np.allclose(pt.image, expect, rtol=1e-5)
    assert np.allclose(wh.image, expect, rtol=1e-5)


def check_point_light(seed: int, tmp_path) -> None:
    """Inverse-square point light over a diffuse plane: the path tracer's direct light (irradiance
    pi I cos / r^2, reflected rho / pi) against the Whitted ray tracer's kd C I cos / r^2, both
    box-filtered pixels (the ray tracer's stratified jitter at 256 samples is far more accurate
    than the path tracer's uniform jitter, whose own standard error bounds the difference: its
    t band per pixel, plus 0.1 % for the ray tracer's own error)."""
    sc = scene(tmp_path, PLANE + '[[lights]]\ntype = "point"\nposition = [0.5, 1.5, 0.3]\n'
                'intensity = 2.0\nfalloff = "inverse_square"\n')
    pt = workbench.render(sc, "pathtrace", spp=256, seed=seed)
    wh = workbench.render(sc, "raytrace", spp=256)
    assert pt.stats["noise_rmse"] > 0.0
    z = band("test_pathtrace::point_light", pt.image.size, dof=255)
    assert np.all(np.abs(pt.image - wh.image) <= z * pt.std_error + 1e-3 * wh.image + 1e-6)


def test_point_light_on_a_plane_matches_whitted(tmp_path):
    check_point_light(0, tmp_path)


RMS_RATIO = (0.75, 1.33)


def check_noise_estimate(seed: int, tmp_path) -> None:
    """Two seeds differ by sqrt(se1^2 + se2^2) in RMS, as each image's own estimate says: the
    ratio within :data:`RMS_RATIO`.  With N = 1,728 independent normal differences the squared
    ratio is chi-square(N) / N; the band's probability under it is checked against the test's
    alpha (the band is far wider: path-traced pixels have heavier tails than the normal)."""
    sc = workbench.load_scene("cornell")
    a = workbench.render(sc, "pathtrace", width=24, height=24, spp=32, seed=2 * seed + 1)
    b = workbench.render(sc, "pathtrace", width=24, height=24, spp=32, seed=2 * seed + 2)
    n = a.image.size
    lo, hi = RMS_RATIO
    assert chi2.cdf(lo ** 2 * n, n) + chi2.sf(hi ** 2 * n, n) <= ALPHA["test_pathtrace::noise_estimate"]
    measured = np.sqrt(np.mean((a.image.astype(np.float64) - b.image) ** 2))
    predicted = np.hypot(a.stats["noise_rmse"], b.stats["noise_rmse"])
    assert lo <= measured / predicted <= hi


def test_noise_estimate_is_honest(tmp_path):
    check_noise_estimate(0, tmp_path)


def test_seeded_progressive_and_thread_independent():
    sc = workbench.load_scene("cornell_spheres")
    once = PathTraceSession(sc, 10, 8, seed=3)
    once.add_samples(8)
    steps = PathTraceSession(sc, 10, 8, seed=3)
    steps.add_samples(3)
    steps.add_samples(5)
    assert np.array_equal(once.image, steps.image)
    assert np.array_equal(once.std_error, steps.std_error)
    other = PathTraceSession(sc, 10, 8, seed=4)
    other.add_samples(8)
    assert not np.array_equal(once.image, other.image)
    import numba
    saved = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = PathTraceSession(sc, 10, 8, seed=3)
        one.add_samples(8)
    finally:
        numba.set_num_threads(saved)
    assert np.array_equal(once.image, one.image)


_GLOSSY = """
[scene]
name = "glossy"
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
vertices = [[-1.0, 2.0, -1.0], [-1.0, 2.0, 0.0], [0.0, 2.0, 0.0], [0.0, 2.0, -1.0]]
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
kr = 0.2
[materials.glass]
color = [1.0, 1.0, 1.0]
kd = 0.0
kr = 0.1
kt = 0.9
ior = 1.5
absorption = [0.2, 0.5, 1.0]
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
"""


KERNEL_SCENES = ["cornell_spheres", "glossy", "cornell"]


def only_triangles(ses) -> bool:
    """Whether the session's kernels were compiled for triangles alone (``kernels.cast``)."""
    return marker_features(ses.geo.kinds) == ("triangles",)
REFERENCE_SPP = 160


def check_kernel_reference(seed: int, tmp_path, names=tuple(KERNEL_SCENES)) -> None:
    """At a few pixels the numba kernel and the readable twin (the ray tracer's readable
    intersection, numpy random numbers) agree within the t band of their combined standard
    errors (the twin's 159 degrees of freedom).  On ``cornell`` every primitive is a BVH
    triangle once its polygons and area light are (its kind marker names no analytic row: each ray goes to the
    BVH alone), while the twin traces the polygons themselves."""
    for name in names:
        _kernel_against_reference(seed, tmp_path, name)


@pytest.mark.parametrize("name", KERNEL_SCENES)
def test_kernel_agrees_with_readable_reference(tmp_path, name):
    check_kernel_reference(0, tmp_path, [name])


def _kernel_against_reference(seed: int, tmp_path, name: str) -> None:
    if name == "glossy":
        sc, w, h, opts = scene(tmp_path, _GLOSSY), 8, 6, dict(fresnel="exact")
        pixels = [(1, 1), (3, 2), (3, 5), (4, 6), (5, 3)]
    else:
        sc, w, h, opts = workbench.load_scene(name), 8, 8, dict(fresnel="schlick")
        pixels = [(1, 4), (5, 2), (5, 5), (3, 0), (7, 4)]
    ses = PathTraceSession(sc, w, h, seed=2 * seed + 7, **opts)
    assert only_triangles(ses) == (name == "cornell")
    ses.add_samples(2048)
    km = ses.image.reshape(-1, 3)[[i * w + j for i, j in pixels]]
    ks = ses.std_error.reshape(-1, 3)[[i * w + j for i, j in pixels]]
    rm, rs = reference.render_pixels(sc, w, h, pixels, REFERENCE_SPP, seed=2 * seed + 11, **opts)
    assert (rs > 0).any(axis=1).all()  # every pixel is lit (a real check, not zeros)
    z = band("test_pathtrace::kernel_reference", len(KERNEL_SCENES) * km.size, dof=REFERENCE_SPP - 1)
    assert np.all(np.abs(km - rm) <= z * np.hypot(ks, rs) + 1e-9)


def _light_over_plane(tmp_path, facing_up: bool):
    """PLANE with a 1 x 1 area light of radiance (3, 2, 1) at height 1 on the line of sight of
    the image's centre, facing up (towards the camera) or down (towards the plane)."""
    c = 4.0 / 3.0  # the centre ray from (0, 3, 4) to the origin crosses y = 1 at z = 4/3
    v = [[-0.5, 1.0, c - 0.5], [-0.5, 1.0, c + 0.5], [0.5, 1.0, c + 0.5], [0.5, 1.0, c - 0.5]]
    if not facing_up:
        v = v[::-1]
    return scene(tmp_path, PLANE + f'[[lights]]\ntype = "area"\nvertices = {v}\ncolor = [3.0, 2.0, 1.0]\n',
                 "light_up" if facing_up else "light_down")


def test_area_light_traced_as_triangles_keeps_one_emitting_side(tmp_path):
    """The session traces a convex area light as two BVH triangles (``geometry.triangulated``)
    of its black material, emitting from the front only: the camera sees exactly its radiance on
    the front and 0 on the back (pixel centres), and the plane it lights below has the mean
    radiance of the light traced as the ray tracer's polygon (``triangulate=False``)
    (:func:`check_area_light_triangles`)."""
    up = PathTraceSession(_light_over_plane(tmp_path, True), 16, 12, seed=1, pixel_filter="center")
    down = PathTraceSession(_light_over_plane(tmp_path, False), 16, 12, seed=1, pixel_filter="center")
    for ses in (up, down):
        assert only_triangles(ses) and len(ses.emitters.cdf) == 2 and (ses.emitters.mesh_tri >= 0).all()
        ses.add_samples(4)
    light = np.float32([3.0, 2.0, 1.0])
    seen = (up.image == light).all(axis=2)        # the front, from above: exactly its radiance
    assert seen[6, 8] and 4 <= seen.sum() < 16 * 12
    assert (up.image[~seen] == 0.0).all()         # it lights nothing below it
    assert (down.image[6, 8] == 0.0).all()         # the back: black
    assert (down.image.max(axis=2) > 0).sum() > 100  # the plane below is lit
    check_area_light_triangles(1, tmp_path)


def check_area_light_triangles(seed: int, tmp_path) -> None:
    """The light traced as two triangles and as the ray tracer's polygon light the plane below
    alike: image means within the normal band of the difference's standard error (16 x 12
    pixels of 64 samples each per channel)."""
    sc = _light_over_plane(tmp_path, False)
    tri, poly = (PathTraceSession(sc, 16, 12, seed=s, triangulate=t)
                 for s, t in ((2 * seed, True), (2 * seed + 1, False)))
    assert not only_triangles(poly)
    for ses in (tri, poly):
        ses.add_samples(64)
    se = np.sqrt((tri.std_error.astype(np.float64) ** 2).sum(axis=(0, 1))
                 + (poly.std_error.astype(np.float64) ** 2).sum(axis=(0, 1))) / (16 * 12)
    diff = tri.image.mean(axis=(0, 1), dtype=np.float64) - poly.image.mean(axis=(0, 1), dtype=np.float64)
    assert (se > 0).all() and np.all(np.abs(diff) <= band("test_pathtrace::area_light_triangles", 3) * se)


def test_area_light_at_grazing_angles_does_not_shadow_itself(tmp_path):
    check_grazing_area_light(0, tmp_path)


GRAZING_SPP, GRAZING_REFERENCE_SPP = 64, 32


def check_grazing_area_light(seed: int, tmp_path) -> None:
    """A small area light (0.2 x 0.2, facing down, 1 above the plane, behind the camera) lights
    the plane in view at grazing angles (|cos| 0.1 to 0.3 at the light): the path tracer matches
    the Whitted ray tracer's stand-in, one inverse-square point light with a cosine lobe at the
    light's centre and of its power (the small-light limit: off by (size / distance)^2 < 0.2 %).
    The shadow feeler once ran along ``l`` from its pushed origin and met the light's own plane
    short of its margin wherever |cos_l| < 1/2: every pixel was black (kernel and twin alike)."""
    v = [[-0.1, 1.0, 4.9], [0.1, 1.0, 4.9], [0.1, 1.0, 5.1], [-0.1, 1.0, 5.1]]  # normal -y
    sc = scene(tmp_path, PLANE + f'[[lights]]\ntype = "area"\nvertices = {v}\ncolor = [30.0, 20.0, 10.0]\n')
    pt = workbench.render(sc, "pathtrace", spp=GRAZING_SPP, pixel_filter="center", seed=2 * seed)
    wh = workbench.render(sc, "raytrace", spp=1)
    assert (wh.image.max(axis=2) > 0).sum() > 150
    test = "test_pathtrace::grazing_area_light"
    checks = pt.image.size + 2 * 3
    z = band(test, checks, dof=GRAZING_SPP - 1)
    assert np.all(np.abs(pt.image - wh.image) <= z * pt.std_error + 5e-3 * wh.image + 1e-7)
    mean, se = reference.render_pixels(sc, 16, 12, [(1, 8), (6, 3)], GRAZING_REFERENCE_SPP,
                                       pixel_filter="center", seed=2 * seed + 1)
    expect = wh.image[[1, 6], [8, 3]]
    z = band(test, checks, dof=GRAZING_REFERENCE_SPP - 1)
    assert np.all(np.abs(mean - expect) <= z * se + 5e-3 * expect + 1e-7) and (mean > 0).all()


@pytest.mark.parametrize("name", [p.stem for p in bundled()])
def test_every_bundled_scene_finite(name):
    r = workbench.render(workbench.load_scene(name), "pathtrace", width=8, height=6, spp=2)
    assert np.isfinite(r.image).all() and np.isfinite(r.std_error).all()
    assert r.stats["nonfinite_pixels"] == 0 and r.stats["nonfinite_samples"] == 0
    assert r.image.max() > 0.0


def test_no_light_is_not_applicable(tmp_path):
    sc = scene(tmp_path, PLANE)
    with pytest.raises(NotApplicable, match="nothing emits light"):
        workbench.render(sc, "pathtrace", spp=1)


def test_memory_estimate_bounds_the_allocations():
    from workbench.renderers.base import get_renderer
    sc = workbench.load_scene("cornell")
    PathTraceSession(sc, 4, 4).add_samples(1)  # compiled outside the measure
    tracemalloc.start()
    try:
        workbench.render(sc, "pathtrace", width=96, height=64, spp=2)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert 0 < peak <= get_renderer("pathtrace").estimate_bytes(sc, 96, 64)


def test_run_to_noise_stops_at_the_target_or_the_cap():
    from workbench.renderers.pathtrace.session import run_to_noise
    sc = workbench.load_scene("furnace")
    ses = run_to_noise(PathTraceSession(sc, 6, 6), 0.02, max_spp=4096)
    assert ses.noise_rmse <= 0.02 and ses.samples < 4096
    capped = run_to_noise(PathTraceSession(sc, 6, 6), 1e-6, max_spp=24)
    assert capped.samples == 24 and capped.noise_rmse > 1e-6


def test_normalised_phong_lobe_under_a_directional_light(tmp_path):
    """A purely glossy plane (kd = 0, ks, n) seen through a tiny field of view at 10 degrees from
    the light's mirror direction: one bounce, no variance, the normalised lobe
    ks (n + 2) / (2 pi) cos^n(alpha) times the irradiance pi I cos(theta); and the course's
    ks cos^n(alpha) I in the Whitted tracer: their ratio is (n + 2) cos(theta) / 2 (DESIGN.md)."""
    a = np.radians(10.0)
    r = np.array([0.6, 0.8, 0.0])                                   # mirror of the light direction
    v = np.array([r[0] * np.cos(a) - r[1] * np.sin(a), r[0] * np.sin(a) + r[1] * np.cos(a), 0.0])
    cam = 10.0 * v
    sc = scene(tmp_path, f"""
[scene]
name = "gloss"
background = [0.0, 0.0, 0.0]
ambient = [0.0, 0.0, 0.0]
[camera]
position = [{cam[0]}, {cam[1]}, {cam[2]}]
look_at = [0.0, 0.0, 0.0]
fov_y = 0.01
resolution = [4, 4]
[[lights]]
type = "directional"
direction = [0.6, -0.8, 0.0]
intensity = 0.9
[materials.gloss]
color = [1.0, 1.0, 1.0]
ka = 0.0
kd = 0.0
ks = 0.8
shininess = 20.0
[[objects]]
type = "plane"
material = "gloss"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
size = [1000.0, 1000.0]
""")
    pt = workbench.render(sc, "pathtrace", spp=8)
    wh = workbench.render(sc, "raytrace", spp=1)
    course = 0.8 * np.cos(a) ** 20 * 0.9
    assert np.allclose(wh.image, course, rtol=1e-3)
    assert np.allclose(pt.image, course * (20 + 2) / 2 * 0.8, rtol=1e-3)
