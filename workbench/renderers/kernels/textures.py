"""Texture maps in numba: the surface colour, the bumped normal, the opacity and the
environment's radiance at one point, as :mod:`workbench.renderers.texturing` (the numpy
reference, whose docstrings give the projections, patterns and equations) computes them for
arrays of points.  ``tests/renderers/kernels/test_kernel_textures.py`` compares the two on
random points for every pattern, projection, bump, opacity and environment kind.

The maps come as one record, :class:`Textures` (built by
:func:`workbench.renderers.raytrace.maps.texture_tables`): three tables with the columns
:class:`.columns.Tex` (a row per material: its colour texture, bump map and opacity map), the
environment row (:class:`.columns.Env`), every image's pixels in one flat float64 array (RGBA
rows, top row first; a table row holds its image's offset and size) and a marker.  The
marker's dtype names ``maps`` when the scene has any map but ``checker`` colours with the
``planar`` or ``solid`` projection: the gates at the end of this module (``@overload``\\ s,
as the kind gates of :mod:`.intersect`) then compile the evaluation of every kind; without it
they compile the checker alone (:func:`checker_color`), so that a scene of plain and
checker colours compiles what it did before the other maps came to numba.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np
from numba.extending import overload

from ...scene.kinds.hypertexture_kernels import value_noise
from .columns import (ENV_IMAGE, ENV_NONE, PROJ_CYLINDRICAL, PROJ_PLANAR, PROJ_SOLID, PROJ_UV, TEX_BRICKS,
                      TEX_CHECKER, TEX_CONSTANT, TEX_GRID, TEX_IMAGE, TEX_MARBLE, TEX_NOISE, Env, Mat, Tex)
from .flags import INLINE, NO_REFCOUNT
from .layout import marker_features
from .shapes import _normalize

TWO_PI = 2.0 * math.pi
OCTAVES = 4
LUMA = (0.2126, 0.7152, 0.0722)
"""Rec. 709 luminance weights (bump heights and opacity of images without alpha)."""
OPACITY_CUT = 0.5
"""Alpha below this cuts the surface out (``workbench.renderers.raytrace.flatten.OPACITY_CUT``)."""


class Textures(NamedTuple):
    """The maps of a scene as the kernels read them (``M`` materials, ``P`` primitive rows)."""

    color: np.ndarray       # (M, TEX_COLS) colour textures (``columns.Tex``; KIND 0: none)
    bump: np.ndarray        # (M, TEX_COLS) bump maps
    opacity: np.ndarray     # (M, TEX_COLS) opacity maps
    env: np.ndarray         # (ENV_COLS,) the environment (``columns.Env``)
    pixels: np.ndarray      # (n,) every image's RGBA values, flat
    has_uv: np.ndarray      # (P,) bool: a mesh row with uvs (else the projections' own mapping)
    marker: np.ndarray      # (0,) structured: its fields name ``maps`` when the scene has more than checkers


def textures_marker(maps: bool) -> np.ndarray:
    """The marker of :class:`Textures`: a field ``maps`` when any map but a planar or solid
    checker is present (a field ``base`` always)."""
    names = ["base"] + (["maps"] if maps else [])
    return np.zeros(0, dtype=np.dtype([(n, np.uint8) for n in names]))


# ----------------------------------------------------------------------------- projections
@nb.njit(**INLINE)
def _wrap01(u):
    u = u - math.floor(u)
    return 0.0 if u >= 1.0 else u


@nb.njit(**INLINE)
def _longitude(tab, mi, dx, dy, dz, zero):
    """``atan2(-d.W, -d.Se) / 2pi`` wrapped to [0, 1), 0 on the axis (``texturing.longitude``)."""
    x = -(dx * tab[mi, Tex.SE] + dy * tab[mi, Tex.SE + 1] + dz * tab[mi, Tex.SE + 2])
    y = -(dx * tab[mi, Tex.W] + dy * tab[mi, Tex.W + 1] + dz * tab[mi, Tex.W + 2])
    if x * x + y * y <= zero * zero * max(1.0, dx * dx + dy * dy + dz * dz):
        return 0.0
    return _wrap01(math.atan2(y, x) / TWO_PI)


@nb.njit(**INLINE)
def project(tab, mi, x, y, z, has_uv, u_mesh, v_mesh, zero):
    """``(u, v)`` of the object-space point under row ``mi``'s projection, before ``scale``
    (``texturing.project``; ``uv`` without mesh uvs: the spherical mapping)."""
    dx, dy, dz = x - tab[mi, Tex.CENTER], y - tab[mi, Tex.CENTER + 1], z - tab[mi, Tex.CENTER + 2]
    proj = tab[mi, Tex.PROJ]
    if proj == PROJ_UV and has_uv:
        return u_mesh, v_mesh
    if proj == PROJ_PLANAR:
        return (dx * tab[mi, Tex.SE] + dy * tab[mi, Tex.SE + 1] + dz * tab[mi, Tex.SE + 2],
                dx * tab[mi, Tex.W] + dy * tab[mi, Tex.W + 1] + dz * tab[mi, Tex.W + 2])
    h = dx * tab[mi, Tex.SP] + dy * tab[mi, Tex.SP + 1] + dz * tab[mi, Tex.SP + 2]
    u = _longitude(tab, mi, dx, dy, dz, zero)
    if proj == PROJ_CYLINDRICAL:
        return u, h
    rx, ry, rz = dx - h * tab[mi, Tex.SP], dy - h * tab[mi, Tex.SP + 1], dz - h * tab[mi, Tex.SP + 2]
    return u, math.atan2(math.sqrt(rx * rx + ry * ry + rz * rz), -h) / math.pi


@nb.njit(**INLINE)
def pattern_coords(tab, mi, x, y, z, has_uv, u_mesh, v_mesh, zero):
    """Pattern coordinates ``s`` (``texturing.pattern_coords``): ``(s0, s1, s2, solid)``,
    ``s2 = 0`` for the 2D projections."""
    sc = tab[mi, Tex.SCALE]
    if tab[mi, Tex.PROJ] == PROJ_SOLID:
        return (sc * (x - tab[mi, Tex.CENTER]), sc * (y - tab[mi, Tex.CENTER + 1]),
                sc * (z - tab[mi, Tex.CENTER + 2]), True)
    u, v = project(tab, mi, x, y, z, has_uv, u_mesh, v_mesh, zero)
    return sc * u, sc * v, 0.0, False


# ----------------------------------------------------------------------------- noise and patterns
@nb.njit(**NO_REFCOUNT)
def fbm(x, y, z):
    """``sum_k (noise(2^k p) - 1/2) / 2^k``, k < 4 (``texturing.fbm``)."""
    out, f = 0.0, 1.0
    for _ in range(OCTAVES):
        out += (value_noise(x * f, y * f, z * f) - 0.5) / f
        f *= 2.0
    return out


@nb.njit(**NO_REFCOUNT)
def turbulence(x, y, z):
    """``sum_k |2 noise(2^k p) - 1| / 2^(k+1)`` (Perlin 1985; ``texturing.turbulence``)."""
    out, f = 0.0, 1.0
    for _ in range(OCTAVES):
        out += abs(2.0 * value_noise(x * f, y * f, z * f) - 1.0) / (2.0 * f)
        f *= 2.0
    return out


@nb.njit(**INLINE)
def smoothstep(e0, e1, x):
    t = min(1.0, max(0.0, (x - e0) / (e1 - e0)))
    return t * t * (3.0 - 2.0 * t)


@nb.njit(**INLINE)
def mortar_distance(s0, s1, s2, solid):
    """Distance to the nearest mortar line centre of the brick layout (bricks 1 x 0.5, odd
    rows shifted by half a brick; solid bricks on ``(x + z, y)``): ``texturing.mortar_distance``."""
    bx = s0 + s2 if solid else s0
    row = math.floor(s1 / 0.5)
    x = bx + 0.5 * (row - 2.0 * math.floor(row / 2.0))
    fx, fy = x - math.floor(x), s1 / 0.5 - row
    return min(min(fx, 1.0 - fx), 0.5 * min(fy, 1.0 - fy))


@nb.njit(**INLINE)
def _grid(s0, s1, width):
    return 1.0 if min(s0 - math.floor(s0), s1 - math.floor(s1)) < width else 0.0


@nb.njit(**INLINE)
def _checker(s0, s1, s2, solid):
    parity = math.floor(s0) + math.floor(s1) + (math.floor(s2) if solid else 0.0)
    return parity - 2.0 * math.floor(parity / 2.0)


@nb.njit(**INLINE)
def checker_color(tab, mi, x, y, z):
    """Texture factor of material ``mi`` at object-space point ``(x, y, z)`` for a ``checker``
    with the ``planar`` (``s = scale (d.Se, d.W)``) or ``solid`` (``s = scale d``) projection,
    ``d = P - center``: the two colours blended by :func:`_checker`.  The whole of
    :func:`texture_color` that a scene whose only maps are such checkers compiles (the path
    tracer's textures, and Whitted's without the ``maps`` feature)."""
    cx, cy, cz = x - tab[mi, Tex.CENTER], y - tab[mi, Tex.CENTER + 1], z - tab[mi, Tex.CENTER + 2]
    sc = tab[mi, Tex.SCALE]
    if tab[mi, Tex.PROJ] == PROJ_PLANAR:
        a = _checker(sc * (cx * tab[mi, Tex.SE] + cy * tab[mi, Tex.SE + 1] + cz * tab[mi, Tex.SE + 2]),
                     sc * (cx * tab[mi, Tex.W] + cy * tab[mi, Tex.W + 1] + cz * tab[mi, Tex.W + 2]), 0.0, False)
    else:
        a = _checker(sc * cx, sc * cy, sc * cz, True)
    return (tab[mi, Tex.COLOR0] * (1.0 - a) + tab[mi, Tex.COLOR1] * a,
            tab[mi, Tex.COLOR0 + 1] * (1.0 - a) + tab[mi, Tex.COLOR1 + 1] * a,
            tab[mi, Tex.COLOR0 + 2] * (1.0 - a) + tab[mi, Tex.COLOR1 + 2] * a)


@nb.njit(**NO_REFCOUNT)
def pattern_value(kind, s0, s1, s2, solid, width):
    """The blend weight of ``colors[1]`` in [0, 1] (``texturing.pattern_value``)."""
    if kind == TEX_CHECKER:
        return _checker(s0, s1, s2, solid)
    if kind == TEX_BRICKS:
        return 1.0 if mortar_distance(s0, s1, s2, solid) < 0.5 * width else 0.0
    if kind == TEX_GRID:
        return _grid(s0, s1, width)
    if kind == TEX_MARBLE:
        return 0.5 + 0.5 * math.sin(TWO_PI * (s0 + 2.0 * turbulence(s0, s1, s2)))
    r = math.hypot(s0, s2) if solid else math.hypot(s0, s1)  # TEX_WOOD
    t = 4.0 * (r + 0.3 * fbm(s0, s1, s2))
    return smoothstep(0.0, 0.8, t - math.floor(t))


# ----------------------------------------------------------------------------- images
@nb.njit(**INLINE)
def _bilerp(pixels, i00, i01, i10, i11, fx, fy):
    a = pixels[i00] * (1.0 - fx) + pixels[i01] * fx
    b = pixels[i10] * (1.0 - fx) + pixels[i11] * fx
    return a * (1.0 - fy) + b * fy


@nb.njit(**NO_REFCOUNT)
def sample_image(pixels, off, w, h, u, v, wrap_v):
    """Bilinear lookup at texel centres (repeat in u; repeat or clamp in v; ``v = 0`` at the
    bottom row) of the RGBA image at ``pixels[off:]``, ``w x h`` (``texturing.sample_image``).
    Returns ``(r, g, b, a)``."""
    x = u * w - 0.5
    y = (1.0 - v) * h - 0.5
    if not wrap_v:
        y = min(max(y, 0.0), h - 1.0)
    fx0, fy0 = math.floor(x), math.floor(y)
    fx, fy = x - fx0, y - fy0
    x0, y0 = np.int64(fx0), np.int64(fy0)
    xs0, xs1 = x0 % w, (x0 + 1) % w
    if wrap_v:
        ys0, ys1 = y0 % h, (y0 + 1) % h
    else:
        ys0, ys1 = min(max(y0, 0), h - 1), min(max(y0 + 1, 0), h - 1)
    i00, i01 = off + (ys0 * w + xs0) * 4, off + (ys0 * w + xs1) * 4
    i10, i11 = off + (ys1 * w + xs0) * 4, off + (ys1 * w + xs1) * 4
    return (_bilerp(pixels, i00, i01, i10, i11, fx, fy), _bilerp(pixels, i00 + 1, i01 + 1, i10 + 1, i11 + 1, fx, fy),
            _bilerp(pixels, i00 + 2, i01 + 2, i10 + 2, i11 + 2, fx, fy),
            _bilerp(pixels, i00 + 3, i01 + 3, i10 + 3, i11 + 3, fx, fy))


@nb.njit(**INLINE)
def _image_at(tx, tab, mi, k, x, y, z, u_mesh, v_mesh, zero):
    """Row ``mi``'s image at the object-space point (projection times ``scale``)."""
    u, v = project(tab, mi, x, y, z, tx.has_uv[k], u_mesh, v_mesh, zero)
    sc = tab[mi, Tex.SCALE]
    return sample_image(tx.pixels, int(tab[mi, Tex.IMAGE]), int(tab[mi, Tex.IMAGE_W]), int(tab[mi, Tex.IMAGE_H]),
                        u * sc, v * sc, True)


