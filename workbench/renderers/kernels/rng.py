"""The path tracer's random numbers: a counter-based stream per path (SplitMix64's finaliser
as the hash), so any path's numbers are reproducible from (seed, pixel, sample) alone and the
sample loop can be split between threads in any order."""
from __future__ import annotations

import numba as nb
import numpy as np

from .flags import INLINE

_G = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)


@nb.njit(**INLINE)
def _mix(z):
    """SplitMix64's finaliser (Steele, Lea & Flood, OOPSLA 2014): a bijective 64-bit hash."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@nb.njit(**INLINE)
def path_key(seed, pixel, sample):
    """The random stream of one path: a hash of (seed, pixel, sample index)."""
    return _mix(_mix(_mix(np.uint64(seed) + _G) + np.uint64(pixel)) + np.uint64(sample))


@nb.njit(**INLINE)
def rand(key, dim):
    """Uniform in [0, 1): dimension ``dim`` of the stream ``key`` (53 bits)."""
    return float(_mix(key + np.uint64(dim) * _G) >> _S11) * (1.0 / 9007199254740992.0)


