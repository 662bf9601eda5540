"""The Whitted tracer's shadow feelers (the course's "rayons d'ombre"): the one
:func:`.kernels.shade_hit` traces from a hit towards a light (:func:`_transmittance`: blocked,
or the ``kt`` of transmissive occluders, and the transmittance of the media crossed), and the
batch of their rays for a caller that traces them itself (:func:`feeler_batch`, opacity maps)."""
from __future__ import annotations

import numba as nb
import numpy as np

from ..kernels.columns import Mat, WhittedOpt
from ..kernels.flags import INLINE
from ..kernels.intersect import closest
from ..kernels.media import march
from ..kernels.optics import _facing, _feeler, _light_dir
from .flatten import SHADOW_CROSSINGS


@nb.njit(**INLINE)
def _transmittance(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmin, tmax, transmissive, zero,
                   eps, media, stack, st, sp_, sf, sn):
    """Shadow feeler: 1 if nothing blocks the segment, 0 if blocked (any hit ends the search);
    with ``transmissive``, the product of the ``kt`` of every surface crossed (at most
    ``SHADOW_CROSSINGS``).  ``media`` (``WhittedOpt.STEP_SCALE``, 0: none in the scene): the
    boundaries of heterogeneous media block nothing, and the feeler takes the transmittance of
    each medium's chord within the segment (:func:`..kernels.media.march`; at most four media
    a feeler)."""
    v = 1.0
    t0 = tmin
    m0, m1, m2, m3 = -1, -1, -1, -1  # media already marched
    for _ in range(SHADOW_CROSSINGS):
        t, k, f, tri, b1, b2 = closest(geo, ox, oy, oz, dx, dy, dz, t0, tmax, np.bool_(True),
                                       np.bool_(not transmissive and media == 0.0), zero, eps, stack, st, sp_, sf, sn)
        if k < 0:
            return v
        med = int(mat_tab[mat_of[k], Mat.MEDIUM])
        if med >= 0:
            if med != m0 and med != m1 and med != m2 and med != m3:
                m0, m1, m2, m3 = med, m0, m1, m2
                tr, _, _, _ = march(geo, med, ox, oy, oz, dx, dy, dz, tmin, tmax, 0.0, 0.0, 0.0, media, False,
                                    (mat_tab[:0], mat_of, mat_tab), (stack, st, sp_, sf, sn))
                v *= tr
        elif not transmissive:
            return 0.0
        else:
            v *= mat_tab[mat_of[k], Mat.KT]
        if v <= 0.0:
            return 0.0
        t0 = t + eps
    return v


@nb.njit(cache=True, error_model="numpy")
def feeler_batch(lights, O, D, t, prim, ng, nsh, opts, fo, fd, ftmin, ftmax, want):
    """The shadow feelers :func:`shade_hit` traces at each hit, one row per (hit ``i``, light
    ``li``): row ``i L + li`` of ``fo, fd, ftmin, ftmax``; ``want`` is False where it traces
    none (a miss, the light behind the shading normal, a zero light factor).  For a caller that
    traces them itself (opacity maps) and passes their visibility to :func:`shade_batch`."""
    nl = lights.shape[0]
    ray_off, t_min, extent = opts[WhittedOpt.RAY_OFFSET], opts[WhittedOpt.T_MIN], opts[WhittedOpt.EXTENT]
    for i in range(O.shape[0]):
        dx, dy, dz = D[i, 0], D[i, 1], D[i, 2]
        px, py, pz = O[i, 0] + t[i] * dx, O[i, 1] + t[i] * dy, O[i, 2] + t[i] * dz
        nx, ny, nz = _facing(nsh, i, dx, dy, dz)
        pm = max(abs(px), abs(py), abs(pz))
        off = ray_off * max(pm, extent)
        for li in range(nl):
            r = i * nl + li
            want[r] = False
            if prim[i] < 0:
                continue
            lx, ly, lz, dist, scale = _light_dir(lights, li, px, py, pz)
            if nx * lx + ny * ly + nz * lz <= 0.0 or scale == 0.0:
                continue
            qx, qy, qz, tmx = _feeler(px, py, pz, ng[i, 0], ng[i, 1], ng[i, 2], lx, ly, lz, dist, off)
            fo[r, 0], fo[r, 1], fo[r, 2] = qx, qy, qz
            fd[r, 0], fd[r, 1], fd[r, 2] = lx, ly, lz
            ftmin[r], ftmax[r] = t_min * max(pm, extent), tmx
            want[r] = True