# ----------------------------------------------------------------------------- the maps
@nb.njit(**NO_REFCOUNT)
def texture_color(tx, mi, k, x, y, z, u_mesh, v_mesh):
    """The colour texture's RGB of material ``mi`` at an object-space point of row ``k``
    (before the material colour; ``texturing.texture_color``)."""
    tab, zero = tx.color, tx.env[Env.ZERO]
    kind = tab[mi, Tex.KIND]
    if kind == TEX_IMAGE:
        r, g, b, _ = _image_at(tx, tab, mi, k, x, y, z, u_mesh, v_mesh, zero)
        return r, g, b
    s0, s1, s2, solid = pattern_coords(tab, mi, x, y, z, tx.has_uv[k], u_mesh, v_mesh, zero)
    t = pattern_value(kind, s0, s1, s2, solid, tab[mi, Tex.WIDTH])
    return (tab[mi, Tex.COLOR0] * (1.0 - t) + tab[mi, Tex.COLOR1] * t,
            tab[mi, Tex.COLOR0 + 1] * (1.0 - t) + tab[mi, Tex.COLOR1 + 1] * t,
            tab[mi, Tex.COLOR0 + 2] * (1.0 - t) + tab[mi, Tex.COLOR1 + 2] * t)


@nb.njit(**NO_REFCOUNT)
def height(tx, mi, x, y, z):
    """Height in [0, 1] of material ``mi``'s bump map at an object-space point
    (``texturing.height``, without mesh uvs, as ``bump_normal`` calls it)."""
    tab, zero = tx.bump, tx.env[Env.ZERO]
    kind = tab[mi, Tex.KIND]
    if kind == TEX_IMAGE:
        u, v = project(tab, mi, x, y, z, False, 0.0, 0.0, zero)
        sc = tab[mi, Tex.SCALE]
        r, g, b, _ = sample_image(tx.pixels, int(tab[mi, Tex.IMAGE]), int(tab[mi, Tex.IMAGE_W]),
                                  int(tab[mi, Tex.IMAGE_H]), u * sc, v * sc, True)
        return r * LUMA[0] + g * LUMA[1] + b * LUMA[2]
    s0, s1, s2, solid = pattern_coords(tab, mi, x, y, z, False, 0.0, 0.0, zero)
    if kind == TEX_BRICKS:
        hw = 0.5 * tab[mi, Tex.WIDTH]
        return smoothstep(0.5 * hw, 1.5 * hw, mortar_distance(s0, s1, s2, solid))
    if kind == TEX_NOISE:
        return 0.5 + fbm(s0, s1, s2)
    return 0.5 + 0.25 * (math.sin(TWO_PI * s0) + math.sin(TWO_PI * s1))  # TEX_WAVES


