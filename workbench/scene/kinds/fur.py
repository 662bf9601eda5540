"""``fur``: texels (Kajiya and Kay, "Rendering fur with three dimensional textures", SIGGRAPH
1989), the course's "Texels : rendu d'objets à micro-structures (poils, ...)": an opaque base
surface (a sphere or a box, drawn with the object's ``material``) covered by a shell of texel
cells ``length`` deep, each cell holding a density and a tangent frame, lit by the texel's own
model.

The texel (object space, a point ``x`` of the shell)::

    s(x)   signed distance to the base (0 <= s <= length in the shell), n(x) its gradient, the
           foot point f(x) = x - s n on the base
    roots  one per cell of a cubic lattice of side c = 1 / sqrt(strands) (strands per unit of
           area), at the cell's corner plus c times three lattice hashes (the textures' value
           noise hash), projected onto the base
    D(x)   1 where |f(x) - root| < thickness (1 - s / length) for the nearest root (a strand
           tapering to its tip), else 0
    T(x)   the strand's tangent: n (straight hairs)

Optics: extinction ``density D`` per object-space unit; a strand scatters light by the
Kajiya-Kay model: per unit of absorbed light, ``kd C (Ia + sum_l I_l sin(T, L))`` diffuse and
``ks sum_l I_l max(0, (T.L)(T.d) + sin(T, L) sin(T, d))^shininess`` specular, ``d`` the ray's
direction, ``C`` the hair ``color``: the ray caster and the Whitted tracer march it with shadow
feelers against the surfaces (the fur does not shadow itself in this model); the raster draws
it as layered shells (the classic stand-in); the path tracer sees a medium of albedo ``kd C``
with the isotropic phase function (no specular lobe).

The ray tracer's rows: the base (a ``sphere`` or ``box`` row of its own) and the shell, bounded
by a sphere of radius :func:`bound_radius`, a medium boundary as the hypertexture's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...core.columns import Columns, pack
from ...core.noise import _hash3
from .. import model as m
from . import box as box_kind, sphere as sphere_kind, values as val
from .aux_rows import MEDIUM_BOUND as BOUND_COLUMN

TYPE = "fur"
FEATURE = "texels"
PTYPE = 12
SOLID = True
CONVEX = False
COMPOSITE = False
MEDIUM = True
"""A participating medium (see :mod:`.hypertexture`); its base is a surface row of its own."""
CLOSED_TESSELLATION = True
KERNELS = "workbench.scene.kinds.fur_kernels"
KEYS = frozenset({"base", "size", "length", "strands", "thickness", "density", "color", "kd", "ks", "shininess",
                  "step"})
REQUIRED = frozenset({"base", "size", "length"})


@dataclass(frozen=True, eq=False)
class Fur(m.SceneObject):
    base: str = "sphere"
    size: tuple = (1.0,)
    length: float = 0.2
    strands: float = 400.0
    thickness: float = 0.01
    density: float = 60.0
    color: tuple = (0.5, 0.35, 0.2)
    kd: float = 0.7
    ks: float = 0.3
    shininess: float = 20.0
    step: float = 0.005
    kind = "fur"


MODEL = Fur


def read(t: dict, where: str, common: dict) -> Fur:
    val.check_keys(t, where, val.COMMON | KEYS, REQUIRED)
    base = t["base"]
    if base not in ("sphere", "box"):
        val.fail(f"{where}.base", f"expected sphere or box, got {base!r}")
    size = t["size"] if isinstance(t["size"], list) else [t["size"]]
    size = val.vector({"size": size}, where, "size", n=1 if base == "sphere" else 3)
    if min(size) <= 0.0:
        val.fail(f"{where}.size", f"expected sizes > 0, got {list(size)}")
    num = lambda k, d, **kw: val.number(t, where, k, d, **kw)
    color = val.vector(t, where, "color", default=(0.5, 0.35, 0.2))
    if min(color) < 0.0 or max(color) > 1.0:
        val.fail(f"{where}.color", f"expected values in [0, 1], got {list(color)}")
    f = Fur(base=base, size=tuple(size), length=num("length", None, lo=0.0, lo_open=True),
            strands=num("strands", 400.0, lo=0.0, lo_open=True),
            thickness=num("thickness", 0.01, lo=0.0, lo_open=True),
            density=num("density", 60.0, lo=0.0, lo_open=True), color=color,
            kd=num("kd", 0.7, lo=0.0, hi=1.0), ks=num("ks", 0.3, lo=0.0), shininess=num("shininess", 20.0, lo=0.0),
            step=num("step", 0.005, lo=0.0, lo_open=True), **common)
    if f.thickness >= 0.5 / math.sqrt(f.strands):
        val.fail(f"{where}.thickness", f"must be below half the strands' spacing 1/sqrt(strands) = "
                 f"{1 / math.sqrt(f.strands):.4g}, got {f.thickness}")
    val.march_step(where, f.step, bound_radius(f), "the shell")
    return f


def parse(ctx, t: dict, where: str, common: dict) -> Fur:
    return val.parse_with(ctx, read, t, where, common)


# --------------------------------------------------------------------------- the texel (readable)
def bound_radius(f: Fur) -> float:
    """Radius of the sphere about the origin holding the shell."""
    shape = f.size[0] if f.base == "sphere" else float(np.linalg.norm(f.size))
    return shape + f.length


def _project(f: Fur, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(signed distance (N,), foot points (N, 3)) of object-space points ``p`` (N, 3) outside or
    on the base."""
    if f.base == "sphere":
        r = np.linalg.norm(p, axis=1)
        return r - f.size[0], p * (f.size[0] / np.maximum(r, 1e-300))[:, None]
    b = np.asarray(f.size)
    foot = np.clip(p, -b, b)
    q = np.abs(p) - b
    s = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
    return s, foot


