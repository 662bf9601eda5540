"""Surface optics shared by Whitted and the path tracer: Fresnel reflectance, the media stack's
index, the shading normal's side, the direction and falloff of a point or directional light,
the shadow feeler's origin, the fused checker texture and the camera ray of a pixel.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from .columns import Light, Mat
from .flags import INLINE
from .shapes import _normalize


POW_NEGLIGIBLE = 46.0
"""``n (1 - b)`` beyond which :func:`_pow` takes ``b ** n`` (``0 <= b <= 1``) for 0: it is then
at most ``exp(-n (1 - b)) < 1.1e-20`` (``ln b <= b - 1``), below the rounding of any
highlight it would be added to."""
POW_SQUARING = 1024
"""Integer exponents up to this are raised by repeated squaring (at most 10 squarings and 10
products, a few ulps of the correctly rounded power) instead of a call to ``pow``."""


@nb.njit(**INLINE)
def _pow(base, n):
    """``base ** n`` for ``0 <= base <= 1`` and ``n >= 0`` (a Phong highlight), mostly without
    the call to ``pow`` (the Whitted scene's trace spent 8 % of its time there, measured):
    ``0 ** n`` (``n > 0``, a highlight turned away) is 0, a negligible power
    (:data:`POW_NEGLIGIBLE`) 0, an integer exponent (the usual shininess) by squaring
    (:data:`POW_SQUARING`)."""
    if n == 0.0:
        return 1.0
    if base == 0.0 and n > 0.0:
        return 0.0
    if n * (1.0 - base) > POW_NEGLIGIBLE:
        return 0.0
    if 0.0 < n <= POW_SQUARING and math.floor(n) == n:
        m = int(n)
        r, b = 1.0, base
        while m > 0:
            if m & 1:
                r *= b
            b *= b
            m >>= 1
        return r
    return base ** n


@nb.njit(**INLINE)
def _ior(mat_tab, stk, ns_):
    return mat_tab[stk[ns_ - 1], Mat.IOR] if ns_ > 0 else 1.0


@nb.njit(**INLINE)
def enter_or_leave(stk, nstk, mi, front):
    """The media stack ``stk`` (its first ``nstk`` entries) after crossing the boundary of a
    medium's material ``mi``: pushed when entering (if there is room), its topmost entry
    removed when leaving.  Returns its size."""
    if front:
        if nstk < 4:
            stk[nstk] = mi
            return nstk + 1
        return nstk
    j = nstk - 1
    while j >= 0 and stk[j] != mi:
        j -= 1
    if j < 0:
        return nstk
    for q in range(j, nstk - 1):
        stk[q] = stk[q + 1]
    return nstk - 1


@nb.njit(**INLINE)
def fresnel_reflectance(fres, n1, n2, cosi, cost):
    """Reflected share F of light crossing from index ``n1`` to ``n2`` (``cosi``, ``cost``: the
    cosines of incidence and refraction): Schlick's approximation for ``fres == 1`` (cosine on the
    lower-index side; Schlick 1994), else the exact unpolarised Fresnel equations (mean of the
    s and p reflectances)."""
    if fres == 1:
        r0 = (n1 - n2) / (n1 + n2)
        r0 *= r0
        cc = cosi if n1 <= n2 else cost
        return r0 + (1.0 - r0) * (1.0 - cc) ** 5
    rs = (n1 * cosi - n2 * cost) / (n1 * cosi + n2 * cost)
    rp = (n2 * cosi - n1 * cost) / (n2 * cosi + n1 * cost)
    return 0.5 * (rs * rs + rp * rp)


@nb.njit(**INLINE)
def _facing(nsh, i, dx, dy, dz):
    """The shading normal of hit ``i``, turned to face the viewer (two-sided shading)."""
    nx, ny, nz = nsh[i, 0], nsh[i, 1], nsh[i, 2]
    if nx * dx + ny * dy + nz * dz > 0.0:
        return -nx, -ny, -nz
    return nx, ny, nz


@nb.njit(**INLINE)
def _light_dir(lights, li, px, py, pz):
    """Unit direction ``l`` from ``P`` to light ``li``, its distance (``inf`` for a directional
    light) and the light's factor there (1, ``1 / d^2`` when attenuated, times the spot
    factor).  Returns ``(lx, ly, lz, dist, scale)``."""
    if lights[li, Light.KIND] > 0.5:
        return (-lights[li, Light.POSITION], -lights[li, Light.POSITION + 1], -lights[li, Light.POSITION + 2],
                np.inf, 1.0)
    vx = lights[li, Light.POSITION] - px
    vy = lights[li, Light.POSITION + 1] - py
    vz = lights[li, Light.POSITION + 2] - pz
    dist = math.sqrt(vx * vx + vy * vy + vz * vz)
    lx, ly, lz = _normalize(vx, vy, vz)
    scale = 1.0
    if lights[li, Light.INVERSE_SQUARE] > 0.5:
        scale = 1.0 / max(dist * dist, 1e-300)
    if lights[li, Light.COSINE] > 0.5:
        scale *= max(0.0, -(lx * lights[li, Light.COSINE_NORMAL] + ly * lights[li, Light.COSINE_NORMAL + 1]
                            + lz * lights[li, Light.COSINE_NORMAL + 2]))
    return lx, ly, lz, dist, scale


@nb.njit(**INLINE)
def _feeler(px, py, pz, gx, gy, gz, lx, ly, lz, dist, off):
    """The shadow feeler towards ``l``: origin pushed ``off`` off the surface (geometric normal
    ``g``) on the light's side, and its end short of the light.  Returns ``(qx, qy, qz, tmax)``."""
    side = 1.0 if gx * lx + gy * ly + gz * lz >= 0.0 else -1.0
    tmx = dist - 2.0 * off if dist < np.inf else np.inf
    return px + side * off * gx, py + side * off * gy, pz + side * off * gz, tmx


@nb.njit(**INLINE)
def camera_ray(cam, i, j, d, q):
    """Row ``q`` of ``d``: the unit direction of the centre ray of the image pixel in row ``i``,
    column ``j`` of the camera ``cam`` (``whitted.camera_frame``: position, rotation,
    tan(fov_y / 2), aspect, width, height; the ray's origin is the position ``cam[:3]``)."""
    x = ((j + 0.5) / cam[14] * 2.0 - 1.0) * cam[12] * cam[13]
    y = (1.0 - (i + 0.5) / cam[15] * 2.0) * cam[12]
    dx = x * cam[3] + y * cam[4] - cam[5]
    dy = x * cam[6] + y * cam[7] - cam[8]
    dz = x * cam[9] + y * cam[10] - cam[11]
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    d[q, 0], d[q, 1], d[q, 2] = dx / n, dy / n, dz / n