@nb.njit(**NO_REFCOUNT)
def bump_normal(tx, xf, mi, k, x, y, z, has_uv, nx, ny, nz):
    """Material ``mi``'s bumped world-space unit normal at a hit of row ``k`` (Blinn 1978 in
    Mikkelsen's surface-gradient form; ``texturing.bump_normal``): the object-space gradient
    of ``d = strength h / scale`` by forward differences of step ``bump_step / scale``, taken
    to world space by ``M^-T`` (``xf``: row ``k``'s ``object_from_world``, whose linear part is
    ``M^-1``), ``N' = normalize(N - (g - (g.N) N))``.  ``N`` unbumped with the ``uv``
    projection on a mesh with uvs."""
    nx, ny, nz = _normalize(nx, ny, nz)
    tab = tx.bump
    if tab[mi, Tex.PROJ] == PROJ_UV and has_uv:
        return nx, ny, nz
    sc = tab[mi, Tex.SCALE]
    delta = tx.env[Env.BUMP_STEP] / sc
    f = tab[mi, Tex.STRENGTH] / sc
    h0 = height(tx, mi, x, y, z)
    g0 = (height(tx, mi, x + delta, y, z) - h0) / delta * f
    g1 = (height(tx, mi, x, y + delta, z) - h0) / delta * f
    g2 = (height(tx, mi, x, y, z + delta) - h0) / delta * f
    gx = g0 * xf[k, 0] + g1 * xf[k, 4] + g2 * xf[k, 8]
    gy = g0 * xf[k, 1] + g1 * xf[k, 5] + g2 * xf[k, 9]
    gz = g0 * xf[k, 2] + g1 * xf[k, 6] + g2 * xf[k, 10]
    gn = gx * nx + gy * ny + gz * nz
    px, py, pz = nx - (gx - gn * nx), ny - (gy - gn * ny), nz - (gz - gn * nz)
    if px * px + py * py + pz * pz > 0.0:
        return _normalize(px, py, pz)
    return nx, ny, nz


