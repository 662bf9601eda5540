"""Named layouts of what the numba kernels take.

:class:`Geometry` is the geometry record every intersection kernel receives: a named tuple
(numba types it field by field and compiles ``geo.ptype`` to a plain load), built by
:meth:`workbench.renderers.raytrace.flatten.SceneData.kernel_args`.  Its last field,
``kinds``, is the kind marker of :func:`kinds_marker`: an empty array whose structured dtype
names the features the scene holds, so that the record's numba type, and with it every kernel
compiled for it, is specialised to that set (:mod:`.specialise`).
"""
from __future__ import annotations

import hashlib
import inspect
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ...scene.kinds import PACKAGE_KINDS, kernel_kinds, kernel_module

MAX_DEPTH = 60
"""Deepest binary level of a BVH build (``raytrace.bvh``): a node there is a leaf whatever its
size (only degenerate input, e.g. triangles at geometrically shrinking spacing, reaches it).
It bounds the traversal stacks: radiosity's visibility test keeps one pending child per
level, the 4-wide walks at most three per level (``walks.BVH_STACK``), so neither ever drops
a node."""

GROUPS = ("csg", "triangles", "analytic")
"""What a kernel compiles only when the scene has it, besides the kinds with kernel modules of
their own: CSG programs, the triangles' BVH walk, and the analytic primitive rows (their
intersection, normals and tree walk: a scene made of triangles only, as the path tracer's
Cornell box, compiles none of it)."""


def marker_name(kind) -> str:
    """A kind's field in the kind marker: its ``TYPE`` for the package's kinds; a plugin's
    ``TYPE`` and a digest of its two modules' sources, so that a kernel compiled, and cached,
    for an older version of a plugin is never reused (the package's own kernel sources key the
    whole cache folder, :mod:`workbench.core.jit_cache`)."""
    if kind.TYPE in PACKAGE_KINDS:
        return kind.TYPE
    h = hashlib.sha256()
    for module in (kind, kernel_module(kind)):
        h.update(Path(inspect.getfile(module)).read_bytes())
    return f"{kind.TYPE}_{h.hexdigest()[:12]}"


def features() -> tuple[str, ...]:
    """Every name a kind marker may hold, in marker order: the kinds with kernel modules of
    their own (:func:`marker_name`, registry order), then :data:`GROUPS`."""
    return tuple(marker_name(k) for k in kernel_kinds()) + GROUPS


def kinds_marker(present) -> np.ndarray:
    """An empty array whose structured dtype has one field per feature present (field order
    that of :func:`features`; a field ``base`` always, so that the dtype is never empty).

    Parameters
    ----------
    present : iterable of names from :func:`features`.

    Returns
    -------
    (0,) structured array; its numba type names the features, nothing else.
    """
    wanted, known = set(present), features()
    unknown = wanted - set(known)
    if unknown:
        raise ValueError(f"unknown kernel features {sorted(unknown)}; known: {', '.join(known)}")
    names = ["base"] + [f for f in known if f in wanted]
    return np.zeros(0, dtype=np.dtype([(n, np.uint8) for n in names]))


def marker_features(kinds) -> tuple[str, ...]:
    """The features a marker (:func:`kinds_marker`, or its numba type) names, in its order."""
    dtype = kinds.dtype
    fields = dtype.fields if isinstance(dtype.fields, dict) else dict(dtype.fields)
    return tuple(f for f in fields if f != "base")


class Geometry(NamedTuple):
    """The scene's geometry as the kernels see it (``P`` primitive rows, ``T`` triangle rows;
    see :mod:`workbench.renderers.raytrace.flatten` for the primitive table and
    :mod:`workbench.renderers.raytrace.accel` for the two trees)."""

    ptype: np.ndarray       # (P,) int64 kind code (``workbench.scene.kinds.*.PTYPE``)
    top: np.ndarray         # (P,) bool: intersected on its own (not a CSG leaf, not a mesh)
    xf: np.ndarray          # (P, 12) object_from_world rows
    nm: np.ndarray          # (P, 9) normal matrix, object to world
    par: np.ndarray         # (P, 20) per-kind parameters
    solid: np.ndarray       # (P,) bool: closed surface with an inside
    shadow: np.ndarray      # (P,) bool: casts shadows
    poly_v: np.ndarray      # (K, 3) polygon vertices, object space
    prog: np.ndarray        # CSG postfix programs: a leaf row >= 0 or a CSG_* operator
    tri_v: np.ndarray       # (T, 9) world-space triangle vertices, BVH order
    tri_n: np.ndarray       # (T, 9) vertex normals
    tri_uv: np.ndarray      # (T, 6) vertex uvs
    tri_e: np.ndarray       # (T, 9) vertex emission
    tri_prim: np.ndarray    # (T,) the mesh's primitive row
    bvh_node: np.ndarray    # triangles' 4-wide BVH (``.bvh.Bvh4``): node boxes
    bvh_child: np.ndarray   # child codes
    bvh_leaf: np.ndarray    # leaves: first packed group, count
    bvh_first: np.ndarray   # first triangle row of each packed group
    bvh_tv4: np.ndarray     # triangles packed by four
    bvh_bounds: np.ndarray  # (6,) box of all triangles
    ident: np.ndarray       # (P,) bool: object space is world space
    aux: np.ndarray         # flat float64 variable-length data of blob, isosurface, lathe, prism
    pfree: np.ndarray       # rows tested by every ray (unbounded primitives)
    pnode: np.ndarray       # analytic primitives' 4-wide tree (``.accel.PrimTree``): nodes
    pchild: np.ndarray      # child codes
    pleaf: np.ndarray       # leaves: first reference, count
    pref: np.ndarray        # primitive row of each leaf reference
    pbounds: np.ndarray     # (6,) box of the bounded primitives
    kinds: np.ndarray       # (0,) kind marker (:func:`kinds_marker`)
