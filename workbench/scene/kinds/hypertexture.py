"""``hypertexture``: a participating medium whose density is a base shape's soft region
modulated by noise (Perlin and Hoffert, "Hypertexture", SIGGRAPH 1989), the course's
"HyperTextures : rendu d'objets à micro-structures (poils, feu, ...)".

Density (object space, a point ``x``)::

    s(x)  = signed distance to the base shape (negative inside): a sphere of radius ``size[0]``,
            a box of half extents ``size``, a torus of radii ``size[0]`` (ring) and ``size[1]``
            (tube) about the y axis
    n(x)  = the noise at ``frequency x + phase``: ``turbulence`` (Perlin's sum of |noise| over
            ``octaves``, centred: in [-1/2, 1/2)), ``fbm`` (in (-(1 - 2^-octaves), 1 - 2^-octaves))
            or ``none`` (0); the value noise is the textures' (lowbias32 lattice hashes)
    s'(x) = s(x) - amplitude soft n(x)           the noise moves the surface by up to
                                                 ``amplitude`` soft-region widths
    D0(x) = clamp(1/2 - s'(x) / soft, 0, 1)      the soft region: 1 inside, 0 outside, a ramp
                                                 ``soft`` wide across the (moved) surface
    D(x)  = gain(bias(D0, b), g)                 Perlin's bias(t, b) = t^(ln b / ln 1/2) and
                                                 gain(t, g) = bias(2t, 1-g)/2 below 1/2, else
                                                 1 - bias(2 - 2t, 1-g)/2

Optics: extinction ``sigma_t = density D(x)`` per object-space unit length; single-scattering
albedo ``albedo ramp(D)`` (isotropic phase function), emitted radiance ``emission ramp(D)``
carried by the absorbed fraction (``sigma_a Le``), where ``ramp`` interpolates the colour stops
``[[d, [r, g, b]], ...]`` linearly in the density (white when absent).  D <= 1, so ``density``
is a majorant of ``sigma_t`` everywhere (delta and ratio tracking use it).

The medium is bounded: ``D = 0`` wherever ``s(x) >= soft (1/2 + amplitude n_max)``, which lies
inside a sphere of radius :func:`bound_radius` about the origin; the ray tracer's row is that
sphere, a boundary that refracts nothing (index 1, no surface lighting), so a ray entering it
pushes the medium onto its media stack and the renderers integrate the density along the
segment.  ``step`` (object-space length) is the ray march's step for the methods that march.

The ``material`` of the object is required, as for every object, and used by nothing but the
raster methods' label; the medium's optics are the keys above.

``grid = N`` (N >= 2) replaces the field by its samples at the centres of ``N^3`` cells tiling
the cube ``[-R, R]^3`` (R = :func:`bound_radius`), interpolated trilinearly with the edge cells
repeated beyond the centres (:func:`density_grid`, :func:`sample_grid`): the convention of
OpenGL 3D textures and of Mitsuba's ``gridvolume``, so that every method, Mitsuba included,
renders the same medium (the ground-truth check's twin).

Aux layout (:func:`params`): albedo (3), emission (3), then ``(d, r, g, b)`` per ramp stop.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...core.columns import Columns, pack
from ...core.errors import WorkbenchError
from ...core.noise import value_noise
from .. import model as m
from . import values as val
from .aux_rows import AUX_OFFSET, MEDIUM_BOUND as BOUND_COLUMN, flatten_aux

TYPE = "hypertexture"
FEATURE = "hypertextures"
PTYPE = 11
"""Its ``ptype`` in the ray tracer's primitive table."""
SOLID = True
CONVEX = False
CLOSED_TESSELLATION = False
KERNELS = "workbench.scene.kinds.hypertexture_kernels"
COMPOSITE = False
MEDIUM = True
"""A participating medium: the ray tracer gives its row a boundary material of its own
(:func:`workbench.renderers.raytrace.flatten.medium_boundary`) and its own feature group in
the kernels' marker (compiled only for scenes that have one)."""
KEYS = frozenset({"base", "size", "soft", "noise", "frequency", "amplitude", "octaves", "phase", "bias",
                  "gain", "density", "albedo", "emission", "ramp", "step", "grid"})
