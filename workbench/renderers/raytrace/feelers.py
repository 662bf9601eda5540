"""The Whitted tracer's shadow feelers (the course's "rayons d'ombre"): the one
:func:`.kernels.shade_hit` traces from a hit towards a light (:func:`_transmittance`: blocked,
or the ``kt`` of transmissive occluders, and the transmittance of the media crossed); through
opacity maps, :func:`.opacity.opacity_feelers`."""
from __future__ import annotations

import numba as nb
import numpy as np

from ..kernels.columns import Mat
from ..kernels.flags import INLINE
from ..kernels.intersect import closest
from ..kernels.media import march
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
        t, k, f, tri, b1, b2, _, _, _ = closest(geo, ox, oy, oz, dx, dy, dz, t0, tmax, np.bool_(True),
                                       np.bool_(not transmissive and media == 0.0), np.bool_(True), zero, eps, stack, st,
                                       sp_, sf, sn)
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
