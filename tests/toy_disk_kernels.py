"""Numba kernels of the toy ``disk`` kind (``toy_disk``): the three roles the kernels'
dispatch calls (signatures: ``workbench.scene.kinds.crossing_events``)."""
from __future__ import annotations

import numba as nb
import numpy as np

from toy_disk import Par
from workbench.renderers.kernels.flags import NO_REFCOUNT


@nb.njit(**NO_REFCOUNT)
def first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax``: ``(t, 0)``, ``(inf, 0)`` on a miss."""
    if dy == 0.0:
        return np.inf, 0
    t = -oy / dy
    x, z = ox + t * dx, oz + t * dz
    if tmin < t < tmax and x * x + z * z <= par[k, Par.RADIUS] * par[k, Par.RADIUS]:
        return t, 0
    return np.inf, 0


@nb.njit(**NO_REFCOUNT)
def events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    """A sheet has no inside: no interval."""
    return 0


@nb.njit(**NO_REFCOUNT)
def normal(par, k, aux, face, x, y, z, stack):
    return 0.0, 1.0, 0.0