def _roots(f: Fur, cells: np.ndarray) -> np.ndarray:
    """The projected root (N, 3) of each lattice cell (N, 3) int."""
    c = 1.0 / math.sqrt(f.strands)
    j = np.stack([_hash3(cells[:, 0], cells[:, 1], cells[:, 2]),
                  _hash3(cells[:, 0] + 1013, cells[:, 1], cells[:, 2]),
                  _hash3(cells[:, 0], cells[:, 1] + 2027, cells[:, 2])], -1)
    return _project(f, (cells + j) * c)[1]


def density(f: Fur, p: np.ndarray) -> np.ndarray:
    """``D(x)`` (N,) in {0, 1} at object-space points ``p`` (N, 3)."""
    p = np.asarray(p, dtype=np.float64)
    s, foot = _project(f, p)
    c = 1.0 / math.sqrt(f.strands)
    base_cell = np.floor(foot / c).astype(np.int64)
    best = np.full(len(p), np.inf)
    for off in np.ndindex(3, 3, 3):
        r = _roots(f, base_cell + np.array(off) - 1)
        best = np.minimum(best, np.linalg.norm(foot - r, axis=1))
    inside = (s >= 0.0) & (s <= f.length)
    return np.where(inside & (best < f.thickness * (1.0 - np.clip(s, 0, f.length) / f.length)), 1.0, 0.0)


def texel(f: Fur, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(D (N,), T (N, 3))`` at object-space points ``p`` (N, 3): :func:`density` and the
    strand's object-space tangent, the unit direction from the foot point (zero where D = 0 or
    on the base), as the numba ``fur_kernels.texel``."""
    p = np.asarray(p, dtype=np.float64)
    d = density(f, p)
    v = p - _project(f, p)[1]
    n = np.linalg.norm(v, axis=1)
    t = np.where(((d > 0.0) & (n > 0.0))[:, None], v / np.maximum(n, 1e-300)[:, None], 0.0)
    return d, t


def shell_scales(f: Fur, shells: int) -> np.ndarray:
    """(shells, 3) per-axis factors taking the base to each shell of the raster's stand-in:
    shell ``i`` at offset ``o_i = length (i + 1/2) / shells``, the sphere of radius ``r + o_i``
    or the box of half-sizes ``b + o_i`` (each face's plane moved out by ``o_i``, its edges and
    corners square)."""
    size = np.broadcast_to(np.asarray(f.size, dtype=np.float64), (3,))
    o = f.length * (np.arange(shells) + 0.5) / shells
    return (size + o[:, None]) / size


def base_mesh(f: Fur, level: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The base's tessellation in object space at ``level`` (the object's own ``tessellation``
    wins): points (V, 3), unit normals (V, 3) and counter-clockwise faces (F, 3) (what the
    raster scales into shells, :func:`shell_scales`)."""
    parts = _base_kind(f).tessellate(base_object(f), int(f.tessellation or level), np.eye(4))
    offsets = np.cumsum([0] + [len(q.positions) for q in parts[:-1]])
    return (np.concatenate([q.positions for q in parts]), np.concatenate([q.normals for q in parts]),
            np.concatenate([q.faces + o for q, o in zip(parts, offsets)]))


