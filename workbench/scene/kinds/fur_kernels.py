"""Numba kernels of the ``fur`` kind (:mod:`.fur`, whose module docstring gives the texel):
the shell's bounding sphere for the ray tracer's dispatch (as the hypertexture's), its optics
for the path tracer's tracking, and its texel (density, tangent, Kajiya-Kay coefficients) for
the march of the ray caster and the Whitted tracer (:mod:`workbench.renderers.kernels.media`)."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .fur import Par
from .hypertexture_kernels import _hash3
from . import medium_sphere

JIT = dict(cache=True, error_model="numpy", **INTERNAL)


@nb.njit(**JIT)
def _project(par, k, x, y, z):
    """(signed distance, foot point) of an object-space point outside or on the base."""
    if par[k, Par.BASE] == 0.0:
        r = math.sqrt(x * x + y * y + z * z)
        a = par[k, Par.SIZE] / max(r, 1e-300)
        return r - par[k, Par.SIZE], x * a, y * a, z * a
    bx, by, bz = par[k, Par.SIZE], par[k, Par.SIZE + 1], par[k, Par.SIZE + 2]
    qx, qy, qz = abs(x) - bx, abs(y) - by, abs(z) - bz
    ox, oy, oz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
    s = math.sqrt(ox * ox + oy * oy + oz * oz) + min(max(qx, qy, qz), 0.0)
    return s, min(max(x, -bx), bx), min(max(y, -by), by), min(max(z, -bz), bz)


@nb.njit(**JIT)
def texel(par, k, x, y, z):
    """``(D, tangent)`` at an object-space point: the strand density (0 or 1) and the base's
    outward normal at the foot point (unit; zero where D = 0)."""
    s, fx, fy, fz = _project(par, k, x, y, z)
    L = par[k, Par.LENGTH]
    if s < 0.0 or s > L:
        return 0.0, 0.0, 0.0, 0.0
    c = par[k, Par.CELL]
    r_max = par[k, Par.THICKNESS] * (1.0 - s / L)
    ix, iy, iz = np.int64(math.floor(fx / c)), np.int64(math.floor(fy / c)), np.int64(math.floor(fz / c))
    best = np.inf
    for a in range(-1, 2):
        for b in range(-1, 2):
            for e in range(-1, 2):
                cx, cy, cz = ix + a, iy + b, iz + e
                px = (cx + _hash3(cx, cy, cz)) * c
                py = (cy + _hash3(cx + 1013, cy, cz)) * c
                pz = (cz + _hash3(cx, cy + 2027, cz)) * c
                _, rx, ry, rz = _project(par, k, px, py, pz)
                d = math.sqrt((fx - rx) ** 2 + (fy - ry) ** 2 + (fz - rz) ** 2)
                best = min(best, d)
    if not best < r_max:
        return 0.0, 0.0, 0.0, 0.0
    nx, ny, nz = x - fx, y - fy, z - fz
    n = math.sqrt(nx * nx + ny * ny + nz * nz)
    if n == 0.0:
        return 1.0, 0.0, 0.0, 0.0
    return 1.0, nx / n, ny / n, nz / n


@nb.njit(**JIT)
def optics(par, k, aux, x, y, z):
    """For the path tracer: ``(sigma_t, albedo kd C, no emission)``."""
    d, _, _, _ = texel(par, k, x, y, z)
    if d <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    kd = par[k, Par.KD]
    return (par[k, Par.DENSITY] * d, kd * par[k, Par.COLOR], kd * par[k, Par.COLOR + 1], kd * par[k, Par.COLOR + 2],
            0.0, 0.0, 0.0)


@nb.njit(**JIT)
def kajiya_kay(par, k, tx, ty, tz, lx, ly, lz, dx, dy, dz):
    """Per unit light: ``(sin(T, L), specular ks max(0, cos phi)^shininess)`` (the diffuse lobe
    is the albedo ``kd C`` times the first) with
    ``cos phi = (T.L)(T.d) + sin(T, L) sin(T, d)`` (Kajiya and Kay 1989; ``d`` the ray's
    direction, so the highlight lies on the cone of mirror directions about the strand)."""
    tl = tx * lx + ty * ly + tz * lz
    td = tx * dx + ty * dy + tz * dz
    sl = math.sqrt(max(0.0, 1.0 - tl * tl))
    sd = math.sqrt(max(0.0, 1.0 - td * td))
    c = tl * td + sl * sd
    spec = par[k, Par.KS] * max(0.0, c) ** par[k, Par.SHININESS] if c > 0.0 else 0.0
    return sl, spec


@nb.njit(**JIT)
def step(par, k):
    return par[k, Par.STEP]


@nb.njit(**JIT)
def majorant(par, k):
    return par[k, Par.DENSITY]


# its row of the ray tracer's table: the bounding sphere (.medium_sphere)
first, events, normal, inside, chord = (medium_sphere.first, medium_sphere.events, medium_sphere.normal,
                                        medium_sphere.inside, medium_sphere.chord)