@nb.njit(**NO_REFCOUNT)
def alpha(tx, mi, k, x, y, z, u_mesh, v_mesh):
    """Opacity in [0, 1] of material ``mi``'s opacity map at an object-space point of row
    ``k`` (``texturing.alpha``; 1 without a map)."""
    tab, zero = tx.opacity, tx.env[Env.ZERO]
    kind = tab[mi, Tex.KIND]
    if kind == TEX_CONSTANT:
        return tab[mi, Tex.VALUE]
    if kind == TEX_IMAGE:
        r, g, b, a = _image_at(tx, tab, mi, k, x, y, z, u_mesh, v_mesh, zero)
        return a if tab[mi, Tex.ALPHA] > 0.5 else r * LUMA[0] + g * LUMA[1] + b * LUMA[2]
    s0, s1, s2, solid = pattern_coords(tab, mi, x, y, z, tx.has_uv[k], u_mesh, v_mesh, zero)
    if kind == TEX_GRID:
        return _grid(s0, s1, tab[mi, Tex.WIDTH])
    if kind == TEX_CHECKER:
        return 1.0 - _checker(s0, s1, s2, solid)
    return 1.0


@nb.njit(**NO_REFCOUNT)
def environment(tx, dx, dy, dz, background):
    """Radiance seen in the world direction ``d`` (``texturing.environment``: the sky's
    gradient, or a bilinear lookup in a lat-long image, ``texturing.latlong_uv``), or the
    background colour when the scene has no environment.  Returns ``(r, g, b)``."""
    env = tx.env
    kind = env[Env.KIND]
    if kind == ENV_NONE:
        return background[0], background[1], background[2]
    dx, dy, dz = _normalize(dx, dy, dz)
    if kind == ENV_IMAGE:
        zero = env[Env.ZERO]
        if dx * dx + dz * dz <= zero * zero:
            u = 0.5
        else:
            u = 0.5 + math.atan2(dx, -dz) / TWO_PI
        v = 0.5 + math.asin(min(1.0, max(-1.0, dy))) / math.pi
        r, g, b, _ = sample_image(tx.pixels, int(env[Env.IMAGE]), int(env[Env.IMAGE_W]), int(env[Env.IMAGE_H]),
                                  _wrap01(u), v, False)
        return r, g, b
    if dy >= 0.0:
        c, e = Env.ZENITH, min(1.0, dy)
    else:
        c, e = Env.GROUND, min(1.0, -4.0 * dy)
    return (env[Env.HORIZON] + (env[c] - env[Env.HORIZON]) * e,
            env[Env.HORIZON + 1] + (env[c + 1] - env[Env.HORIZON + 1]) * e,
            env[Env.HORIZON + 2] + (env[c + 2] - env[Env.HORIZON + 2]) * e)


