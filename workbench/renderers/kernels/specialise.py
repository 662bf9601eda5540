"""Kind dispatch specialised to the kinds a scene holds: a scene of spheres never compiles the
lathe's, the blob's or the isosurface's kernels.

The geometry record ends with a kind marker (:func:`.layout.kinds_marker`) whose numba type
names the features present, so every kernel taking the record is compiled, and cached on disk,
once per feature set.  The functions below are ``@overload``\\ ed: at typing time they read the
marker's type and return a dispatch over ``ptype`` written for the kinds it names only (one
``if kind == PTYPE: return module.role(...)`` per kind, generated from the registry,
:func:`workbench.scene.kinds.kernel_kinds`): the kernels of absent kinds are never typed, so
never compiled.  Each is callable from compiled code only.

The kinds with kernel modules of their own are the registry's ``KERNELS`` kinds (blob,
isosurface, lathe, prism, and any plugin); the rest (sphere, rectangle, box, polygon, quadric)
are a few lines each and stay inline in :mod:`workbench.renderers.kernels.shapes`.
"""
from __future__ import annotations

import numpy as np
from numba.extending import overload

from ...scene.kinds import kernel_kinds, kernel_module
from .flags import GATE
from .layout import marker_features, marker_name

JIT = GATE
FIRST_ARGS = "par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack"
EVENTS_ARGS = "par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack"
NORMAL_ARGS = "par, k, aux, face, x, y, z, stack"


def has(kinds, feature: str) -> bool:
    """Whether the marker (its numba type at typing time) names ``feature``."""
    return feature in marker_features(kinds)


def dispatch(kinds, role: str, args: str, miss: str):
    """The implementation of one gate for the marker ``kinds``: ``impl(kinds, kind, <args>)``
    calling ``role`` (``first``, ``events``, ``normal``) of the kernel module of each kind the
    marker names whose ``PTYPE`` is ``kind``, else returning ``miss`` (source text)."""
    named = set(marker_features(kinds))
    present = [k for k in kernel_kinds() if marker_name(k) in named]
    lines = [f"def impl(kinds, kind, {args}):"]
    env = {"np": np}
    for i, k in enumerate(present):
        env[f"f{i}"] = getattr(kernel_module(k), role)
        lines += [f"    if kind == {int(k.PTYPE)}:", f"        return f{i}({args})"]
    lines.append(f"    return {miss}")
    exec(compile("\n".join(lines), f"<{role} dispatch over {', '.join(k.TYPE for k in present) or 'no kind'}>",
                 "exec"), env)
    return env["impl"]


def exotic_first(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax`` of row ``k`` of a kind with its own kernels (object-space
    ray; ``out_t``, ``out_f``, ``stack``: scratch).  Returns ``(t, face)``, ``(inf, 0)`` on a
    miss or for a kind not handled here."""
    raise TypeError("exotic_first is callable from numba-compiled code only")


@overload(exotic_first, jit_options=JIT)
def _exotic_first(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    return dispatch(kinds, "first", FIRST_ARGS, "np.inf, 0")


def exotic_events(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack):
    """Interval list of row ``k`` along the whole object-space line (entering and leaving
    alternate) written to ``et`` (t) and ``ef`` (face), at most ``cap``; returns the count
    (0 for a kind not handled here)."""
    raise TypeError("exotic_events is callable from numba-compiled code only")


@overload(exotic_events, jit_options=JIT)
def _exotic_events(kinds, kind, par, k, aux, ox, oy, oz, dx, dy, dz, et, ef, cap, stack):
    return dispatch(kinds, "events", EVENTS_ARGS, "0")


def exotic_normal(kinds, kind, par, k, aux, face, x, y, z, stack):
    """Outward normal (unnormalised) of row ``k`` at an object-space point; ``(0, 0, 0)`` for a
    kind not handled here."""
    raise TypeError("exotic_normal is callable from numba-compiled code only")


@overload(exotic_normal, jit_options=JIT)
def _exotic_normal(kinds, kind, par, k, aux, face, x, y, z, stack):
    return dispatch(kinds, "normal", NORMAL_ARGS, "0.0, 0.0, 0.0")