# --------------------------------------------------------------------------- the base surface
def base_object(f: Fur) -> m.SceneObject:
    """The opaque base as an object of its kind (same material, transform, name)."""
    common = dict(material=f.material, world_from_object=f.world_from_object, name=f.name,
                  tessellation=f.tessellation)
    if f.base == "sphere":
        return m.Sphere(**common, radius=f.size[0])
    b = tuple(float(x) for x in f.size)
    return m.Box(**common, min=tuple(-x for x in b), max=b)


def _base_kind(f: Fur):
    return sphere_kind if f.base == "sphere" else box_kind


def bound_points(f: Fur) -> np.ndarray:
    r = bound_radius(f)
    return np.array([r * (2 * np.array(q) - 1) for q in np.ndindex(2, 2, 2)], dtype=np.float64)


def tessellate(f: Fur, level: int, M: np.ndarray) -> list:
    """The base's triangles (the raster draws the shells over them)."""
    return _base_kind(f).tessellate(base_object(f), level, M)


def patch_surfaces(f: Fur, W: np.ndarray, h: float):
    return _base_kind(f).patch_surfaces(base_object(f), W, h)


def hits(f: Fur, O, D, solid: bool):
    """The base's crossings (the readable tracer sees the base only)."""
    return _base_kind(f).hits(base_object(f), O, D, solid)


def normal(f: Fur, face: int, P):
    return _base_kind(f).normal(base_object(f), face, P)


def inside(f: Fur, q) -> bool:
    """Inside the shell's bounding sphere (the camera starts in the fur's medium)."""
    return bool(np.linalg.norm(q) < bound_radius(f))


class Par(Columns):
    """The shell row's columns of ``par``."""

    BASE = 0         # 0 sphere, 1 box
    BOUND = BOUND_COLUMN  # the bounding sphere's radius (.medium_sphere)
    SIZE = 2, 3
    LENGTH = 5
    CELL = 6         # the lattice's side 1 / sqrt(strands)
    THICKNESS = 7
    DENSITY = 8
    COLOR = 9, 3
    KD = 12
    KS = 13
    SHININESS = 14
    STEP = 15


def flatten(b, f: Fur, index: int, W: np.ndarray, top: bool) -> int:
    """Two rows: the base (its kind's row, the object's material) and the shell (a medium)."""
    base = base_object(f)
    _base_kind(f).flatten(b, base, index, W, top)
    size = tuple(f.size) + (0.0,) * (3 - len(f.size))
    par = pack(Par, base=0 if f.base == "sphere" else 1, size=size, length=f.length, cell=1.0 / math.sqrt(f.strands),
               thickness=f.thickness, density=f.density, color=f.color, kd=f.kd, ks=f.ks, shininess=f.shininess,
               step=f.step, bound=bound_radius(f))
    return b.add(PTYPE, index, f, W, par, top=top, solid=SOLID)


def povray(f: Fur, w, in_csg: bool):
    w.leave(FEATURE, "POV-Ray has no texel model: the fur's base is exported without its fur")
    return _base_kind(f).povray(base_object(f), w, in_csg)


def mitsuba(f: Fur, x):
    x.leave(FEATURE, "Mitsuba 3 has no texel model: the fur's base is exported without its fur")
    return _base_kind(f).mitsuba(base_object(f), x)
