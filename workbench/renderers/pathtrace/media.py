"""The path tracer in heterogeneous media (hypertextures): the transmittance of a shadow ray
(ratio tracking through each medium it crosses, :func:`..kernels.media.ratio`) and the
vertex of a real collision inside a medium (next-event estimation with the isotropic phase
function ``1 / 4 pi`` and a new direction drawn from it).  :func:`.kernels.trace_path` calls
them through :func:`shadow_gate` and :func:`vertex_gate`, which compile to constants for a
scene without a medium (as the gates of :mod:`..kernels.media`); the delta tracking itself is
:func:`..kernels.media.track`.  The free-flight and collision estimators: Novák et al., "Monte
Carlo methods for volumetric light transport simulation", CGF 2018."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from numba.extending import overload

from ..kernels.columns import Light, Mat, PathCount, PathOpt
from ..kernels.flags import GATE, NO_REFCOUNT
from ..kernels.intersect import closest
from ..kernels.media import medium_kinds, ratio
from ..kernels.optics import _light_dir
from ..kernels.rng import rand
from .sampling import mis_weight, sample_emitter

INV_4PI = 0.25 / math.pi
SHADOW_CROSSINGS = 16
"""Medium boundaries a shadow ray goes on through before it counts as blocked."""


@nb.njit(**NO_REFCOUNT)
def shadow_transmittance(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, key, mdim, scr):
    """Transmittance of the segment ``o + t d``, ``tmin < t < tmax``: 0 at any surface but a
    medium's boundary, else the product of ratio-tracking estimates over each medium's chord
    (each medium once; at most four).  Returns ``(T, next mdim)``."""
    stack, st, sp_, sf, sn = scr
    v = 1.0
    t0 = tmin
    m0, m1, m2, m3 = -1, -1, -1, -1
    for _ in range(SHADOW_CROSSINGS):
        t, k, f, tri, b1, b2, _, _, _ = closest(geo, ox, oy, oz, dx, dy, dz, t0, tmax, np.bool_(True), np.bool_(False),
                                       np.bool_(False), zero, eps, stack, st, sp_, sf, sn)
        if k < 0:
            return v, mdim
        med = int(mat_tab[mat_of[k], Mat.MEDIUM])
        if med < 0:
            return 0.0, mdim
        if med != m0 and med != m1 and med != m2 and med != m3:
            m0, m1, m2, m3 = med, m0, m1, m2
            tr, mdim = ratio(geo, med, ox, oy, oz, dx, dy, dz, tmin, tmax, key, mdim)
            v *= tr
            if v <= 0.0:
                return 0.0, mdim
        t0 = t + eps
    return 0.0, mdim


@nb.njit(**NO_REFCOUNT)
def medium_vertex(geo, shading, emitters, opts, key, dim, mdim, px, py, pz, br, bg_, bb, counts, scr):
    """A real scattering collision at ``p`` with path throughput ``beta`` (albedo applied):
    next-event estimation to one emitter triangle (MIS against the phase function) and to every
    point or directional light, then a direction drawn from the isotropic phase function (its
    weight ``phase / pdf`` is 1).  Random dimensions ``dim .. dim + 4`` of the path's stream.
    Returns ``(L r, g, b, new direction, next mdim)``."""
    mat_of, mat_tab, tex_tab, lights = shading
    em_cdf = emitters[4]
    beta_mis = opts[PathOpt.MIS_BETA]
    zero = opts[PathOpt.ZERO]
    off = opts[PathOpt.RAY_OFFSET] * max(max(abs(px), abs(py), abs(pz)), opts[PathOpt.EXTENT])
    tri_e = geo.tri_e
    lr, lg, lb = 0.0, 0.0, 0.0
    if em_cdf.shape[0] > 0:
        qx, qy, qz, lx, ly, lz, dist, cos_l, ler, leg, leb, p_l = sample_emitter(
            emitters, mat_of, mat_tab, tri_e, key, dim, px, py, pz, 0)
        if dist > 2.0 * off and (ler > 0.0 or leg > 0.0 or leb > 0.0) and p_l > 0.0:
            counts[PathCount.SHADOW_RAYS] += 1
            vis, mdim = shadow_transmittance(geo, mat_of, mat_tab, px, py, pz, lx, ly, lz, 0.0, dist - 2.0 * off,
                                             zero, off, key, mdim, scr)
            wl = vis * mis_weight(p_l, INV_4PI, beta_mis) * INV_4PI / p_l
            lr, lg, lb = lr + br * ler * wl, lg + bg_ * leg * wl, lb + bb * leb * wl
    for li in range(lights.shape[0]):
        lx, ly, lz, dist, sc = _light_dir(lights, li, px, py, pz)
        if sc == 0.0:
            continue
        counts[PathCount.SHADOW_RAYS] += 1
        vis, mdim = shadow_transmittance(geo, mat_of, mat_tab, px, py, pz, lx, ly, lz, 0.0, dist, zero, off,
                                         key, mdim, scr)
        # radiance scattered: phase (1 / 4 pi) times the light's irradiance pi sc P (as at a surface)
        f = 0.25 * sc * vis
        lr += br * lights[li, Light.POWER] * f
        lg += bg_ * lights[li, Light.POWER + 1] * f
        lb += bb * lights[li, Light.POWER + 2] * f
    z = 1.0 - 2.0 * rand(key, dim + 3)
    r = math.sqrt(max(0.0, 1.0 - z * z))
    phi = 2.0 * math.pi * rand(key, dim + 4)
    return lr, lg, lb, r * math.cos(phi), r * math.sin(phi), z, mdim


def shadow_gate(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, key, mdim, scr):
    """:func:`shadow_transmittance` for a scene with a medium; ``(1, mdim)`` otherwise (never
    reached: the caller asks ``PathOpt.HAS_MEDIA`` first)."""
    raise TypeError("shadow_gate is callable from numba-compiled code only")


@overload(shadow_gate, jit_options=GATE)
def _shadow_gate(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, key, mdim, scr):
    on = bool(medium_kinds(geo.types[-1]))

    def impl(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, key, mdim, scr):
        if on:
            return shadow_transmittance(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmin, tmax, zero, eps, key,
                                        mdim, scr)
        return 1.0, mdim
    return impl


def vertex_gate(geo, shading, emitters, opts, key, dim, mdim, px, py, pz, br, bg_, bb, counts, scr):
    """:func:`medium_vertex` for a scene with a medium; nothing otherwise (never reached)."""
    raise TypeError("vertex_gate is callable from numba-compiled code only")


@overload(vertex_gate, jit_options=GATE)
def _vertex_gate(geo, shading, emitters, opts, key, dim, mdim, px, py, pz, br, bg_, bb, counts, scr):
    on = bool(medium_kinds(geo.types[-1]))

    def impl(geo, shading, emitters, opts, key, dim, mdim, px, py, pz, br, bg_, bb, counts, scr):
        if on:
            return medium_vertex(geo, shading, emitters, opts, key, dim, mdim, px, py, pz, br, bg_, bb, counts, scr)
        return 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, mdim
    return impl
