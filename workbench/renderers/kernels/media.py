"""Heterogeneous media (the ``hypertexture`` kind's, :mod:`workbench.scene.kinds.hypertexture`)
along a ray: the emission-absorption march of the ray caster and the Whitted tracer, and the
delta and ratio tracking of the path tracer.  Each entry point is a gate (as the kind gates of
:mod:`.specialise`): compiled to the medium's code for a scene whose kind marker names a medium
kind, to a constant otherwise, so a scene without one compiles none of it.

A medium kind (``MEDIUM = True``) has a kernel module defining ``optics(par, k, aux, x, y, z) ->
(sigma_t, albedo r, g, b, emission r, g, b)`` at an object-space point (extinction per
object-space unit, at most the row's majorant ``majorant(par, k)``) and ``chord(par, k, ox, oy,
oz, dx, dy, dz) -> (t0, t1)``, the object-space line's overlap with its bounding region
(``(inf, inf)``: none).  The kernels take the ray into the row's object space
(``object_from_world``); the ray parameter ``t`` is unchanged, and an object-space length is
``|D'| dt`` with ``D'`` the object-space direction.

March (Perlin and Hoffert 1989; Max, "Optical models for direct volume rendering", IEEE TVCG
1995, the emission-absorption model): over ``[t0, t1]``, ``N = ceil(L / step)`` steps of equal
length (``L`` the object-space length, ``step`` the row's times ``step_scale``), each sampled at
its midpoint: ``tau_j = sigma_t(x_j) h |D'|``, ``L += T (1 - exp(-tau_j)) J_j``,
``T *= exp(-tau_j)`` with the source ``J = (1 - a) Le + a ambient`` (albedo ``a``: the ambient
light is the only light scattered in by this model).

Tracking (the path tracer; Woodcock et al. 1965, Novák et al., "Monte Carlo methods for
volumetric light transport simulation", CGF 2018): tentative collisions at exponential
distances of the majorant ``sigma_bar`` (the row's ``majorant``); delta tracking (:func:`track`)
accepts one as real with probability ``sigma_t / sigma_bar``, ratio tracking (:func:`ratio`)
multiplies the transmittance estimate by ``1 - sigma_t / sigma_bar`` at each: both unbiased.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba.extending import overload

from ...scene.kinds import KINDS, kernel_module
from .columns import Light, Mat
from .flags import GATE, INLINE
from .intersect import closest
from .optics import _light_dir
from .layout import marker_features, marker_name
from .rng import rand

MAX_MARCH_STEPS = 1 << 20
"""Most steps of one march (the kinds bound ``step`` against their size; this bounds
``step_scale`` too)."""
MAX_COLLISIONS = 1 << 24
"""Most tentative collisions of one tracking (a majorant of 1e6 per unit over a unit chord
takes 1e6; beyond the cap the tracking stops as if absorbed, a bias the stress cases show)."""
T_CUT = 1e-12
"""A march stops once its transmittance falls below this (what is behind adds < 1e-12 of its
radiance)."""


def medium_kinds(kinds) -> list:
    """The medium kinds (``MEDIUM``) the marker (its numba type) names."""
    named = set(marker_features(kinds))
    return [k for k in KINDS.values() if getattr(k, "MEDIUM", False) and marker_name(k) in named]


@nb.njit(**INLINE)
def to_object(geo, k, ox, oy, oz, dx, dy, dz):
    """The ray in row ``k``'s object space (``object_from_world``)."""
    if geo.ident[k]:
        return ox, oy, oz, dx, dy, dz
    a = geo.xf
    return (a[k, 0] * ox + a[k, 1] * oy + a[k, 2] * oz + a[k, 3],
            a[k, 4] * ox + a[k, 5] * oy + a[k, 6] * oz + a[k, 7],
            a[k, 8] * ox + a[k, 9] * oy + a[k, 10] * oz + a[k, 11],
            a[k, 0] * dx + a[k, 1] * dy + a[k, 2] * dz,
            a[k, 4] * dx + a[k, 5] * dy + a[k, 6] * dz,
            a[k, 8] * dx + a[k, 9] * dy + a[k, 10] * dz)