# ----------------------------------------------------------------------------- gates
def has_maps(tx) -> bool:
    """Whether a :class:`Textures` record's marker (the record's numba type, at typing time)
    names ``maps``."""
    return "maps" in marker_features(tx.types[-1])


def surface_maps(tx, mat_tab, mi, k, xf, po, uv, ns, col):
    """Colour and shading normal of a hit of row ``k`` (material ``mi``): ``col[0]`` the
    material colour times its texture (set for a textured material), ``ns[0]`` bumped (for a
    bump-mapped one); ``po``, ``uv``: the hit's object-space point and mesh uv (row 0)."""
    raise TypeError("surface_maps is callable from numba-compiled code only")


@overload(surface_maps, jit_options=INLINE)
def _surface_maps(tx, mat_tab, mi, k, xf, po, uv, ns, col):
    on = has_maps(tx)

    def impl(tx, mat_tab, mi, k, xf, po, uv, ns, col):
        if mat_tab[mi, Mat.TEXTURED] > 0.5:
            if on:
                r, g, b = texture_color(tx, mi, k, po[0, 0], po[0, 1], po[0, 2], uv[0, 0], uv[0, 1])
            else:
                r, g, b = checker_color(tx.color, mi, po[0, 0], po[0, 1], po[0, 2])
            col[0, 0] = mat_tab[mi, Mat.COLOR] * r
            col[0, 1] = mat_tab[mi, Mat.COLOR + 1] * g
            col[0, 2] = mat_tab[mi, Mat.COLOR + 2] * b
        if on and mat_tab[mi, Mat.BUMPED] > 0.5:
            ns[0, 0], ns[0, 1], ns[0, 2] = bump_normal(tx, xf, mi, k, po[0, 0], po[0, 1], po[0, 2], tx.has_uv[k],
                                                       ns[0, 0], ns[0, 1], ns[0, 2])
    return impl