REQUIRED = frozenset({"base", "size", "density"})
BASES = {"sphere": 0, "box": 1, "torus": 2}
"""Base shapes and their codes in the parameter row."""
NOISES = {"none": 0, "turbulence": 1, "fbm": 2}
"""Noise kinds and their codes."""
MAX_OCTAVES = 8
MAX_STOPS = 16
MAX_GRID = 256
"""Largest ``grid`` resolution (256^3 float64 numbers in the ray tracer's aux: 128 MiB)."""
MIN_STEPS, MAX_STEPS = val.MARCH_STEPS
"""The march's steps across the bounding sphere's diameter (:func:`.values.march_step`)."""


@dataclass(frozen=True, eq=False)
class Hypertexture(m.SceneObject):
    """A density field (module docstring); ``ramp`` (k, 4) rows ``(d, r, g, b)``."""

    base: str = "sphere"
    size: tuple = (1.0,)
    soft: float = 0.2
    noise: str = "turbulence"
    frequency: float = 4.0
    amplitude: float = 1.0
    octaves: int = 4
    phase: tuple = (0.0, 0.0, 0.0)
    bias: float = 0.5
    gain: float = 0.5
    density: float = 1.0
    albedo: tuple = (0.0, 0.0, 0.0)
    emission: tuple = (0.0, 0.0, 0.0)
    ramp: np.ndarray = field(default_factory=lambda: np.array([[0.0, 1.0, 1.0, 1.0], [1.0, 1.0, 1.0, 1.0]]))
    step: float = 0.02
    grid: int = 0
    kind = "hypertexture"


MODEL = Hypertexture


# --------------------------------------------------------------------------- parse
def read(t: dict, where: str, common: dict) -> Hypertexture:
    val.check_keys(t, where, val.COMMON | KEYS, REQUIRED)
    base = t["base"]
    if base not in BASES:
        val.fail(f"{where}.base", f"expected one of {', '.join(BASES)}, got {base!r}")
    n_size = {"sphere": 1, "box": 3, "torus": 2}[base]
    size = t["size"]
    if n_size == 1 and not isinstance(size, list):
        size = [size]
    size = val.vector({"size": size}, where, "size", n=n_size)
    if min(size) <= 0.0:
        val.fail(f"{where}.size", f"expected sizes > 0, got {list(size)}")
    if base == "torus" and size[1] >= size[0]:
        val.fail(f"{where}.size", f"expected a tube radius below the ring radius, got {list(size)}")
    noise = t.get("noise", "turbulence")
    if noise not in NOISES:
        val.fail(f"{where}.noise", f"expected one of {', '.join(NOISES)}, got {noise!r}")
    ramp = np.array([[0.0, 1.0, 1.0, 1.0], [1.0, 1.0, 1.0, 1.0]])
    if "ramp" in t:
        r = t["ramp"]
        if not (isinstance(r, list) and 1 <= len(r) <= MAX_STOPS):
            val.fail(f"{where}.ramp", f"expected 1 to {MAX_STOPS} stops [[d, [r, g, b]], ...], got {r!r}")
        rows = []
        for i, stop in enumerate(r):
            ok = (isinstance(stop, list) and len(stop) == 2 and val._is_number(stop[0])
                  and isinstance(stop[1], list) and len(stop[1]) == 3 and all(val._is_number(c) for c in stop[1]))
            if not ok or not 0.0 <= stop[0] <= 1.0 or min(stop[1]) < 0.0:
                val.fail(f"{where}.ramp[{i}]", f"expected [d, [r, g, b]] with 0 <= d <= 1 and colours >= 0, got {stop!r}")
            if rows and stop[0] < rows[-1][0]:
                val.fail(f"{where}.ramp[{i}]", f"stops must be in increasing density, {stop[0]} < {rows[-1][0]}")
            rows.append([float(stop[0])] + [float(c) for c in stop[1]])
        ramp = np.array(rows)
    colour = lambda key: val.vector(t, where, key, default=(0.0, 0.0, 0.0))
    albedo, emission = colour("albedo"), colour("emission")
    if min(albedo) < 0.0 or max(albedo) > 1.0:
        val.fail(f"{where}.albedo", f"expected values in [0, 1], got {list(albedo)}")
    if min(emission) < 0.0:
        val.fail(f"{where}.emission", f"expected values >= 0, got {list(emission)}")
    if max(albedo) > 0.0 and max(ramp[:, 1:].ravel()) > 1.0:
        val.fail(f"{where}.ramp", "colours above 1 would give an albedo above 1 (the ramp scales the albedo too)")
    h = Hypertexture(
        base=base, size=tuple(size), soft=val.number(t, where, "soft", 0.2, lo=0.0, lo_open=True),
        noise=noise, frequency=val.number(t, where, "frequency", 4.0, lo=0.0),
        amplitude=val.number(t, where, "amplitude", 1.0, lo=0.0),
        octaves=val.number(t, where, "octaves", 4, lo=1, hi=MAX_OCTAVES, integer=True),
        phase=val.vector(t, where, "phase", default=(0.0, 0.0, 0.0)),
        bias=val.number(t, where, "bias", 0.5, lo=0.0, lo_open=True, hi=0.999),
        gain=val.number(t, where, "gain", 0.5, lo=0.001, hi=0.999),
        density=val.number(t, where, "density", lo=0.0, lo_open=True),
        albedo=albedo, emission=emission, ramp=ramp,
        step=val.number(t, where, "step", 0.02, lo=0.0, lo_open=True),
        grid=val.number(t, where, "grid", 0, lo=0, hi=MAX_GRID, integer=True), **common)
    if h.grid == 1:
        val.fail(f"{where}.grid", "expected 0 (the analytic field) or a resolution >= 2, got 1")
    val.march_step(where, h.step, bound_radius(h), "the medium")
    return h


