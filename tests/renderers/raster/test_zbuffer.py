"""The CPU Z-buffer (``zbuffer``) and the raster methods' "as taught" options (issue 15, items 5
and 6): the course's scanline interpolation and its orientation dependence, the p-bit integer
depth buffer, the plain-mean vertex normals, and the Z-buffer as the pixel-by-pixel twin of
the GL flat / Gouraud / Phong images drawn with ``interpolation=screen`` (and ``standins=off``:
the Z-buffer draws the bare local model)."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.core.errors import WorkbenchError
from workbench.renderers.base import get_renderer
from workbench.renderers.zbuffer import clip_near, near_clipped_mask, to_window
from workbench.renderers.zbuffer_scan import Polygons, new_frame, scan_polygons
from workbench.scene.mesh_normals import mean_face_normals

DIFFERS = 1e-2
"""A pixel differs when a channel differs by more than this (linear units; float32 rounding
and the GL driver's arithmetic stay below 1e-4 on the shaded surfaces)."""


def _scan(xy, values, z=0.5, size=64, depth_bits=24, frame=None):
    """Scan one convex polygon (window xy (n, 2), one attribute per vertex) into ``frame``."""
    xy = np.asarray(xy, dtype=np.float64)
    zs = np.broadcast_to(np.asarray(z, dtype=np.float64), (len(xy),))
    polys = Polygons(np.column_stack([xy, zs]), np.asarray(values, dtype=np.float64)[:, None],
                     np.array([0]), np.array([len(xy)]), np.array([0], np.int32))
    frame = frame or new_frame(size, size, 1, depth_bits)
    scan_polygons(polys, frame)
    return frame


def _square(angle_deg: float, centre=(32.0, 32.0), r=20.0) -> np.ndarray:
    a = np.radians(angle_deg) + np.pi / 4 + np.arange(4) * np.pi / 2
    return np.asarray(centre) + r * np.stack([np.cos(a), np.sin(a)], -1)


def test_gouraud_scanline_on_a_quad_depends_on_its_orientation():
    """The course's comparison slide: Gouraud's colour depends on the polygon's orientation.
    A square with intensities (1, 0, 0, 0) at its corners: at its centre the scanline gives
    1/4 when its sides are axis-aligned (the row meets the two sides through A) and 1/80 when
    it is turned by 45 degrees (the row through the centre passes by B and D, both 0):
    measured 0.25 and 0.0125, a difference of 0.2375 for the same polygon."""
    centre = []
    for angle in (0.0, 45.0):
        f = _scan(_square(angle), [1.0, 0.0, 0.0, 0.0])
        centre.append(f.attrs[31:33, 31:33, 0].mean())   # the four pixels around (32, 32)
    assert centre[0] == pytest.approx(0.25, abs=1e-9)
    assert centre[1] < 0.02
    assert centre[0] - centre[1] > 0.2


def test_scanline_on_a_triangle_is_the_plane_at_any_orientation():
    """On a triangle the same formulas give the affine function of its three values at every
    pixel centre, whatever the rotation: the dependence above needs four or more vertices."""
    for angle in (0.0, 17.0, 45.0, 90.0):
        a = np.radians(angle) + np.array([0.0, 2.1, 4.0])
        xy = 32.0 + 25.0 * np.stack([np.cos(a), np.sin(a)], -1)
        vals = np.array([1.0, -2.0, 0.5])
        f = _scan(xy, vals)
        i, j = np.nonzero(f.ident >= 0)
        M = np.column_stack([xy, np.ones(3)])
        coef = np.linalg.solve(M, vals)
        plane = coef[0] * (j + 0.5) + coef[1] * (i + 0.5) + coef[2]
        assert len(i) > 500
        assert np.abs(f.attrs[i, j, 0] - plane).max() < 1e-9


def test_near_clipped_triangle_stays_linear_in_screen_space():
    """A triangle in front of the eye that the near plane cuts: the new corners get the values
    of the screen-linear function of the three original corners (the course's interpolation
    over the whole triangle), not the clip-space lerp (0.018 instead of 0.109 on one edge here)."""
    from workbench.core.transform import perspective
    clip_from_camera = perspective(60.0, 1.0, 1.0, 100.0)
    cam = np.array([[-2.0, -1.0, -0.5], [2.0, -1.0, -0.5], [0.0, 1.5, -6.0]])   # w = 0.5, 0.5, 6
    clip = np.concatenate([cam, np.ones((3, 1))], 1) @ clip_from_camera.T
    vals = np.array([[0.0], [1.0], [0.2]])
    cp, ap, keep = clip_near(clip[None], vals[None])
    assert not keep[0] and len(cp) == 1 and len(cp[0]) == 3    # two corners cut off
    win = to_window(clip, 64, 64)
    coef = np.linalg.solve(np.column_stack([win[:, :2], np.ones(3)]), vals[:, 0])
    new = to_window(cp[0], 64, 64)
    expected = np.column_stack([new[:, :2], np.ones(len(new))]) @ coef
    assert np.abs(ap[0][:, 0] - expected).max() < 1e-9
    d = clip[:, 2] + clip[:, 3]                     # the clip-space lerp along edge c -> a
    t = d[2] / (d[2] - d[0])
    assert abs((vals[2, 0] + t * (vals[0, 0] - vals[2, 0])) - expected).min() > 0.05


def test_depth_buffer_is_p_bits_initialised_to_its_maximum():
    """Course: "initialisée au maximum possible 2^p - 1", and a surface replaces the stored one
    only if its integer depth is smaller.  Two parallel squares at window depths 0.5021 and
    0.5020, the farther drawn first: with p = 24 the nearer one wins everywhere, with p = 8
    (levels 1/255 apart) both round to 128 and the first one drawn stays (a tie)."""
    for p, nearer_wins in ((24, True), (8, False)):
        f = new_frame(16, 16, 1, p)
        assert (f.depth == 2 ** p - 1).all() and (f.ident == -1).all()
        sq = [(2.0, 2.0), (14.0, 2.0), (14.0, 14.0), (2.0, 14.0)]
        xyz = np.array([[x, y, z] for z in (0.5021, 0.5020) for x, y in sq])
        polys = Polygons(xyz, np.zeros((8, 1)), np.array([0, 4]), np.array([4, 4]), np.array([0, 1], np.int32))
        scan_polygons(polys, f)
        drawn = f.ident >= 0
        assert drawn.sum() == 144
        assert (f.ident[drawn] == (1 if nearer_wins else 0)).all()
        assert (f.depth[drawn] < 2 ** p - 1).all()


def test_mean_face_normals_is_the_plain_mean():
    """A vertex shared by one big triangle tilted up and two small flat ones: the course's
    plain mean counts each face once (area weights would let the big one dominate)."""
    V = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-0.1, 0.0, 0.0], [0.0, -0.1, 0.0],
                  [-10.0, 0.0, 10.0]])
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]])
    fu = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    fu /= np.linalg.norm(fu, axis=1, keepdims=True)
    expected = fu.mean(0) / np.linalg.norm(fu.mean(0))
    N = mean_face_normals(V, F, np.zeros_like(V))
    assert np.abs(N[0] - expected).max() < 1e-12
    assert np.allclose(N[5], fu[3])           # a vertex of one face: that face's normal