def _dispatch(kinds, body, args: str, miss: str, name: str):
    """An implementation ``impl(geo, k, <args>)`` running ``body`` (source using ``optics``,
    ``chord``, ``step``, ``majorant``, and for texel kinds ``texel`` and ``kajiya_kay``; or a
    function of the kind's kernel module returning the source) for the medium kind whose
    ``PTYPE`` is ``geo.ptype[k]``; ``miss`` for a scene without one."""
    present = medium_kinds(kinds)
    env = {"np": np, "math": math, "to_object": to_object, "MAX_STEPS": MAX_MARCH_STEPS, "T_CUT": T_CUT,
           "rand": rand, "MAX_COLLISIONS": MAX_COLLISIONS, "light_dir": _light_dir, "visibility": visibility,
           "POWER": int(Light.POWER)}
    lines = [f"def impl(geo, k, {args}):"]
    names = ("optics", "chord", "step", "majorant", "texel", "kajiya_kay")
    for i, kind in enumerate(present):
        mod = kernel_module(kind)
        text = body(mod) if callable(body) else body
        for n in names:
            if hasattr(mod, n):
                env[f"{n}{i}"] = getattr(mod, n)
                text = text.replace(f"{n}(", f"{n}{i}(")
        lines.append(f"    if geo.ptype[k] == {int(kind.PTYPE)}:")
        lines += ["        " + ln for ln in text.strip("\n").split("\n")]
    lines.append(f"    return {miss}")
    exec(compile("\n".join(lines), f"<{name} over {', '.join(k.TYPE for k in present) or 'no medium'}>", "exec"), env)
    return env["impl"]


@nb.njit(**GATE)
def visibility(geo, mat_of, mat_tab, ox, oy, oz, dx, dy, dz, tmax, eps, scr):
    """1 if no surface but media boundaries lies on ``o + t d``, ``eps < t < tmax``, else 0
    (a texel's feeler: the fur does not shadow itself in this model)."""
    stack, st, sp_, sf, sn = scr
    t0 = eps
    for _ in range(16):
        t, kk, f, tri, b1, b2, _, _, _ = closest(geo, ox, oy, oz, dx, dy, dz, t0, tmax, np.bool_(True), np.bool_(False),
                                        np.bool_(False), 0.0, eps, stack, st, sp_, sf, sn)
        if kk < 0:
            return 1.0
        if mat_tab[mat_of[kk], Mat.MEDIUM] < 0.0:
            return 0.0
        t0 = t + eps
    return 0.0


_STEPS = """
qx, qy, qz, ux, uy, uz = to_object(geo, k, ox, oy, oz, dx, dy, dz)
c0, c1 = chord(geo.par, k, qx, qy, qz, ux, uy, uz)
t0, t1 = max(t0, c0), min(t1, c1)
speed = math.sqrt(ux * ux + uy * uy + uz * uz)
if not t1 > t0:
    return 1.0, 0.0, 0.0, 0.0
n = min(MAX_STEPS, max(1, int(math.ceil((t1 - t0) * speed / (step(geo.par, k) * scale)))))
h = (t1 - t0) / n
tr, lr, lg, lb = 1.0, 0.0, 0.0, 0.0
"""

_MARCH = _STEPS + """
for j in range(n):
    t = t0 + (j + 0.5) * h
    st, a0, a1, a2, e0, e1, e2 = optics(geo.par, k, geo.aux, qx + t * ux, qy + t * uy, qz + t * uz)
    if st > 0.0:
        att = math.exp(-st * h * speed)
        f = tr * (1.0 - att)
        if emit:
            lr += f * ((1.0 - a0) * e0 + a0 * amb_r)
            lg += f * ((1.0 - a1) * e1 + a1 * amb_g)
            lb += f * ((1.0 - a2) * e2 + a2 * amb_b)
        tr *= att
        if tr < T_CUT:
            return 0.0, lr, lg, lb
return tr, lr, lg, lb
"""


_MARCH_TEXEL = _STEPS + """
lights, mat_of, mat_tab = light
nm = geo.nm
for j in range(n):
    t = t0 + (j + 0.5) * h
    d, tx, ty, tz = texel(geo.par, k, qx + t * ux, qy + t * uy, qz + t * uz)
    if d > 0.0:
        st, a0, a1, a2, _e0, _e1, _e2 = optics(geo.par, k, geo.aux, qx + t * ux, qy + t * uy, qz + t * uz)
        att = math.exp(-st * h * speed)
        f = tr * (1.0 - att)
        if emit:
            wx = nm[k, 0] * tx + nm[k, 1] * ty + nm[k, 2] * tz
            wy = nm[k, 3] * tx + nm[k, 4] * ty + nm[k, 5] * tz
            wz = nm[k, 6] * tx + nm[k, 7] * ty + nm[k, 8] * tz
            wn = math.sqrt(wx * wx + wy * wy + wz * wz)
            if wn > 0.0:
                wx, wy, wz = wx / wn, wy / wn, wz / wn
            px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
            sr, sg, sb = a0 * amb_r, a1 * amb_g, a2 * amb_b
            eps = 1e-9 * max(max(abs(px), abs(py), abs(pz)), 1.0)
            for li in range(lights.shape[0]):
                lx, ly, lz, dist, sc = light_dir(lights, li, px, py, pz)
                if sc == 0.0:
                    continue
                vis = visibility(geo, mat_of, mat_tab, px, py, pz, lx, ly, lz, dist, eps, scr)
                if vis > 0.0:
                    sin_tl, spec = kajiya_kay(geo.par, k, wx, wy, wz, lx, ly, lz, dx, dy, dz)
                    w = sc * vis
                    sr += lights[li, POWER] * w * (a0 * sin_tl + spec)
                    sg += lights[li, POWER + 1] * w * (a1 * sin_tl + spec)
                    sb += lights[li, POWER + 2] * w * (a2 * sin_tl + spec)
            lr += f * sr
            lg += f * sg
            lb += f * sb
        tr *= att
        if tr < T_CUT:
            return 0.0, lr, lg, lb
return tr, lr, lg, lb
"""