def hit_alpha(tx, mat_tab, mi, k, po, uv):
    """Opacity of a hit (0 where cut out, below :data:`OPACITY_CUT`; 1 without an opacity map,
    and always 1 in a scene without maps)."""
    raise TypeError("hit_alpha is callable from numba-compiled code only")


@overload(hit_alpha, jit_options=INLINE)
def _hit_alpha(tx, mat_tab, mi, k, po, uv):
    on = has_maps(tx)

    def impl(tx, mat_tab, mi, k, po, uv):
        if on and mat_tab[mi, Mat.OPACITY] > 0.5:
            a = alpha(tx, mi, k, po[0, 0], po[0, 1], po[0, 2], uv[0, 0], uv[0, 1])
            return a if a >= OPACITY_CUT else 0.0
        return 1.0
    return impl


def miss_radiance(tx, dx, dy, dz, background, out):
    """``out[:]``: what a ray of direction ``d`` leaving the scene sees (the environment, or
    ``background``)."""
    raise TypeError("miss_radiance is callable from numba-compiled code only")


@overload(miss_radiance, jit_options=INLINE)
def _miss_radiance(tx, dx, dy, dz, background, out):
    on = has_maps(tx)

    def impl(tx, dx, dy, dz, background, out):
        if on:
            out[0], out[1], out[2] = environment(tx, dx, dy, dz, background)
        else:
            out[0], out[1], out[2] = background[0], background[1], background[2]
    return impl