def test_zbuffer_rejects_bad_options():
    scene = workbench.load_scene("scenes/cornell.toml")
    for bad in ({"depth_bits": 0}, {"depth_bits": 33}, {"tessellation": 0}, {"shading": "toon"},
                {"normals": "weighted"}):
        with pytest.raises(WorkbenchError, match="zbuffer"):
            workbench.render(scene, "zbuffer", width=16, height=12, **bad)


def _differing(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a - b).max(-1) > DIFFERS


def _twin_check(names):
    for name in names:
        scene = workbench.load_scene(f"scenes/{name}.toml")
        for mode in ("flat", "gouraud", "phong"):
            z = workbench.render(scene, "zbuffer", width=160, height=120, shading=mode).image
            g = get_renderer(mode).render(scene.with_camera(scene.camera.with_resolution(160, 120)), 160, 120,
                                          interpolation="screen", standins="off").image
            assert np.isfinite(z).all() and np.isfinite(g).all(), (name, mode)
            clipped = near_clipped_mask(scene, 160, 120)
            diff = _differing(z, g)
            assert diff.mean() < 0.002, (name, mode, diff.mean())
            assert (diff & clipped).mean() < 0.001, (name, mode, (diff & clipped).mean())


@pytest.mark.gl
def test_zbuffer_is_the_twin_of_gl_screen_space(gl_ctx):
    """``whitted`` in every mode (the measurements: :func:`test_zbuffer_twin_on_four_scenes`)."""
    _twin_check(["whitted"])