def parse(ctx, t: dict, where: str, common: dict) -> Hypertexture:
    """:func:`read` with its error handed to the scene reader's ``ctx.fail``."""
    return val.parse_with(ctx, read, t, where, common)


# --------------------------------------------------------------------------- the field (readable)
def noise_bound(h: Hypertexture) -> float:
    """Largest ``|n(x)|`` the noise can take (module docstring)."""
    return {"none": 0.0, "turbulence": 0.5, "fbm": 1.0 - 0.5 ** h.octaves}[h.noise]


def bound_radius(h: Hypertexture) -> float:
    """Radius of an object-space sphere about the origin outside which ``D = 0``: the base
    shape's own bound plus the reach ``soft (1/2 + amplitude n_max)`` of its soft region (the
    signed distances are exact, so ``s(x) < c`` lies within ``c`` of the shape)."""
    s = h.size
    shape = {"sphere": s[0], "box": float(np.linalg.norm(s)), "torus": s[0] + s[-1]}[h.base]
    return shape + h.soft * (0.5 + h.amplitude * noise_bound(h))


def signed_distance(h: Hypertexture, p: np.ndarray) -> np.ndarray:
    """Signed distance (N,) of object-space points ``p`` (N, 3) to the base shape."""
    p = np.asarray(p, dtype=np.float64)
    if h.base == "sphere":
        return np.linalg.norm(p, axis=1) - h.size[0]
    if h.base == "box":
        q = np.abs(p) - np.asarray(h.size)
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
    ring = np.hypot(p[:, 0], p[:, 2]) - h.size[0]
    return np.hypot(ring, p[:, 1]) - h.size[1]


def noise_at(h: Hypertexture, p: np.ndarray) -> np.ndarray:
    """``n(x)`` (N,) (module docstring)."""
    if h.noise == "none":
        return np.zeros(len(p))
    q = np.asarray(p, dtype=np.float64) * h.frequency + np.asarray(h.phase)
    out = np.zeros(len(q))
    for k in range(h.octaves):
        v = value_noise(q * 2.0 ** k)
        out += np.abs(2.0 * v - 1.0) / 2.0 ** (k + 1) if h.noise == "turbulence" else (v - 0.5) / 2.0 ** k
    return out - 0.5 if h.noise == "turbulence" else out


def bias(t, b: float):
    """Perlin's bias ``t^(ln b / ln 1/2)`` (maps 1/2 to b)."""
    return np.power(t, math.log(b) / math.log(0.5))


def gain(t, g: float):
    """Perlin's gain (module docstring)."""
    t = np.asarray(t, dtype=np.float64)
    lo = 0.5 * bias(2.0 * t, 1.0 - g)
    hi = 1.0 - 0.5 * bias(np.maximum(2.0 - 2.0 * t, 0.0), 1.0 - g)
    return np.where(t < 0.5, lo, hi)


def density(h: Hypertexture, p: np.ndarray) -> np.ndarray:
    """``D(x)`` in [0, 1] (N,) at object-space points ``p`` (N, 3) (the grid's, when ``grid``)."""
    if h.grid:
        return sample_grid(density_grid(h, h.grid), bound_radius(h), p)
    return field_density(h, p)


