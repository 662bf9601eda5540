"""Sampling helpers the path tracer's surface and medium vertices share: the choice of an
emitter triangle and the multiple importance sampling weight (Veach and Guibas 1995)."""
from __future__ import annotations

import math

import numba as nb

from ..kernels.columns import Mat
from ..kernels.flags import INLINE, NO_REFCOUNT
from ..kernels.rng import rand


@nb.njit(**INLINE)
def mis_weight(pa, pb, beta):
    """Power heuristic ``pa^beta / (pa^beta + pb^beta)`` (``beta = 1``: balance heuristic)."""
    if beta == 2.0:
        a, b = pa * pa, pb * pb
    else:
        a, b = pa, pb
    return a / (a + b) if a > 0.0 else 0.0


@nb.njit(**NO_REFCOUNT)
def pick_emitter(cdf, u):
    """Index of the first ``cdf`` entry above ``u`` (binary search)."""
    lo, hi = 0, cdf.shape[0] - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if cdf[mid] > u:
            hi = mid
        else:
            lo = mid + 1
    return lo


@nb.njit(**INLINE)
def sample_emitter(emitters, mat_of, mat_tab, tri_e, key, dim, px, py, pz, transport):
    """A point ``q`` on an emitter triangle (picked by the emitters' CDF, then uniform on it:
    random dimensions ``dim .. dim + 2``) seen from ``p``.  Returns ``(q, l, dist, cos_l, Le,
    p_l)``: the unit direction to it, its distance (0: ``q`` is ``p``), the cosine at the light
    (> 0: its front), its emitted radiance towards ``p`` (a front-only emitter's back is black;
    ``transport`` 0, full: with the vertex emission of a radiosity mesh) and the solid-angle
    density of the sample (0 at a grazing 90 degrees)."""
    em_tri, em_n, em_prim, em_mtri, em_cdf, lpdf_prim, lpdf_tri = emitters
    e = pick_emitter(em_cdf, rand(key, dim))
    su = math.sqrt(rand(key, dim + 1))
    u2 = rand(key, dim + 2)
    c0, c1, c2 = 1.0 - su, su * (1.0 - u2), su * u2
    qx = c0 * em_tri[e, 0] + c1 * em_tri[e, 3] + c2 * em_tri[e, 6]
    qy = c0 * em_tri[e, 1] + c1 * em_tri[e, 4] + c2 * em_tri[e, 7]
    qz = c0 * em_tri[e, 2] + c1 * em_tri[e, 5] + c2 * em_tri[e, 8]
    vx, vy, vz = qx - px, qy - py, qz - pz
    dist = math.sqrt(vx * vx + vy * vy + vz * vz)
    if not dist > 0.0:
        return qx, qy, qz, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    lx, ly, lz = vx / dist, vy / dist, vz / dist
    cos_l = -(lx * em_n[e, 0] + ly * em_n[e, 1] + lz * em_n[e, 2])
    emi = mat_of[em_prim[e]]
    ler, leg, leb = 0.0, 0.0, 0.0
    if cos_l > 0.0 or (transport == 0 and mat_tab[emi, Mat.FRONT_ONLY] < 0.5):
        ler, leg, leb = mat_tab[emi, Mat.EMISSION], mat_tab[emi, Mat.EMISSION + 1], mat_tab[emi, Mat.EMISSION + 2]
    mt = em_mtri[e]
    if mt >= 0 and transport == 0:
        ler += c0 * tri_e[mt, 0] + c1 * tri_e[mt, 3] + c2 * tri_e[mt, 6]
        leg += c0 * tri_e[mt, 1] + c1 * tri_e[mt, 4] + c2 * tri_e[mt, 7]
        leb += c0 * tri_e[mt, 2] + c1 * tri_e[mt, 5] + c2 * tri_e[mt, 8]
    p_l = 0.0
    if cos_l != 0.0:
        p_l = (lpdf_tri[mt] if mt >= 0 else lpdf_prim[em_prim[e]]) * dist * dist / abs(cos_l)
    return qx, qy, qz, lx, ly, lz, dist, cos_l, ler, leg, leb, p_l
