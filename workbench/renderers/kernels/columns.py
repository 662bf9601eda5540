"""Named columns of the tables the numba kernels read: materials, lights, texture maps and
the environment, the Whitted and path-tracing options and the kernels' counters (:class:`workbench.core.columns.Columns`:
``NAME = first, span``).  The builders (``workbench.renderers.raytrace.flatten``'s
``_material_row`` and ``light_rows``, ``raytrace.maps.texture_tables``, the sessions' options) write
by name through :func:`~workbench.core.columns.pack`.  The primitive table's per-kind
parameters are named by each kind's ``Par`` (``workbench.scene.kinds``).
"""
from __future__ import annotations

from ...core.columns import Columns, width


class Mat(Columns):
    """Material table ``(M, MAT_COLS)``, one row per scene material."""

    COLOR = 0, 3         # diffuse colour
    KA = 3               # ambient coefficient
    KD = 4               # diffuse coefficient
    KS = 5               # specular coefficient
    SHININESS = 6        # Phong exponent
    KR = 7               # mirror reflection
    KT = 8               # transmission
    IOR = 9              # index of refraction
    ABSORPTION = 10, 3   # Beer absorption per unit length
    EMISSION = 13, 3     # emitted radiance
    FRONT_ONLY = 16      # 1: emits from its front side only
    TEXTURED = 17        # 1: has a colour texture (``Tex`` row of the colour table)
    BUMPED = 18          # 1: has a bump map
    OPACITY = 19         # 1: has an opacity map
    ENVIRONMENT = 20     # 1: reflects the environment map
    MEDIUM = 21          # the primitive row of the heterogeneous medium inside (a hypertexture), -1: none


class Light(Columns):
    """Point and directional light table ``(L, LIGHT_COLS)``."""

    KIND = 0             # 0 point, 1 directional
    POSITION = 1, 3      # position, or direction of a directional light
    POWER = 4, 3         # colour times intensity
    INVERSE_SQUARE = 7   # 1: falls off as 1 / d^2
    COSINE = 8           # 1: a cosine (spot-like) light
    COSINE_NORMAL = 9, 3  # its axis


class Tex(Columns):
    """Texture map table ``(M, TEX_COLS)``, one row per material, of a colour texture, a bump
    map or an opacity map (three tables, :mod:`.textures`; ``KIND`` 0: none)."""

    KIND = 0             # pattern: a ``TEX_*`` code
    PROJ = 1             # projection: a ``PROJ_*`` code
    SCALE = 2            # pattern periods per unit
    CENTER = 3, 3        # pattern origin
    SP = 6, 3            # pole (unit)
    SE = 9, 3            # equator made orthogonal to the pole (unit)
    W = 12, 3            # SP x SE
    COLOR0 = 15, 3       # first colour
    COLOR1 = 18, 3       # second colour
    WIDTH = 21           # mortar (bricks, bump bricks) or line width (grid opacity)
    STRENGTH = 22        # bump strength
    VALUE = 23           # constant opacity
    IMAGE = 24           # first value of the image in the pixel array (RGBA rows, top first)
    IMAGE_W = 25         # its width
    IMAGE_H = 26         # its height
    ALPHA = 27           # opacity image: 1 its alpha channel, 0 its luminance


(TEX_NONE, TEX_CHECKER, TEX_BRICKS, TEX_GRID, TEX_MARBLE, TEX_WOOD, TEX_IMAGE, TEX_NOISE, TEX_WAVES,
 TEX_CONSTANT) = range(10)
"""``Tex.KIND`` codes: the patterns of :mod:`workbench.renderers.texturing` (colour, bump, opacity)."""
PROJ_PLANAR, PROJ_CYLINDRICAL, PROJ_SPHERICAL, PROJ_UV, PROJ_SOLID = range(5)
"""``Tex.PROJ`` codes."""


class Env(Columns):
    """What a ray leaving the scene sees and the texturing tolerances ``(ENV_COLS,)``."""

    KIND = 0             # ENV_NONE (the background colour), ENV_SKY or ENV_IMAGE
    HORIZON = 1, 3
    ZENITH = 4, 3
    GROUND = 7, 3
    IMAGE = 10           # lat-long image: first value in the pixel array
    IMAGE_W = 11
    IMAGE_H = 12
    ZERO = 13            # tol.zero (the poles of the projections)
    BUMP_STEP = 14       # tol.bump_step


ENV_NONE, ENV_SKY, ENV_IMAGE = range(3)
"""``Env.KIND`` codes."""