def field_density(h: Hypertexture, p: np.ndarray) -> np.ndarray:
    """The analytic field ``D(x)`` (N,) (module docstring), whatever ``grid`` says."""
    s = signed_distance(h, p) - h.amplitude * h.soft * noise_at(h, p)
    d0 = np.clip(0.5 - s / h.soft, 0.0, 1.0)
    return gain(bias(d0, h.bias), h.gain)


def ramp(h: Hypertexture, d: np.ndarray) -> np.ndarray:
    """Colour (N, 3) of the ramp at densities ``d`` (N,), linear between stops, clamped."""
    d = np.asarray(d, dtype=np.float64)
    return np.stack([np.interp(d, h.ramp[:, 0], h.ramp[:, 1 + c]) for c in range(3)], -1)


# --------------------------------------------------------------------------- grids
GRID_BYTES = 256 << 20
"""Most bytes a density grid (raster 3D texture, Mitsuba volume) may take."""


def grid_bytes(res: int, channels: int = 1, itemsize: int = 4) -> int:
    """Bytes of a ``res^3`` grid of ``channels`` values of ``itemsize`` bytes."""
    return int(res) ** 3 * channels * itemsize


def density_grid(h: Hypertexture, res: int, limit: int = GRID_BYTES) -> np.ndarray:
    """``D`` sampled at the centres of ``res^3`` cells tiling the cube ``[-R, R]^3``
    (R = :func:`bound_radius`), float32 (res, res, res) indexed ``[z, y, x]`` (the layout of
    OpenGL 3D textures and Mitsuba's grid volumes).  Raises WorkbenchError, before allocating,
    when the grid would take more than ``limit`` bytes."""
    if res < 2 or grid_bytes(res) > limit:
        raise WorkbenchError(f"hypertexture grid of {res}^3 cells: {grid_bytes(res) / 2**20:.1f} MiB "
                             f"exceeds the limit of {limit / 2**20:.0f} MiB (or res < 2)")
    R = bound_radius(h)
    c = (np.arange(res) + 0.5) / res * 2.0 * R - R
    out = np.empty((res, res, res), np.float32)
    Y, X = np.meshgrid(c, c, indexing="ij")
    for iz, z in enumerate(c):
        pts = np.stack([X.ravel(), Y.ravel(), np.full(X.size, z)], -1)
        out[iz] = field_density(h, pts).reshape(res, res)
    return out


def sample_grid(grid: np.ndarray, R: float, p: np.ndarray) -> np.ndarray:
    """Trilinear interpolation (N,) of ``grid`` (res, res, res) ``[z, y, x]`` (cell centres
    tiling ``[-R, R]^3``, edges clamped) at object-space points ``p`` (N, 3)."""
    res = grid.shape[0]
    u = np.clip((np.asarray(p, dtype=np.float64) + R) / (2.0 * R) * res - 0.5, 0.0, res - 1.0)
    i0 = np.minimum(np.floor(u).astype(np.int64), res - 2)
    f = u - i0
    out = np.zeros(len(u))
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                w = ((f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1])
                     * (f[:, 2] if dz else 1 - f[:, 2]))
                out += w * grid[i0[:, 2] + dz, i0[:, 1] + dy, i0[:, 0] + dx]
    return out


# --------------------------------------------------------------------------- boundary (the ray tracer's row)
def bound_points(h: Hypertexture) -> np.ndarray:
    """(8, 3) corners of the cube around the bounding sphere."""
    r = bound_radius(h)
    return np.array([r * (2 * np.array(q) - 1) for q in np.ndindex(2, 2, 2)], dtype=np.float64)


def tessellate(h: Hypertexture, level: int, M: np.ndarray) -> list:
    """No surface: the raster methods march the medium instead (or leave it out)."""
    return []


def patch_surfaces(h: Hypertexture, W: np.ndarray, h_: float):
    return None


def hits(h: Hypertexture, O, D, solid: bool) -> list[tuple[float, int]]:
    """Crossings of the bounding sphere."""
    from .sphere import roots
    return roots((0.0, 0.0, 0.0), bound_radius(h), O, D)


def normal(h: Hypertexture, face: int, P) -> np.ndarray:
    return np.asarray(P, dtype=np.float64)


def inside(h: Hypertexture, q) -> bool:
    return bool(np.linalg.norm(q) < bound_radius(h))


