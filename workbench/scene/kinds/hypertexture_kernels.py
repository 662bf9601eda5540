"""Numba kernels of the ``hypertexture`` kind (:mod:`.hypertexture`, whose module docstring gives
the field): the bounding sphere's entry points for the ray tracer's dispatch (signatures:
:mod:`.crossing_events`) and the medium's optics at a point (:func:`optics`), which the
renderers' marches and trackers call.  Apart from the kind so that reading a scene does not
import numba."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .hypertexture import AUX_ALBEDO, AUX_EMISSION, AUX_STOPS, Par
from . import medium_sphere

JIT = dict(cache=True, error_model="numpy", **INTERNAL)
_M32 = np.uint64(0xFFFFFFFF)


@nb.njit(**JIT)
def _hash3(ix, iy, iz):
    """:func:`workbench.core.noise._hash3` of one lattice point (int64 coordinates), in [0, 1)."""
    m = _M32
    h = (((np.uint64(ix & 0xFFFFFFFF) * np.uint64(73856093)) & m)
         ^ ((np.uint64(iy & 0xFFFFFFFF) * np.uint64(19349663)) & m)
         ^ ((np.uint64(iz & 0xFFFFFFFF) * np.uint64(83492791)) & m))
    h ^= h >> np.uint64(16)
    h = (h * np.uint64(0x7FEB352D)) & m
    h ^= h >> np.uint64(15)
    h = (h * np.uint64(0x846CA68B)) & m
    h ^= h >> np.uint64(16)
    return float(h >> np.uint64(8)) / 16777216.0


@nb.njit(**JIT)
def value_noise(x, y, z):
    """:func:`workbench.core.noise.value_noise` at one point."""
    fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
    ix, iy, iz = np.int64(fx), np.int64(fy), np.int64(fz)
    tx, ty, tz = x - fx, y - fy, z - fz
    wx = tx * tx * tx * (tx * (tx * 6.0 - 15.0) + 10.0)
    wy = ty * ty * ty * (ty * (ty * 6.0 - 15.0) + 10.0)
    wz = tz * tz * tz * (tz * (tz * 6.0 - 15.0) + 10.0)
    out = 0.0
    for dx in range(2):
        for dy in range(2):
            for dz in range(2):
                w = (wx if dx else 1.0 - wx) * (wy if dy else 1.0 - wy) * (wz if dz else 1.0 - wz)
                out += w * _hash3(ix + dx, iy + dy, iz + dz)
    return out


@nb.njit(**JIT)
def _signed_distance(par, k, x, y, z):
    base = int(par[k, Par.BASE])
    a, b, c = par[k, Par.SIZE], par[k, Par.SIZE + 1], par[k, Par.SIZE + 2]
    if base == 0:
        return math.sqrt(x * x + y * y + z * z) - a
    if base == 1:
        qx, qy, qz = abs(x) - a, abs(y) - b, abs(z) - c
        ox, oy, oz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
        return math.sqrt(ox * ox + oy * oy + oz * oz) + min(max(qx, qy, qz), 0.0)
    ring = math.sqrt(x * x + z * z) - a
    return math.sqrt(ring * ring + y * y) - b


@nb.njit(**JIT)
def _noise(par, k, x, y, z):
    kind = int(par[k, Par.NOISE])
    if kind == 0:
        return 0.0
    f = par[k, Par.FREQUENCY]
    qx, qy, qz = x * f + par[k, Par.PHASE], y * f + par[k, Par.PHASE + 1], z * f + par[k, Par.PHASE + 2]
    out = 0.0
    s = 1.0
    for _ in range(int(par[k, Par.OCTAVES])):
        v = value_noise(qx * s, qy * s, qz * s)
        if kind == 1:
            out += abs(2.0 * v - 1.0) / (2.0 * s)
        else:
            out += (v - 0.5) / s
        s *= 2.0
    return out - 0.5 if kind == 1 else out


@nb.njit(**JIT)
def _grid(par, k, aux, x, y, z):
    """Trilinear sample of the object's grid (:func:`.hypertexture.sample_grid`)."""
    res = int(par[k, Par.GRID])
    R = par[k, Par.BOUND]
    g0 = int(par[k, Par.OFFSET]) + AUX_STOPS + 4 * int(par[k, Par.STOPS])
    sc = res / (2.0 * R)
    u = min(max((x + R) * sc - 0.5, 0.0), res - 1.0)
    v = min(max((y + R) * sc - 0.5, 0.0), res - 1.0)
    w = min(max((z + R) * sc - 0.5, 0.0), res - 1.0)
    i, j, l = min(int(u), res - 2), min(int(v), res - 2), min(int(w), res - 2)
    fu, fv, fw = u - i, v - j, w - l
    out = 0.0
    for dz in range(2):
        for dy in range(2):
            for dx in range(2):
                wt = (fu if dx else 1.0 - fu) * (fv if dy else 1.0 - fv) * (fw if dz else 1.0 - fw)
                out += wt * aux[g0 + ((l + dz) * res + j + dy) * res + i + dx]
    return out