class WhittedOpt(Columns):
    """Options of the Whitted kernels ``(WHITTED_OPTS,)``."""

    GENERATIONS = 0      # bound on a ray's generation (max_depth and threshold)
    THRESHOLD = 1        # adaptive depth control: weights below end a ray
    FRESNEL = 2          # 0 none, 1 Schlick, 2 exact
    TRANSMISSIVE_SHADOWS = 3
    BLINN = 4            # 1: Blinn-Phong highlight
    SHADOWS = 5          # 1: shadow feelers
    REFLECTION = 6       # 1: reflected children
    REFRACTION = 7       # 1: refracted children
    RAY_OFFSET = 8       # tol.ray_offset
    T_MIN = 9            # tol.t_min
    ZERO = 10            # tol.zero
    EXTENT = 11          # the scene's size
    BACKGROUND = 12      # 1: a missed ray takes the background colour (no environment map)
    N_MEDIA = 13         # media around the camera
    MEDIA = 14, 4        # their material rows, innermost last
    STEP_SCALE = 18      # multiplies every heterogeneous medium's march step; 0: the scene has none


class PathOpt(Columns):
    """Options of the path tracer's kernels ``(PATH_OPTS,)``."""

    FRESNEL = 0          # 0 none, 1 Schlick, 2 exact
    RAY_OFFSET = 1
    T_MIN = 2
    ZERO = 3
    EXTENT = 4
    NORMAL_CANCEL = 5    # tol.normal_cancel
    RR_START = 6         # bounce at which Russian roulette starts
    MAX_BOUNCES = 7
    TEXTURED = 8         # 1: textures evaluated (the fused checkers)
    MIS_BETA = 9         # multiple importance sampling: 0 off, else the power heuristic's beta
    BACKGROUND = 10, 3   # background radiance
    N_MEDIA = 13
    MEDIA = 14, 4        # their material rows, innermost last
    TRANSPORT = 18       # 0 full, 1 diffuse (see pathtrace.kernels)
    PIXEL_FILTER = 19    # 0 box, 1 pixel centre
    HAS_MEDIA = 20       # 1: heterogeneous media (hypertextures): tracked, shadow rays see through them


class RayCount(Columns):
    """Ray counts of the Whitted kernels, a row per ray or per task ``(RAY_COUNTS,)``; the
    renderer's ``stats`` holds them under the members' lower-case names."""

    SHADOW_RAYS = 0          # shadow feelers traced
    ENDED_BY_DEPTH = 1       # children not spawned: the generation bound
    ENDED_BY_THRESHOLD = 2   # children not spawned: weight below the threshold
    TOTAL_INTERNAL_REFLECTIONS = 3
    REFLECTED_RAYS = 4
    REFRACTED_RAYS = 5
    ESCAPED_RAYS = 6         # missed everything


class PathCount(Columns):
    """Counts of the path tracer's kernels ``(PATH_COUNTS,)``; the session's ``stats`` holds
    them under the members' lower-case names."""

    CAMERA_RAYS = 0
    EXTENSION_RAYS = 1
    SHADOW_RAYS = 2
    ENDED_BY_ROULETTE = 3
    ESCAPED_PATHS = 4
    NONFINITE_SAMPLES = 5    # recorded as 0
    ENDED_BY_BOUNCE_CAP = 6  # paths stopped at ``max_bounces``


class WalkCount(Columns):
    """The two counters of a counting tree walk (:func:`.walks.bvh_walk`,
    :func:`.intersect.prim_tree_walk` with ``count``), a run of :class:`TraversalCount`."""

    NODES = 0                # 4-wide nodes visited
    TESTS = 1                # primitive tests (triangles: four per leaf group)


class TraversalCount(Columns):
    """Per-ray traversal statistics ``(N, TRAVERSAL_COUNTS)``
    (:mod:`workbench.renderers.raytrace.traversal_stats`): a :class:`WalkCount` pair per
    structure."""

    TRIANGLES = 0, 2         # the triangles' BVH: nodes, tests
    ANALYTIC = 2, 2          # the analytic primitives' tree (and list): nodes, tests


MAT_COLS, LIGHT_COLS, TEX_COLS, ENV_COLS = width(Mat), width(Light), width(Tex), width(Env)
WHITTED_OPTS, PATH_OPTS = width(WhittedOpt), width(PathOpt)
RAY_COUNTS, PATH_COUNTS = width(RayCount), width(PathCount)
TRAVERSAL_COUNTS = width(TraversalCount)