class Par(Columns):
    """Its columns of the primitive table's ``par`` (aux: :func:`params`)."""

    OFFSET = AUX_OFFSET
    BOUND = BOUND_COLUMN  # the bounding sphere's radius (.medium_sphere)
    BASE = 2
    SIZE = 3, 3
    SOFT = 6
    NOISE = 7
    FREQUENCY = 8
    AMPLITUDE = 9
    OCTAVES = 10
    PHASE = 11, 3
    BIAS = 14        # the exponent ln b / ln 1/2
    GAIN = 15        # the exponent ln (1 - g) / ln 1/2
    DENSITY = 16
    STEP = 17
    STOPS = 18
    GRID = 19        # 0: the analytic field; else the grid's resolution (its samples follow the stops)


AUX_ALBEDO, AUX_EMISSION, AUX_STOPS = 0, 3, 6
"""Offsets within the object's aux numbers (the grid, when ``grid``, after the ramp's stops)."""


def grid_samples(h: Hypertexture) -> int:
    """Cells of its grid (0 without one)."""
    return h.grid ** 3


def aux_count(h: Hypertexture) -> int:
    """How many numbers :func:`params` puts in aux, counted without building the grid (the ray
    tracer's memory estimate)."""
    return 6 + h.ramp.size + grid_samples(h)


