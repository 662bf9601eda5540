"""Named columns of the tables the numba kernels read: materials, lights, fused checker
textures, and the Whitted and path-tracing options.

Each table is a float64 array whose columns are named by an ``IntEnum`` (numba compiles
``mat_tab[mi, Mat.KD]`` to the same load as a literal column).  A member names the first
column of a run where :data:`SPANS` says so (``Mat.COLOR + 1`` is green).  The
builders (``workbench.renderers.raytrace.flatten``'s ``_material_row`` and ``light_rows``,
``whitted.fused_textures``, the sessions' options) write by name through :func:`pack`, which
refuses a table with a column left unnamed or unset.
"""
from __future__ import annotations

from enum import IntEnum

import numpy as np


class Mat(IntEnum):
    """Material table ``(M, MAT_COLS)``, one row per scene material."""

    COLOR = 0          # diffuse colour (3)
    KA = 3             # ambient coefficient
    KD = 4             # diffuse coefficient
    KS = 5             # specular coefficient
    SHININESS = 6      # Phong exponent
    KR = 7             # mirror reflection
    KT = 8             # transmission
    IOR = 9            # index of refraction
    ABSORPTION = 10    # Beer absorption per unit length (3)
    EMISSION = 13      # emitted radiance (3)
    FRONT_ONLY = 16    # 1: emits from its front side only
    TEXTURED = 17      # 1: has a texture (the fused checker or numpy texturing)
    BUMPED = 18        # 1: has a bump map
    OPACITY = 19       # 1: has an opacity map
    ENVIRONMENT = 20   # 1: reflects the environment map


class Light(IntEnum):
    """Point and directional light table ``(L, LIGHT_COLS)``."""

    KIND = 0           # 0 point, 1 directional
    POSITION = 1       # position, or direction of a directional light (3)
    POWER = 4          # colour times intensity (3)
    INVERSE_SQUARE = 7  # 1: falls off as 1 / d^2
    COSINE = 8         # 1: a cosine (spot-like) light
    COSINE_NORMAL = 9  # its axis (3)


class Tex(IntEnum):
    """Fused checker texture table ``(M, TEX_COLS)`` of the per-pixel Whitted kernel."""

    KIND = 0           # CHECKER_PLANAR or CHECKER_SOLID
    SCALE = 1          # checks per unit
    CENTER = 2         # pattern origin (3)
    SE = 5             # planar projection's first axis (3)
    W = 8              # planar projection's second axis (3)
    COLOR0 = 11        # first colour (3)
    COLOR1 = 14        # second colour (3)


CHECKER_PLANAR, CHECKER_SOLID = 1, 2
"""``tex_tab`` kinds of the procedural textures the fused kernel evaluates itself."""


class WhittedOpt(IntEnum):
    """Options of the Whitted kernels ``(WHITTED_OPTS,)``."""

    GENERATIONS = 0    # bound on a ray's generation (max_depth and threshold)
    THRESHOLD = 1      # adaptive depth control: weights below end a ray
    FRESNEL = 2        # 0 none, 1 Schlick, 2 exact
    TRANSMISSIVE_SHADOWS = 3
    BLINN = 4          # 1: Blinn-Phong highlight
    SHADOWS = 5        # 1: shadow feelers
    REFLECTION = 6     # 1: reflected children
    REFRACTION = 7     # 1: refracted children
    RAY_OFFSET = 8     # tol.ray_offset
    T_MIN = 9          # tol.t_min
    ZERO = 10          # tol.zero
    EXTENT = 11        # the scene's size
    BACKGROUND = 12    # 1: a missed ray takes the background colour (no environment map)
    N_MEDIA = 13       # media around the camera
    MEDIA = 14         # their material rows, innermost last (4)


class PathOpt(IntEnum):
    """Options of the path tracer's kernels ``(PATH_OPTS,)``."""

    FRESNEL = 0        # 0 none, 1 Schlick, 2 exact
    RAY_OFFSET = 1
    T_MIN = 2
    ZERO = 3
    EXTENT = 4
    NORMAL_CANCEL = 5  # tol.normal_cancel
    RR_START = 6       # bounce at which Russian roulette starts
    MAX_BOUNCES = 7
    TEXTURED = 8       # 1: textures evaluated (the fused checkers)
    MIS_BETA = 9       # multiple importance sampling: 0 off, else the power heuristic's beta
    BACKGROUND = 10    # background radiance (3)
    N_MEDIA = 13
    MEDIA = 14         # (4)
    TRANSPORT = 18     # 0 full, 1 diffuse (see pathtrace.kernels)
    PIXEL_FILTER = 19  # 0 box, 1 pixel centre
    ONLY_TRIANGLES = 20  # 1: every surface is a triangle (no analytic rows)


SPANS = {"Mat.COLOR": 3, "Mat.ABSORPTION": 3, "Mat.EMISSION": 3, "Light.POSITION": 3, "Light.POWER": 3,
         "Light.COSINE_NORMAL": 3, "Tex.CENTER": 3, "Tex.SE": 3, "Tex.W": 3, "Tex.COLOR0": 3, "Tex.COLOR1": 3,
         "WhittedOpt.MEDIA": 4, "PathOpt.BACKGROUND": 3, "PathOpt.MEDIA": 4}
"""Columns of the members that name a run, by ``Table.MEMBER`` (the others are one column;
keyed by name: members of different tables with one value are equal as ints)."""


def span(c: IntEnum) -> int:
    """Number of columns member ``c`` names."""
    return SPANS.get(f"{type(c).__name__}.{c.name}", 1)


def width(columns: type[IntEnum]) -> int:
    """Number of columns of a table named by ``columns``."""
    return max(int(c) + span(c) for c in columns)


MAT_COLS, LIGHT_COLS, TEX_COLS = width(Mat), width(Light), width(Tex)
WHITTED_OPTS, PATH_OPTS = width(WhittedOpt), width(PathOpt)


def pack(columns: type[IntEnum], **values) -> np.ndarray:
    """One row of a table named by ``columns``, every member given by its lower-case name (a
    scalar, or a sequence of the member's span).  Raises ``KeyError`` on a missing or unknown
    name and ``ValueError`` on a wrong length: a column is never left at a silent zero."""
    given = {k.upper() for k in values}
    names = {c.name for c in columns}
    if given != names:
        raise KeyError(f"{columns.__name__}: missing {sorted(names - given)}, unknown {sorted(given - names)}")
    row = np.zeros(width(columns))
    for c in columns:
        v = np.atleast_1d(np.asarray(values[c.name.lower()], dtype=np.float64))
        if v.shape != (span(c),):
            raise ValueError(f"{columns.__name__}.{c.name}: {v.shape[0]} values for {span(c)} columns")
        row[c:c + len(v)] = v
    return row