@nb.njit(**JIT)
def density(par, k, aux, x, y, z):
    """``D`` in [0, 1] at an object-space point (the kind's module docstring; the grid's, when
    the object has one)."""
    if par[k, Par.GRID] > 0.0:
        return _grid(par, k, aux, x, y, z)
    soft = par[k, Par.SOFT]
    s = _signed_distance(par, k, x, y, z) - par[k, Par.AMPLITUDE] * soft * _noise(par, k, x, y, z)
    d = min(1.0, max(0.0, 0.5 - s / soft))
    if d <= 0.0:
        return 0.0
    d = d ** par[k, Par.BIAS]
    e = par[k, Par.GAIN]
    if d < 0.5:
        return 0.5 * (2.0 * d) ** e
    return 1.0 - 0.5 * max(2.0 - 2.0 * d, 0.0) ** e


@nb.njit(**JIT)
def optics(par, k, aux, x, y, z):
    """At an object-space point: ``(sigma_t, albedo r, g, b, emission r, g, b)``, extinction per
    object-space unit, single-scattering albedo and emitted radiance (the ramp applied)."""
    d = density(par, k, aux, x, y, z)
    if d <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    off = int(par[k, Par.OFFSET])
    n = int(par[k, Par.STOPS])
    s0 = off + AUX_STOPS
    cr, cg, cb = aux[s0 + 1], aux[s0 + 2], aux[s0 + 3]
    if d >= aux[s0 + 4 * (n - 1)]:
        j = s0 + 4 * (n - 1)
        cr, cg, cb = aux[j + 1], aux[j + 2], aux[j + 3]
    elif d > aux[s0]:
        for i in range(n - 1):
            j = s0 + 4 * i
            d0, d1 = aux[j], aux[j + 4]
            if d0 <= d <= d1:
                u = (d - d0) / (d1 - d0) if d1 > d0 else 1.0
                cr = aux[j + 1] + u * (aux[j + 5] - aux[j + 1])
                cg = aux[j + 2] + u * (aux[j + 6] - aux[j + 2])
                cb = aux[j + 3] + u * (aux[j + 7] - aux[j + 3])
                break
    a, e = off + AUX_ALBEDO, off + AUX_EMISSION
    return (par[k, Par.DENSITY] * d, aux[a] * cr, aux[a + 1] * cg, aux[a + 2] * cb,
            aux[e] * cr, aux[e + 1] * cg, aux[e + 2] * cb)


@nb.njit(**JIT)
def step(par, k):
    """The march's step (object-space length)."""
    return par[k, Par.STEP]


@nb.njit(**JIT)
def majorant(par, k):
    """An upper bound of ``sigma_t`` over the medium (D <= 1)."""
    return par[k, Par.DENSITY]


# its row of the ray tracer's table: the bounding sphere (.medium_sphere)
first, events, normal, inside, chord = (medium_sphere.first, medium_sphere.events, medium_sphere.normal,
                                        medium_sphere.inside, medium_sphere.chord)