def march(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, amb_r, amb_g, amb_b, scale, emit, light, scr):
    """Emission-absorption march (module docstring) of medium row ``k`` along the world ray over
    ``[t0, t1]`` (clipped to the medium's chord); ``scale`` multiplies the row's step; without
    ``emit`` only the transmittance.  A texel kind (a kernel module with ``texel`` and
    ``kajiya_kay``: the fur) lights its strands instead: ambient and, through feelers against
    the surfaces (:func:`visibility`), each light of ``light = (lights, mat_of, mat_tab)`` by
    its Kajiya-Kay lobes.  ``scr``: the intersector's scratch.  Returns ``(T, L r, g, b)``;
    ``(1, 0, 0, 0)`` for a scene without a medium."""
    raise TypeError("march is callable from numba-compiled code only")


@overload(march, jit_options=GATE)
def _march(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, amb_r, amb_g, amb_b, scale, emit, light, scr):
    return _dispatch(geo.types[-1], lambda mod: _MARCH_TEXEL if hasattr(mod, "kajiya_kay") else _MARCH,
                     "ox, oy, oz, dx, dy, dz, t0, t1, amb_r, amb_g, amb_b, scale, emit, light, scr",
                     "1.0, 0.0, 0.0, 0.0", "march")


_CHORD = """
qx, qy, qz, ux, uy, uz = to_object(geo, k, ox, oy, oz, dx, dy, dz)
c0, c1 = chord(geo.par, k, qx, qy, qz, ux, uy, uz)
t0, t1 = max(t0, c0), min(t1, c1)
speed = math.sqrt(ux * ux + uy * uy + uz * uz)
mj = majorant(geo.par, k) * speed
"""

_TRACK = _CHORD + """
if not t1 > t0 or not mj > 0.0:
    return np.inf, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, dim
t = t0
for _ in range(MAX_COLLISIONS):
    t -= math.log(1.0 - rand(key, dim)) / mj
    if t >= t1:
        return np.inf, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, dim + 1
    st, a0, a1, a2, e0, e1, e2 = optics(geo.par, k, geo.aux, qx + t * ux, qy + t * uy, qz + t * uz)
    if rand(key, dim + 1) * mj < st * speed:
        return t, a0, a1, a2, e0, e1, e2, dim + 2
    dim += 2
return t, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, dim
"""


def track(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, key, dim):
    """Delta tracking of medium row ``k`` along the world ray over ``[t0, t1]`` (clipped to its
    chord), random numbers ``rand(key, dim), rand(key, dim + 1), ...``.  Returns ``(t, albedo
    r, g, b, emission r, g, b, next dim)``: ``t`` of the first real collision (``inf``: none
    before ``t1``) and the medium's optics there."""
    raise TypeError("track is callable from numba-compiled code only")


@overload(track, jit_options=GATE)
def _track(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, key, dim):
    return _dispatch(geo.types[-1], _TRACK, "ox, oy, oz, dx, dy, dz, t0, t1, key, dim",
                     "np.inf, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, dim", "track")


_RATIO = _CHORD + """
if not t1 > t0 or not mj > 0.0:
    return 1.0, dim
t = t0
tr = 1.0
for _ in range(MAX_COLLISIONS):
    t -= math.log(1.0 - rand(key, dim)) / mj
    dim += 1
    if t >= t1:
        return tr, dim
    st, _a0, _a1, _a2, _e0, _e1, _e2 = optics(geo.par, k, geo.aux, qx + t * ux, qy + t * uy, qz + t * uz)
    tr *= 1.0 - st * speed / mj
    if tr < T_CUT:
        return 0.0, dim
return 0.0, dim
"""


def ratio(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, key, dim):
    """Ratio tracking: an unbiased estimate of medium row ``k``'s transmittance along the world
    ray over ``[t0, t1]`` (clipped to its chord).  Returns ``(T, next dim)``."""
    raise TypeError("ratio is callable from numba-compiled code only")


@overload(ratio, jit_options=GATE)
def _ratio(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, key, dim):
    return _dispatch(geo.types[-1], _RATIO, "ox, oy, oz, dx, dy, dz, t0, t1, key, dim", "1.0, dim", "ratio")
