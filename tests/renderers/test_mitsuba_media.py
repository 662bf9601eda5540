"""The Mitsuba export of a hypertexture is the same medium: the export as data (the ``.vol``
file read back, the grid's frame, the scale per world length, the albedo, the integrator, the
notes) and, rendered by Mitsuba, the transmittance of a soft sphere in front of a uniform
background against a numpy quadrature of ``exp(-integral sigma_t)`` (Mitsuba 3 is installed by
the README's commands: like tests/renderers/test_mitsuba_method.py, these fail, not skip, when
it is missing)."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from pathtrace_scenes import scene as load_text
from statistics_budget import band
from workbench.core import transform as tf
from workbench.core.errors import WorkbenchError
from workbench.renderers import mitsuba_export as mx
from workbench.renderers import mitsuba_method as mm
from workbench.renderers.base import get_renderer
from workbench.scene.kinds import hypertexture as ht

SOFT_SPHERE = """
[scene]
name = "soft_sphere"
background = [{bg}, {bg}, {bg}]
ambient = [0.0, 0.0, 0.0]
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 42.0
resolution = [16, 16]
[materials.smoke]
color = [1.0, 1.0, 1.0]
[[objects]]
type = "hypertexture"
material = "smoke"
transform = {{ scale = 1.5, translate = [0.12, -0.07, 0.0] }}
base = "sphere"
size = 0.6
soft = 0.5
noise = "none"
density = {density}
albedo = [{albedo}, {albedo}, {albedo}]
grid = {grid}
{extra}
"""


def soft_sphere(tmp_path, bg=1.0, density=1.5, albedo=0.0, grid=6, extra=""):
    """A soft sphere (no noise) seen whole, scaled by 1.5 (world extinction = object / 1.5) and
    off the axis, on a coarse grid (6 cells: a half-cell error in the grid's frame is 0.14
    object units), in front of a uniform background that is the only light."""
    text = SOFT_SPHERE.format(bg=bg, density=density, albedo=albedo, grid=grid, extra=extra)
    return load_text(tmp_path, text, "soft_sphere")


def read_vol(path: str) -> tuple[np.ndarray, np.ndarray]:
    """(data (z, y, x, channels), box (6,)) of a Mitsuba ``.vol`` file, read by its documented
    layout (written independently of :func:`workbench.renderers.mitsuba_export.write_vol`)."""
    raw = open(path, "rb").read()
    assert raw[:3] == b"VOL" and raw[3] == 3
    enc, xr, yr, zr, ch = np.frombuffer(raw[4:24], "<i4")
    assert enc == 1
    box = np.frombuffer(raw[24:48], "<f4")
    data = np.frombuffer(raw[48:], "<f4")
    assert data.size == xr * yr * zr * ch
    return data.reshape(zr, yr, xr, ch), box


def _medium_shapes(d: dict) -> list[dict]:
    return [v for v in d.values() if isinstance(v, dict) and "interior" in v]


def test_export_writes_the_grid_its_frame_and_the_world_scale(tmp_path):
    s = soft_sphere(tmp_path)
    h = s.objects[0]
    ex = mx.export_scene(s, str(tmp_path), tessellation=4)
    (shape,) = _medium_shapes(ex.scene_dict)
    assert ex.scene_dict["integrator"]["type"] == "volpath"
    assert shape["type"] == "sphere" and shape["bsdf"] == {"type": "null"}
    R = ht.bound_radius(h)
    W = np.asarray(h.world_from_object)
    assert np.allclose(shape["to_world"], W @ tf.scale(R))
    med = shape["interior"]
    assert med["type"] == "heterogeneous" and med["phase"] == {"type": "isotropic"}
    assert med["scale"] == pytest.approx(1.5 / 1.5)  # density per object length / the scale 1.5
    vol = med["sigma_t"]
    assert vol["filter_type"] == "trilinear" and vol["wrap_mode"] == "clamp"
    data, box = read_vol(vol["filename"])
    assert data.shape == (6, 6, 6, 1) and np.allclose(box, [-R, -R, -R, R, R, R])
    assert np.array_equal(data[..., 0], ht.density_grid(h, 6))
    # the unit cube's corners land on the world cube around the bound; a cell centre on its sample
    V = np.asarray(vol["to_world"])
    assert np.allclose(tf.transform_points(V, np.array([[0, 0, 0], [1, 1, 1.0]])),
                       tf.transform_points(W, np.array([[-R, -R, -R], [R, R, R]])))
    i, j, k = 1, 4, 2  # x, y, z cell
    u = (np.array([i, j, k]) + 0.5) / 6
    p_obj = tf.transform_points(np.linalg.inv(W), tf.transform_points(V, u[None]))
    assert ht.sample_grid(ht.density_grid(h, 6), R, p_obj)[0] == pytest.approx(data[k, j, i, 0], abs=1e-6)
    assert med["albedo"] == {"type": "rgb", "value": [0.0, 0.0, 0.0]}
    assert not [n for n in ex.left_out if n.feature == ht.FEATURE]  # the grid: exact


def test_export_notes_the_analytic_field_the_emission_and_a_non_similarity(tmp_path):
    s = soft_sphere(tmp_path, grid=0, extra='emission = [1.0, 0.5, 0.2]')
    ex = mx.export_scene(s, str(tmp_path), tessellation=4, volume_grid=12)
    notes = [n for n in ex.left_out if n.feature == ht.FEATURE]
    assert any("12^3" in n.reason and n.status.value == "approximated" for n in notes), notes
    assert any("emissive media" in n.reason and n.status.value == "left out" for n in notes), notes
    data, _ = read_vol(_medium_shapes(ex.scene_dict)[0]["interior"]["sigma_t"]["filename"])
    assert data.shape == (12, 12, 12, 1)
    text = SOFT_SPHERE.format(bg=1.0, density=1.5, albedo=0.0, grid=6, extra="")
    stretched = load_text(tmp_path, text.replace("scale = 1.5", "scale = [1.0, 2.0, 1.0]"), "stretched")
    d, left = {}, []
    assert ht.mitsuba(stretched.objects[0], mx.ShapeWriter(stretched, str(tmp_path), d, 4, left)) == []
    assert d == {} and any("not a similarity" in n.reason for n in left if n.feature == ht.FEATURE), left


def test_a_ramp_gives_an_rgb_albedo_grid_and_a_camera_inside_gets_the_medium(tmp_path):
    ramp = 'ramp = [[0.0, [1.0, 0.2, 0.1]], [0.5, [0.2, 1.0, 0.3]], [1.0, [0.5, 0.5, 1.0]]]'
    s = soft_sphere(tmp_path, albedo=0.8, extra=ramp)
    h = s.objects[0]
    ex = mx.export_scene(s, str(tmp_path), tessellation=4)
    med = _medium_shapes(ex.scene_dict)[0]["interior"]
    rgb, _ = read_vol(med["albedo"]["filename"])
    D = ht.density_grid(h, 6)
    assert rgb.shape == (6, 6, 6, 3)
    assert np.allclose(rgb, 0.8 * ht.ramp(h, D.ravel()).reshape(6, 6, 6, 3), atol=1e-6)
    assert not ht.ramp_is_affine(h)
    assert any("ramp" in n.reason for n in ex.left_out if n.feature == ht.FEATURE)
    assert "medium" not in ex.scene_dict["sensor"]
    inside = load_text(tmp_path, SOFT_SPHERE.format(bg=1.0, density=1.5, albedo=0.0, grid=6, extra="")
                       .replace("[0.0, 0.0, 4.0]", "[0.3, 0.0, 0.5]"), "inside")
    ex3 = mx.export_scene(inside, str(tmp_path), tessellation=4)
    assert ex3.scene_dict["sensor"]["medium"] is _medium_shapes(ex3.scene_dict)[0]["interior"]


def test_scenes_without_media_keep_the_path_integrator(tmp_path):
    ex = mx.export_scene(workbench.load_scene("cornell"), str(tmp_path), tessellation=4)
    assert ex.scene_dict["integrator"]["type"] == "path"


def test_volume_grid_option_is_checked_and_counted_in_the_memory_estimate(tmp_path):
    s = soft_sphere(tmp_path, grid=0)
    with pytest.raises(WorkbenchError, match="volume_grid must be within 2"):
        workbench.render(s, "mitsuba", width=8, height=8, spp=2, volume_grid=1)
    r = get_renderer("mitsuba")
    small, big = r.estimate_bytes(s, 8, 8, volume_grid=16), r.estimate_bytes(s, 8, 8, volume_grid=256)
    assert big - small == ht.MITSUBA_BYTES_PER_CELL * (256 ** 3 - 16 ** 3)
    assert ht.MITSUBA_BYTES_PER_CELL * 256 ** 3 > 4 * 4 * 256 ** 3  # both grids, twice in Mitsuba


# --------------------------------------------------------------------------- transmittance
#: Sub-pixel rays per side for the pixel's box-filtered average, and quadrature points per ray.
SUB, STEPS = 8, 600
SPP = 4096


def expected_transmittance(s, shift: float = 0.0, factor: float = 1.0) -> np.ndarray:
    """(H, W) each pixel's box-filtered average of ``exp(-density integral D)`` along the eye
    rays (``SUB`` x ``SUB`` rays per pixel), integrated in object space (the object's
    extinction per object length; the length along ``W^-1 d``) with ``STEPS`` midpoints over
    the chord of the bounding sphere, ``D`` from the grid (:func:`sample_grid`).  ``shift``
    (object units, along x, y and z) and ``factor`` (on the extinction) make it wrong on
    purpose."""
    cam = s.camera
    h = s.objects[0]
    R = ht.bound_radius(h)
    Winv = np.linalg.inv(np.asarray(h.world_from_object))
    o, d = cam.with_resolution(cam.width * SUB, cam.height * SUB).rays()
    O = tf.transform_points(Winv, o.reshape(-1, 3))
    Dv = tf.transform_vectors(Winv, d.reshape(-1, 3))
    a = (Dv * Dv).sum(1)
    b = (O * Dv).sum(1)
    disc = b * b - a * ((O * O).sum(1) - R * R)
    hit = disc > 0.0
    t0 = (-b - np.sqrt(np.maximum(disc, 0.0))) / a
    t1 = (-b + np.sqrt(np.maximum(disc, 0.0))) / a
    grid = ht.density_grid(h, h.grid)
    tau = np.zeros(len(O))
    u = (np.arange(STEPS) + 0.5) / STEPS
    for idx in np.flatnonzero(hit):
        t = t0[idx] + u * (t1[idx] - t0[idx])
        D = ht.sample_grid(grid, R, O[idx] + t[:, None] * Dv[idx] + shift)
        tau[idx] = factor * h.density * D.mean() * (t1[idx] - t0[idx]) * np.sqrt(a[idx])
    T = np.exp(-tau).reshape(cam.height, SUB, cam.width, SUB)
    return T.mean((1, 3))


#: Pixels summed per block of the block chi-square (4 x 4).
BLOCK = 4


def check_transmittance(seed: int, tmp_path) -> None:
    """Mitsuba's image of the soft sphere over a background of radiance 1 (albedo 0, no
    emission: a sample sees 1 or 0, Bernoulli with the pixel's mean transmittance ``p``; its
    variance ``p (1 - p) / spp`` is known exactly, nothing is estimated) against the
    quadrature: the block chi-square over 4 x 4 blocks (16 x 4096 samples each: normal)
    within its band, and the mean of all pixels within ``z`` standard errors.  Bonferroni over
    the two checks."""
    s = soft_sphere(tmp_path)
    r = workbench.render(s, "mitsuba", spp=SPP, seed=seed, variant=mm.FALLBACK_VARIANT)
    assert r.stats["variant"] == mm.FALLBACK_VARIANT and r.stats["integrator"].startswith("volpath")
    assert np.isfinite(r.image).all()
    img = r.image.astype(np.float64)
    assert np.abs(img - img[..., :1]).max() <= 1e-6  # grey
    p = expected_transmittance(s)
    a = img[..., 0]
    var = p * (1.0 - p) / SPP
    z = band("test_mitsuba_media::transmittance", 2)
    H, W = p.shape
    bs = lambda x: x.reshape(H // BLOCK, BLOCK, W // BLOCK, BLOCK).sum((1, 3))
    diff, bvar = bs(a - p), bs(var)
    live = bvar > 0.0
    assert np.abs(diff[~live]).max(initial=0.0) <= 1e-5  # blocks no ray of the medium crosses: exactly 1
    K = int(live.sum())
    chi2 = float((diff[live] ** 2 / bvar[live]).sum()) / K
    assert abs(chi2 - 1.0) <= z * np.sqrt(2.0 / K), (chi2, K)
    se = np.sqrt(var.sum()) / p.size
    assert abs(a.mean() - p.mean()) <= z * se, (a.mean(), p.mean(), se)
    assert z * se <= 0.005 * p.mean()  # the mean check sees a 0.5 % bias


def test_mitsuba_transmittance_through_a_soft_sphere_is_the_quadratures(tmp_path):
    check_transmittance(0, tmp_path)


def test_the_quadrature_sees_the_grids_frame_and_the_world_scale(tmp_path):
    """The check above can fail: a grid shifted by half a cell, or the extinction not divided by
    the transform's scale, moves the expected image far beyond the noise (4096 spp: a pixel's
    standard error is at most 0.008)."""
    s = soft_sphere(tmp_path)
    p = expected_transmittance(s)
    assert 0.1 < p.min() < 0.3 and p.max() == pytest.approx(1.0)
    half_cell = ht.bound_radius(s.objects[0]) / 6
    assert np.abs(expected_transmittance(s, shift=half_cell) - p).max() > 0.05
    assert np.abs(expected_transmittance(s, factor=1.5) - p).max() > 0.05
