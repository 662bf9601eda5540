"""Opacity maps in the Whitted kernel (:func:`.kernels.pixels_task`): the hits beyond surfaces an
opacity map cuts out (:func:`pass_cutouts`) and the shadow feelers through partly opaque
surfaces (:func:`opacity_feelers`), as :mod:`.reference`'s ``visible_hit`` and
``shadow_feeler``.  Both are gates (``@overload``\\ s reading the maps' marker,
:mod:`..kernels.textures`): a scene without maps compiles neither's search."""
from __future__ import annotations

import numba as nb
import numpy as np
from numba.extending import overload

from ..kernels.columns import Mat, WhittedOpt
from ..kernels.flags import GATE, INLINE
from ..kernels.intersect import closest, object_point, surface
from ..kernels.optics import _facing, _feeler, _light_dir
from ..kernels.textures import has_maps, hit_alpha
from .flatten import MAX_CUTOUTS, SHADOW_CROSSINGS


@nb.njit(**INLINE)
def _past(ox, oy, oz, dx, dy, dz, t, ray_off, extent):
    """``tmin`` just beyond the hit at ``t`` (offset scaled with the hit point)."""
    return t + ray_off * max(max(abs(ox + t * dx), abs(oy + t * dy), abs(oz + t * dz)), extent)


def pass_cutouts(geo, shading, ox, oy, oz, dx, dy, dz, t, ncancel, hit, scr):
    """The ray's next hits beyond a cut-out surface at ``t`` (alpha below the cut), until one
    is not cut out (at most :data:`.flatten.MAX_CUTOUTS` surfaces, then a miss), its surface
    data in ``hit = (ng, ns, uv, po, ev)``.  Returns ``(t, prim, alpha)``.  Compiled for scenes
    with maps only (:mod:`..kernels.textures`): without, a surface is never cut out."""
    raise TypeError("pass_cutouts is callable from numba-compiled code only")


@overload(pass_cutouts, jit_options=GATE)
def _pass_cutouts(geo, shading, ox, oy, oz, dx, dy, dz, t, ncancel, hit, scr):
    if not has_maps(shading.types[shading.fields.index("maps")]):
        return lambda geo, shading, ox, oy, oz, dx, dy, dz, t, ncancel, hit, scr: (t, np.int64(-1), 1.0)

    def impl(geo, shading, ox, oy, oz, dx, dy, dz, t, ncancel, hit, scr):
        opts, mat_of = shading.opts, shading.mat_of
        zero, ray_off, extent = opts[WhittedOpt.ZERO], opts[WhittedOpt.RAY_OFFSET], opts[WhittedOpt.EXTENT]
        ng, ns, uv, po, ev = hit
        stack, st, sp_, sf, sn = scr
        eps = ray_off * max(max(abs(ox), abs(oy), abs(oz)), extent)
        for _ in range(MAX_CUTOUTS - 1):
            tmin = _past(ox, oy, oz, dx, dy, dz, t, ray_off, extent)
            t, k, f, tri, b1, b2, _, _, _ = closest(geo, ox, oy, oz, dx, dy, dz, tmin, np.inf, np.bool_(False),
                                           np.bool_(False), np.bool_(True), zero, eps, stack, st, sp_, sf, sn)
            if k < 0:
                return t, k, 1.0
            surface(geo, k, f, tri, b1, b2, ox + t * dx, oy + t * dy, oz + t * dz, ncancel, ng, ns, uv, po, ev, 0,
                    stack)
            a = hit_alpha(shading.maps, shading.mat_tab, mat_of[k], k, po, uv)
            if a > 0.0:
                return t, k, a
        return np.inf, np.int64(-1), 1.0
    return impl


def opacity_feelers(geo, shading, ox, oy, oz, dx, dy, dz, t, ng, ns, vis, spare, scr):
    """``vis[0, l]``: the visibility of each light from the hit at ``t`` through surfaces with
    opacity maps (each lets ``1 - alpha`` through, and ``alpha kt`` with
    ``transmissive_shadows``; at most :data:`.flatten.SHADOW_CROSSINGS`), for the feelers
    :func:`shade_hit` would trace (``reference.shadow_feeler``).  Nothing without a row in
    ``vis`` (no opacity map or no shadows); compiled for scenes with maps only."""
    raise TypeError("opacity_feelers is callable from numba-compiled code only")


@overload(opacity_feelers, jit_options=GATE)
def _opacity_feelers(geo, shading, ox, oy, oz, dx, dy, dz, t, ng, ns, vis, spare, scr):
    if not has_maps(shading.types[shading.fields.index("maps")]):
        return lambda geo, shading, ox, oy, oz, dx, dy, dz, t, ng, ns, vis, spare, scr: None

    def impl(geo, shading, ox, oy, oz, dx, dy, dz, t, ng, ns, vis, spare, scr):
        if vis.shape[0] == 0:
            return
        opts, mat_of, mat_tab, lights = shading.opts, shading.mat_of, shading.mat_tab, shading.lights
        zero, ray_off, extent = opts[WhittedOpt.ZERO], opts[WhittedOpt.RAY_OFFSET], opts[WhittedOpt.EXTENT]
        transmissive = opts[WhittedOpt.TRANSMISSIVE_SHADOWS] > 0.5
        po, uv = spare
        stack, st, sp_, sf, sn = scr
        px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
        nx, ny, nz = _facing(ns, 0, dx, dy, dz)
        pm = max(abs(px), abs(py), abs(pz))
        off = ray_off * max(pm, extent)
        for li in range(lights.shape[0]):
            vis[0, li] = 1.0
            lx, ly, lz, dist, scale = _light_dir(lights, li, px, py, pz)
            if nx * lx + ny * ly + nz * lz <= 0.0 or scale == 0.0:
                continue
            qx, qy, qz, tmx = _feeler(px, py, pz, ng[0, 0], ng[0, 1], ng[0, 2], lx, ly, lz, dist, off)
            tmin = opts[WhittedOpt.T_MIN] * max(pm, extent)
            v = 1.0
            for _ in range(SHADOW_CROSSINGS):
                s, k, f, tri, b1, b2, _, _, _ = closest(geo, qx, qy, qz, lx, ly, lz, tmin, tmx, np.bool_(True),
                                               np.bool_(False), np.bool_(True), zero, off, stack, st, sp_, sf, sn)
                if k < 0:
                    break
                po[0, 0], po[0, 1], po[0, 2] = object_point(geo, k, qx + s * lx, qy + s * ly, qz + s * lz)
                if tri >= 0:
                    b0 = 1.0 - b1 - b2
                    for c in range(2):
                        uv[0, c] = b0 * geo.tri_uv[tri, c] + b1 * geo.tri_uv[tri, 2 + c] + b2 * geo.tri_uv[tri, 4 + c]
                a = hit_alpha(shading.maps, mat_tab, mat_of[k], k, po, uv)
                v *= 1.0 - a + (a * mat_tab[mat_of[k], Mat.KT] if transmissive else 0.0)
                if v <= 0.0:
                    v = 0.0
                    break
                tmin = _past(qx, qy, qz, lx, ly, lz, s, ray_off, extent)
            vis[0, li] = v
    return impl