def params(h: Hypertexture, aux_offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameter row head (:class:`Par`) and aux (albedo, emission, ramp stops, grid)."""
    size = tuple(h.size) + (0.0,) * (3 - len(h.size))
    head = pack(Par, offset=aux_offset, base=BASES[h.base], size=size, soft=h.soft, noise=NOISES[h.noise],
                frequency=h.frequency, amplitude=h.amplitude, octaves=h.octaves, phase=h.phase,
                bias=math.log(h.bias) / math.log(0.5), gain=math.log(1.0 - h.gain) / math.log(0.5),
                density=h.density, step=h.step, bound=bound_radius(h), stops=len(h.ramp), grid=h.grid)
    parts = [np.asarray(h.albedo, float), np.asarray(h.emission, float), h.ramp.reshape(-1)]
    if h.grid:
        parts.append(density_grid(h, h.grid).astype(np.float64).reshape(-1))
    aux = np.concatenate(parts)
    return head, aux


def flatten(b, obj: Hypertexture, index: int, W: np.ndarray, top: bool) -> int:
    """Its row: the bounding sphere, solid (a medium); see :func:`params`."""
    return flatten_aux(b, obj, index, W, top, PTYPE, params(obj, 0), SOLID)


# --------------------------------------------------------------------------- exporters
def ramp_is_affine(h: Hypertexture) -> bool:
    """Whether ``ramp`` is one straight line over ``[0, 1]`` (then the trilinear interpolation
    of ``ramp(D)`` between grid samples equals ``ramp`` of the interpolated ``D``)."""
    d = np.unique(np.concatenate([[0.0, 1.0], h.ramp[:, 0]]))
    c = ramp(h, d)
    line = c[0] + d[:, None] * (c[-1] - c[0])
    return bool(np.abs(c - line).max() <= 1e-12 * max(1.0, float(np.abs(c).max())))


MITSUBA_BYTES_PER_CELL = 64
"""Bytes per grid cell of the Mitsuba export: the density (float32 in the exporter, twice in
Mitsuba: the file's grid and its texture: 12) and the RGB albedo grid (36), rounded up."""


def mitsuba_bytes(h: Hypertexture, volume_grid: int) -> int:
    """Bytes the Mitsuba export of ``h`` adds (:func:`mitsuba`): its grids (the object's
    ``grid``, else ``volume_grid`` cells along each side)."""
    return MITSUBA_BYTES_PER_CELL * grid_bytes(h.grid or volume_grid, 1, 1)


def mitsuba(h: Hypertexture, x) -> list[dict] | None:
    """A Mitsuba 3 ``heterogeneous`` medium inside the bounding sphere, through the shape
    writer ``x`` (:class:`workbench.renderers.mitsuba_export.ShapeWriter`):

    - the boundary: ``sphere`` with ``to_world = world_from_object S(R)`` (``x.medium``: a
      ``null`` BSDF, the medium as its interior);
    - ``sigma_t``: a ``gridvolume`` of ``D`` at the centres of the cells tiling ``[-R, R]^3``
      (:func:`density_grid`; ``grid``, else the export's ``x.volume_grid``, noted), trilinear
      and clamped: Mitsuba's grid maps the unit cube through its ``to_world`` =
      ``world_from_object T(-R) S(2R)`` and Dr.Jit's texture puts sample ``i`` at
      ``(i + 1/2) / res`` (``pos res - 1/2``) and clamps the indices: the convention of
      :func:`sample_grid`;
    - ``scale``: ``density / s`` with ``s`` the transform's uniform scale (Mitsuba's extinction
      is per world length, ours per object length); a transform that is not a similarity has no
      such scalar (its length ratio depends on the direction): not exported;
    - ``albedo``: ``albedo ramp`` as a constant when the ramp is one colour, else an RGB
      ``gridvolume`` of ``albedo ramp(D)`` at the same cells (interpolated as colours: exact
      where the ramp is linear, :func:`ramp_is_affine`, noted otherwise);
    - isotropic phase function.  Emission is not exported (Mitsuba 3 has no emissive media)."""
    from ...core import transform as tf
    W = np.asarray(h.world_from_object, dtype=np.float64)
    s = x.similarity_scale(W)
    if s is None:
        x.leave(FEATURE, "a hypertexture under a transform that is not a similarity is not exported: Mitsuba's "
                "extinction is per world length, the same in every direction")
        return []
    R = bound_radius(h)
    res = h.grid or x.volume_grid
    D = density_grid(h, res)
    if not h.grid:
        x.leave(FEATURE, f"the analytic density sampled at {res}^3 cell centres, trilinear (option volume_grid; "
                "the object's grid = N is exact)", approximated=True)
    lo, hi = (-R, -R, -R), (R, R, R)
    V = (W @ tf.translate(lo) @ tf.scale(2.0 * R)).tolist()

    def grid(data):
        return {"type": "gridvolume", "filename": x.write_volume(data, lo, hi), "to_world": V,
                "filter_type": "trilinear", "wrap_mode": "clamp"}

    albedo = np.asarray(h.albedo, dtype=np.float64)
    colours = h.ramp[:, 1:]
    if albedo.max() == 0.0 or np.all(colours == colours[0]):
        alb = {"type": "rgb", "value": [float(c) for c in albedo * colours[0]]}
    else:
        if grid_bytes(res, 3) > GRID_BYTES:
            raise WorkbenchError(f"hypertexture albedo grid of {res}^3 RGB cells: {grid_bytes(res, 3) / 2**20:.1f} "
                                 f"MiB exceeds the limit of {GRID_BYTES / 2**20:.0f} MiB")
        rgb = np.empty(D.shape + (3,), np.float32)
        for iz in range(res):  # slice by slice: ramp's float64 temporaries stay small
            rgb[iz] = (albedo * ramp(h, D[iz].ravel())).reshape(res, res, 3)
        alb = grid(rgb)
        if not ramp_is_affine(h):
            x.leave(FEATURE, "the albedo ramp is interpolated between the grid's samples as colours "
                    "(ramp of the interpolated density elsewhere; they differ where the ramp bends)", approximated=True)
    medium = {"type": "heterogeneous", "sigma_t": grid(D), "scale": float(h.density / s), "albedo": alb,
              "phase": {"type": "isotropic"}}
    if max(h.emission) > 0.0:
        x.leave(FEATURE, "the medium's emission is not exported: Mitsuba 3 has no emissive media "
                "(absorption and scattering only)")
    centre = W[:3, 3]
    cam = np.linalg.solve(W, np.append(np.asarray(x.scene.camera.position, dtype=np.float64), 1.0))[:3]
    sphere = {"type": "sphere", "to_world": (W @ tf.scale(R)).tolist()}
    return [x.medium(sphere, medium, centre - s * R, centre + s * R, around_camera=bool(np.linalg.norm(cam) < R))]


def povray(h: Hypertexture, w, in_csg: bool):
    """Not exported: POV-Ray's noise differs from ours, and its ``density_file df3`` with
    ``interpolate 1`` (3.7's ``density_pattern``) puts sample ``j`` at ``j / S``, wraps the
    upper neighbour periodically and is 0 outside the unit cube, unlike the grid's cell
    centres and clamped edges (a padded df3 would match for a one-colour ramp: see
    docs/hypertextures.md)."""
    w.leave(FEATURE, "not exported: POV-Ray's noise differs from ours, and its df3 density file interpolates "
            "samples at j/S with periodic wrap (our grid: cell centres, clamped edges)")
    return None
