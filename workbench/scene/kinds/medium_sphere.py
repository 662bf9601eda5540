"""The bounding sphere of a medium kind (``MEDIUM = True``: the hypertexture, the fur): the
ray tracer's entry points of its row (signatures: :mod:`.crossing_events`) and its chord,
shared by the medium kinds, whose ``Par`` keeps the sphere's radius in column
:data:`.aux_rows.MEDIUM_BOUND`."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...core.jit_options import INTERNAL
from .aux_rows import MEDIUM_BOUND as BOUND
JIT = dict(cache=True, error_model="numpy", **INTERNAL)


@nb.njit(**JIT)
def sphere_chord(r, ox, oy, oz, dx, dy, dz):
    """Both t of the object-space line with the sphere of radius ``r`` about the origin
    (t0 <= t1), or (inf, inf) (the stable form of :func:`.sphere.roots`)."""
    s = math.sqrt(dx * dx + dy * dy + dz * dz)
    ux, uy, uz = dx / s, dy / s, dz / s
    b = ox * ux + oy * uy + oz * uz
    px, py, pz = ox - b * ux, oy - b * uy, oz - b * uz
    disc = r * r - (px * px + py * py + pz * pz)
    if not disc > 0.0:
        return np.inf, np.inf
    sq = math.sqrt(disc)
    q = -b - sq if b >= 0.0 else -b + sq
    no = math.sqrt(ox * ox + oy * oy + oz * oz)
    c = (no - r) * (no + r)
    t0 = c / q if q != 0.0 else -sq
    t0, t1 = min(t0, q), max(t0, q)
    return t0 / s, t1 / s


@nb.njit(**JIT)
def chord(par, k, ox, oy, oz, dx, dy, dz):
    """Both t of the object-space line with row ``k``'s bounding sphere, or (inf, inf)."""
    return sphere_chord(par[k, BOUND], ox, oy, oz, dx, dy, dz)


@nb.njit(**JIT)
def first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    t0, t1 = chord(par, k, ox, oy, oz, dx, dy, dz)
    if tmin < t0 < tmax:
        return t0, 0
    if tmin < t1 < tmax:
        return t1, 0
    return np.inf, 0


@nb.njit(**JIT)
def events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    t0, t1 = chord(par, k, ox, oy, oz, dx, dy, dz)
    if t0 == np.inf or cap < 2:
        return 0
    out_t[0], out_f[0], out_t[1], out_f[1] = t0, 0, t1, 0
    return 2


@nb.njit(**JIT)
def normal(par, k, aux, face, x, y, z, stack):
    return x, y, z


@nb.njit(**JIT)
def inside(par, k, aux, x, y, z, stack):
    r = par[k, BOUND]
    return x * x + y * y + z * z < r * r
