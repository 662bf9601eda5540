"""Kind dispatch specialised to the kinds a scene holds: a scene of spheres never compiles the
lathe's, the blob's or the isosurface's kernels.

The geometry record ends with a kind marker (:func:`.layout.kinds_marker`) whose numba type
names the features present, so every kernel taking the record is compiled, and cached on disk,
once per feature set.  The functions below are ``@overload``\\ ed: at typing time they read the
marker's type and return an implementation whose branches for absent kinds test a constant
``False`` (a closure variable), which numba's dead-branch pruning removes before type inference:
the kernels of absent kinds are never typed, so never compiled.  Each is callable from compiled
code only.

The kinds with kernels of their own are blob, isosurface, lathe and prism
(``workbench.scene.kinds.*_kernels``); the rest (sphere, rectangle, box, polygon, quadric) are a
few lines each and stay inline in :mod:`workbench.renderers.kernels.shapes`.
"""
from __future__ import annotations

import numpy as np
from numba.extending import overload

from ...scene.kinds import blob, isosurface, lathe, prism
from ...scene.kinds import blob_kernels as kb, isosurface_kernels as ki, lathe_kernels as kl, prism_kernels as kp
from .flags import GATE
from .layout import marker_features

BLOB, ISOSURFACE, LATHE, PRISM = blob.PTYPE, isosurface.PTYPE, lathe.PTYPE, prism.PTYPE
JIT = GATE


def has(kinds, feature: str) -> bool:
    """Whether the marker (its numba type at typing time) names ``feature``."""
    return feature in marker_features(kinds)


def exotic_first(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax`` of row ``k`` of a kind with its own kernels (object-space
    ray; ``out_t``, ``out_f``, ``stack``: scratch).  Returns ``(t, face)``, ``(inf, 0)`` on a
    miss or for a kind not handled here."""
    raise TypeError("exotic_first is callable from numba-compiled code only")


@overload(exotic_first, jit_options=JIT)
def _exotic_first(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    on_blob, on_iso, on_lathe, on_prism = (has(kinds, f) for f in ("blob", "isosurface", "lathe", "prism"))

    def impl(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
        if on_blob:
            if kind == BLOB:
                return kb.blob_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack)
        if on_iso:
            if kind == ISOSURFACE:
                return ki.iso_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack)
        if on_lathe:
            if kind == LATHE:
                return kl.lathe_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack)
        if on_prism:
            if kind == PRISM:
                return kp.prism_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack)
        return np.inf, 0
    return impl


def exotic_events(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack):
    """Interval list of row ``k`` along the whole object-space line (entering and leaving
    alternate) written to ``et`` (t) and ``ef`` (face), at most ``cap``; returns the count
    (0 for a kind not handled here)."""
    raise TypeError("exotic_events is callable from numba-compiled code only")


@overload(exotic_events, jit_options=JIT)
def _exotic_events(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack):
    on_blob, on_iso, on_lathe, on_prism = (has(kinds, f) for f in ("blob", "isosurface", "lathe", "prism"))

    def impl(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack):
        if on_blob:
            if kind == BLOB:
                return kb.blob_events(par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack)
        if on_iso:
            if kind == ISOSURFACE:
                return ki.iso_events(par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack)
        if on_lathe:
            if kind == LATHE:
                return kl.lathe_events(par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack)
        if on_prism:
            if kind == PRISM:
                return kp.prism_events(par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack)
        return 0
    return impl


def exotic_normal(kinds, kind, par, k, aux, face, x, y, z, stack):
    """Outward normal (unnormalised) of row ``k`` at an object-space point; ``(0, 0, 0)`` for a
    kind not handled here."""
    raise TypeError("exotic_normal is callable from numba-compiled code only")


@overload(exotic_normal, jit_options=JIT)
def _exotic_normal(kinds, kind, par, k, aux, face, x, y, z, stack):
    on_blob, on_iso, on_lathe, on_prism = (has(kinds, f) for f in ("blob", "isosurface", "lathe", "prism"))

    def impl(kinds, kind, par, k, aux, face, x, y, z, stack):
        if on_blob:
            if kind == BLOB:
                return kb.blob_normal(par, k, aux, face, x, y, z, stack)
        if on_iso:
            if kind == ISOSURFACE:
                return ki.iso_normal(par, k, aux, face, x, y, z, stack)
        if on_lathe:
            if kind == LATHE:
                return kl.lathe_normal(par, k, aux, face, x, y, z, stack)
        if on_prism:
            if kind == PRISM:
                return kp.prism_normal(par, k, aux, face, x, y, z, stack)
        return 0.0, 0.0, 0.0
    return impl
