"""3D value noise (lattice hashes blended with quintic weights), shared by the textures
(:mod:`workbench.renderers.texturing`, ``shaders/include/texturing.glsl``) and the
hypertextures (:mod:`workbench.scene.kinds.hypertexture`): the numpy definition (the numba twin is
:func:`workbench.scene.kinds.hypertexture_kernels.value_noise`, tested against it).

The hash is lowbias32 (C. Wellons, "Prospecting for hash functions", 2018) of the lattice
point's three coordinates mixed by large primes, in uint32 arithmetic that wraps like GLSL's
``uint``.
"""
from __future__ import annotations

import numpy as np


def _hash3(ix: np.ndarray, iy: np.ndarray, iz: np.ndarray) -> np.ndarray:
    """lowbias32 of the lattice point (uint32 arithmetic, wraps like GLSL ``uint``), in [0, 1)."""
    u = lambda a: (np.asarray(a, dtype=np.int64) & 0xFFFFFFFF).astype(np.uint32)
    with np.errstate(over="ignore"):
        h = (u(ix) * np.uint32(73856093)) ^ (u(iy) * np.uint32(19349663)) ^ (u(iz) * np.uint32(83492791))
        h ^= h >> np.uint32(16)
        h *= np.uint32(0x7FEB352D)
        h ^= h >> np.uint32(15)
        h *= np.uint32(0x846CA68B)
        h ^= h >> np.uint32(16)
    return (h >> np.uint32(8)).astype(np.float64) / 16777216.0


def _quintic(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def value_noise(p: np.ndarray) -> np.ndarray:
    """3D value noise in [0, 1) at points p (N, 3) (trilinear blend of lattice hashes with
    quintic weights).  (N,)"""
    p = np.asarray(p, dtype=np.float64)
    i = np.floor(p)
    f = p - i
    i = i.astype(np.int64)
    wx, wy, wz = (_quintic(f[:, k]) for k in range(3))
    out = np.zeros(len(p))
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                wgt = (wx if dx else 1 - wx) * (wy if dy else 1 - wy) * (wz if dz else 1 - wz)
                out += wgt * _hash3(i[:, 0] + dx, i[:, 1] + dy, i[:, 2] + dz)
    return out
