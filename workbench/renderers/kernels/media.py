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
from .flags import GATE, INLINE
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


def _dispatch(kinds, body: str, args: str, miss: str, name: str):
    """An implementation ``impl(geo, k, <args>)`` running ``body`` (source using ``optics``,
    ``chord``, ``step``) for the medium kind whose ``PTYPE`` is ``geo.ptype[k]``; ``miss``
    for a scene without one."""
    present = medium_kinds(kinds)
    env = {"np": np, "math": math, "to_object": to_object, "MAX_STEPS": MAX_MARCH_STEPS, "T_CUT": T_CUT,
           "rand": rand, "MAX_COLLISIONS": MAX_COLLISIONS}
    lines = [f"def impl(geo, k, {args}):"]
    for i, kind in enumerate(present):
        mod = kernel_module(kind)
        env[f"optics{i}"], env[f"chord{i}"], env[f"step{i}"] = mod.optics, mod.chord, mod.step
        env[f"majorant{i}"] = mod.majorant
        lines.append(f"    if geo.ptype[k] == {int(kind.PTYPE)}:")
        lines += ["        " + ln.replace("optics(", f"optics{i}(").replace("chord(", f"chord{i}(")
                  .replace("step(", f"step{i}(").replace("majorant(", f"majorant{i}(")
                  for ln in body.strip("\n").split("\n")]
    lines.append(f"    return {miss}")
    exec(compile("\n".join(lines), f"<{name} over {', '.join(k.TYPE for k in present) or 'no medium'}>", "exec"), env)
    return env["impl"]


_MARCH = """
qx, qy, qz, ux, uy, uz = to_object(geo, k, ox, oy, oz, dx, dy, dz)
c0, c1 = chord(geo.par, k, qx, qy, qz, ux, uy, uz)
t0, t1 = max(t0, c0), min(t1, c1)
speed = math.sqrt(ux * ux + uy * uy + uz * uz)
if not t1 > t0:
    return 1.0, 0.0, 0.0, 0.0
n = min(MAX_STEPS, max(1, int(math.ceil((t1 - t0) * speed / (step(geo.par, k) * scale)))))
h = (t1 - t0) / n
tr, lr, lg, lb = 1.0, 0.0, 0.0, 0.0
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


def march(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, amb_r, amb_g, amb_b, scale, emit):
    """Emission-absorption march (module docstring) of medium row ``k`` along the world ray over
    ``[t0, t1]`` (clipped to the medium's chord); ``scale`` multiplies the row's step; without
    ``emit`` only the transmittance.  Returns ``(T, L r, g, b)``; ``(1, 0, 0, 0)`` for a
    scene without a medium."""
    raise TypeError("march is callable from numba-compiled code only")


@overload(march, jit_options=GATE)
def _march(geo, k, ox, oy, oz, dx, dy, dz, t0, t1, amb_r, amb_g, amb_b, scale, emit):
    return _dispatch(geo.types[-1], _MARCH, "ox, oy, oz, dx, dy, dz, t0, t1, amb_r, amb_g, amb_b, scale, emit",
                     "1.0, 0.0, 0.0, 0.0", "march")


def chord_of(geo, k, ox, oy, oz, dx, dy, dz):
    """World ``(t0, t1)`` of the ray's overlap with medium row ``k``'s bounding region;
    ``(inf, inf)`` when it misses (or for a scene without a medium)."""
    raise TypeError("chord_of is callable from numba-compiled code only")


@overload(chord_of, jit_options=GATE)
def _chord_of(geo, k, ox, oy, oz, dx, dy, dz):
    body = """
qx, qy, qz, ux, uy, uz = to_object(geo, k, ox, oy, oz, dx, dy, dz)
return chord(geo.par, k, qx, qy, qz, ux, uy, uz)
"""
    return _dispatch(geo.types[-1], body, "ox, oy, oz, dx, dy, dz", "np.inf, np.inf", "chord_of")


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