@pytest.mark.gl
@pytest.mark.slow
def test_zbuffer_twin_on_four_scenes(gl_ctx):
    """Every mode on four bundled scenes (those with neither bump nor opacity maps, which the
    Z-buffer leaves out) at 160 x 120, against the GL image with ``interpolation=screen``.

    Measured (llvmpipe; ``bench/zbuffer.py`` at 320 x 240): 0 to 8 differing pixels per
    image (at most 0.01 %): pixel centres on a triangle edge (rasterisation rules, float32 edge
    functions) or on a texture pattern boundary (float32).  None on the triangles the near
    plane cuts (the floor under the camera): both give the corners it adds their screen-linear
    values (:func:`~workbench.renderers.zbuffer.clip_near`, ``shaders/include/
    screen_space.glsl``).  With GLSL's ``noperspective`` instead, llvmpipe's clipper gave them
    NaN (43 pixels of ``whitted`` Gouraud, 199 of ``quadrics``) or a zero normal (Phong: black).
    Bounds: 0.2 % of the pixels, 0.1 % on near-clipped triangles, the GL image finite.
    """
    _twin_check(["whitted", "quadrics", "mesh", "csg"])


@pytest.mark.gl
def test_screen_space_option_is_what_makes_gl_the_twin(gl_ctx):
    """On the ``whitted`` floor (a big checkered plane seen at a grazing angle) GL's default,
    perspective-correct interpolation differs from the course's screen-space formulas on many
    pixels; the ``interpolation=screen`` option removes them (measured at 160 x 120, Gouraud:
    3.2 % of pixels differ from the Z-buffer with perspective-correct varyings, 0.01 % with
    screen-space ones).  And ``normals=face_mean`` changes the spheres' shading (plain mean
    of the faces' normals instead of the analytic normals)."""
    scene = workbench.load_scene("scenes/whitted.toml")
    z = workbench.render(scene, "zbuffer", width=160, height=120).image
    persp = workbench.render(scene, "gouraud", width=160, height=120, standins="off").image
    small = scene.with_camera(scene.camera.with_resolution(160, 120))
    screen = get_renderer("gouraud").render(small, 160, 120, interpolation="screen", standins="off").image  # NaNs kept
    assert _differing(z, persp).mean() > 0.02
    assert np.isfinite(screen).all()
    assert _differing(z, screen).mean() < 0.002
    mean = workbench.render(scene, "gouraud", width=160, height=120, normals="face_mean", standins="off").image
    assert np.abs(mean - persp).max() > 1e-3
    zm = workbench.render(scene, "zbuffer", width=160, height=120, normals="face_mean").image
    sm = get_renderer("gouraud").render(scene.with_camera(scene.camera.with_resolution(160, 120)), 160, 120,
                                        interpolation="screen", normals="face_mean", standins="off").image
    assert _differing(zm, sm).mean() < 0.002
