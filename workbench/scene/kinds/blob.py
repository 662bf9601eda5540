"""``blob``: metaballs (POV-Ray's ``blob``; Wyvill, McPheeters & Wyvill, "Data structure for soft
objects", The Visual Computer 2, 1986).

Components ``(centre c_i, radius r_i, strength s_i)`` and a ``threshold`` T > 0.  The field

    F(P) = sum_i s_i (1 - |P - c_i|^2 / r_i^2)^2        over the components with |P - c_i| < r_i

is C1 (each term and its gradient vanish on the component's sphere); the solid is F > T, the
surface F = T, the outward normal -grad F = sum_i 4 s_i q_i (P - c_i) / r_i^2 with
``q_i = 1 - |P - c_i|^2 / r_i^2``.  One component alone is a sphere of radius
``r sqrt(1 - sqrt(T / s))`` (when s > T).

Ray intersection, exact per interval: along ``P = O + t u`` (u unit) each component contributes
``s q(t)^2`` with ``q`` quadratic in t on the chord where the ray is inside its sphere; between
consecutive sorted chord endpoints the field is one quartic ``p(v) = sum s q^2 - T``, expanded
about the interval's midpoint ``t_m`` (``v = t - t_m``; the expansion about a point inside the
interval keeps the coefficients well conditioned at any distance of the origin).  Its real
roots in the interval are isolated by its critical points (roots of the cubic ``p'``, isolated
in turn by the roots of the quadratic ``p''``): on each piece between them ``p`` is monotone,
so a sign change brackets exactly one root, narrowed to adjacent floating-point numbers
(bisection in the readable twin, the Illinois method in the numba one; the accuracy is that of
evaluating ``p``).  A tangent (double) root is no crossing.

Aux layout (:func:`params`): ``5 n`` floats ``(cx, cy, cz, r, s)`` per component; parameter
row: ``[aux offset, n, T]``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import Polynomial

from ...core.columns import Columns, pack
from .. import model as m
from ..parts import make_part
from . import values as val
from .aux_rows import AUX_OFFSET, flatten_aux
from .crossing_events import BISECTIONS
from .marching_cubes import grid_cells, marching_cubes, shade_normals

TYPE = "blob"
FEATURE = "blobs"
PTYPE = 7
"""Its ``ptype`` in the ray tracer's primitive table."""
SOLID = True
CONVEX = False
CLOSED_TESSELLATION = True
KERNELS = "workbench.scene.kinds.blob_kernels"
COMPOSITE = False
KEYS = frozenset({"threshold", "components"})
REQUIRED = KEYS
LEVEL_CELLS = 8
"""Marching-cubes cells along the longest side of the bounds per tessellation level."""
MAX_COMPONENTS = 256
"""Most components a blob may have (the kernels' cost per ray is quadratic in their number)."""


@dataclass(frozen=True, eq=False)
class Blob(m.SceneObject):
    """Metaballs.  ``components`` (n, 5): rows ``(cx, cy, cz, radius, strength)``;
    ``threshold`` > 0."""

    components: np.ndarray = field(default_factory=lambda: np.array([[0.0, 0.0, 0.0, 1.0, 1.0]]))
    threshold: float = 0.5
    kind = "blob"


MODEL = Blob


# --------------------------------------------------------------------------- parse
def read(t: dict, where: str, common: dict) -> Blob:
    """Read ``{threshold = T, components = [{center = [x, y, z], radius = r, strength = s}, ...]}``
    (``common``: the keys every object has, already read: material, transform, ...)."""
    val.check_keys(t, where, val.COMMON | KEYS, REQUIRED)
    threshold = val.number(t, where, "threshold", lo=0.0, lo_open=True)
    comps = t.get("components")
    if not isinstance(comps, list) or not 1 <= len(comps) <= MAX_COMPONENTS:
        val.fail(f"{where}.components", f"expected a list of 1 to {MAX_COMPONENTS} tables "
                 f"{{center, radius, strength}}, got {comps!r}"[:200])
    rows = []
    for i, c in enumerate(comps):
        w = f"{where}.components[{i}]"
        val.check_keys(c, w, {"center", "radius", "strength"}, {"center", "radius"})
        s = val.number(c, w, "strength", 1.0)
        if s == 0.0:
            val.fail(f"{w}.strength", "must not be 0")
        rows.append((*val.vector(c, w, "center"), val.number(c, w, "radius", lo=0.0, lo_open=True), s))
    C = np.array(rows, dtype=np.float64)
    if not (C[:, 4] > 0).any():
        val.fail(f"{where}.components", "needs a component of positive strength (else the field never "
                 "exceeds the threshold)")
    return Blob(components=C, threshold=threshold, **common)


def parse(ctx, t: dict, where: str, common: dict) -> Blob:
    """:func:`read` with its error handed to the scene reader's ``ctx.fail``."""
    return val.parse_with(ctx, read, t, where, common)


def bound_points(b: Blob) -> np.ndarray:
    """(8, 3) corners of :func:`bounds`."""
    lo, hi = bounds(b)
    return np.array([np.where(np.array(s, bool), hi, lo) for s in np.ndindex(2, 2, 2)])


def bounds(b: Blob) -> tuple[np.ndarray, np.ndarray]:
    """Object-space box of the solid: the spheres of the positive components (negative ones
    only take away)."""
    C = b.components[b.components[:, 4] > 0]
    return (C[:, :3] - C[:, 3:4]).min(0), (C[:, :3] + C[:, 3:4]).max(0)


# --------------------------------------------------------------------------- readable twin
def field_value(b: Blob, P) -> np.ndarray:
    """F at points P (..., 3)."""
    P = np.asarray(P, dtype=np.float64)
    out = np.zeros(P.shape[:-1])
    for cx, cy, cz, r, s in b.components:
        q = 1.0 - ((P - (cx, cy, cz)) ** 2).sum(-1) / (r * r)
        out += np.where(q > 0.0, s * q * q, 0.0)
    return out


def gradient(b: Blob, P) -> np.ndarray:
    """-grad F at points P (..., 3): the outward normal direction (not normalised)."""
    P = np.asarray(P, dtype=np.float64)
    out = np.zeros(P.shape)
    for cx, cy, cz, r, s in b.components:
        d = P - (cx, cy, cz)
        q = 1.0 - (d * d).sum(-1) / (r * r)
        out += np.where(q[..., None] > 0.0, 4.0 * s * q[..., None] * d / (r * r), 0.0)
    return out


def inside(b: Blob, P) -> np.ndarray:
    """F(P) > T (bool, shape of P without its last axis)."""
    return field_value(b, P) > b.threshold


def _chord(c, r, O, u):
    """``(t0, t1)`` where the unit ray ``O + t u`` is inside the sphere ``(c, r)``, or None
    (Haines et al., "Precision improvements for ray/sphere intersection", Ray Tracing Gems 2019)."""
    f = O - c
    b = f @ u
    disc = r * r - np.sum((f - b * u) ** 2)
    if not disc > 0.0:
        return None
    q = -b - math.sqrt(disc) if b >= 0 else -b + math.sqrt(disc)
    nf = np.linalg.norm(f)
    t0 = (nf - r) * (nf + r) / q if q != 0.0 else -math.sqrt(disc)
    return min(t0, q), max(t0, q)


def _bisect(p, a, b):
    """Narrow ``[a, b]`` where ``p > 0`` differs at the two ends to adjacent floats; the end
    past the change."""
    sa = p(a) > 0.0
    for _ in range(BISECTIONS):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        if (p(m) > 0.0) == sa:
            a = m
        else:
            b = m
    return b


def crossings(b: Blob, O, D) -> list[tuple[float, int]]:
    """Every crossing of the surface by the line ``O + t D`` (object space), sorted, as
    ``(t, 0)``; they alternate entering / leaving (the line starts outside)."""
    O, D = np.asarray(O, dtype=np.float64), np.asarray(D, dtype=np.float64)
    s = float(np.linalg.norm(D))
    u = D / s
    chords = []
    for cx, cy, cz, r, st in b.components:
        ch = _chord(np.array([cx, cy, cz]), r, O, u)
        if ch is not None:
            chords.append((ch, np.array([cx, cy, cz]), r, st))
    ends = sorted({e for ch in chords for e in ch[0]})
    out = []
    for e0, e1 in zip(ends[:-1], ends[1:]):
        tm = 0.5 * (e0 + e1)
        p = Polynomial([-b.threshold])
        for (ta, tb), c, r, st in chords:
            if ta < tm < tb:
                g = O + tm * u - c
                p = p + st * Polynomial([1.0 - g @ g / (r * r), -2.0 * (g @ u) / (r * r), -1.0 / (r * r)]) ** 2
        lo, hi = e0 - tm, e1 - tm
        crit = [float(z.real) for z in p.deriv().roots() if z.imag == 0.0 and lo < z.real < hi]
        pts = [lo, *sorted(crit), hi]
        for a, c in zip(pts[:-1], pts[1:]):
            if (p(a) > 0.0) != (p(c) > 0.0):
                out.append(((tm + _bisect(p, a, c)) / s, 0))
    return out


def hits(b: Blob, O, D, solid: bool = True) -> list[tuple[float, int]]:
    """The registry's name for :func:`crossings` (a blob is always a solid)."""
    return crossings(b, O, D)


def normal(b: Blob, face: int, P) -> np.ndarray:
    """Unit outward normal at the surface point P (3,)."""
    g = gradient(b, P)
    return g / np.linalg.norm(g)


def intersect(b: Blob, O, D, tmin: float = 0.0, tmax: float = np.inf):
    """First crossing ``tmin < t < tmax``: ``(t, unit normal)``, or ``(inf, None)``."""
    for t, f in crossings(b, O, D):
        if tmin < t < tmax:
            return t, normal(b, f, np.asarray(O) + t * np.asarray(D))
    return np.inf, None


# --------------------------------------------------------------------------- tessellation
def mesh(b: Blob, resolution: int):
    """Marching cubes over the bounds (``resolution`` cells along their longest side, plus a
    cell of margin): ``(P (V, 3), N (V, 3) unit outward normals, F (T, 3) int64)``, object space."""
    lo, hi = bounds(b)
    h = (hi - lo).max() / resolution
    lo, hi = lo - h, hi + h
    n = grid_cells(lo, hi, resolution + 2, f"blob {b.name!r}")
    xs, ys, zs = (np.linspace(a, c, k + 1) for a, c, k in zip(lo, hi, n))
    G = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), -1)
    P, F = marching_cubes(b.threshold - field_value(b, G), xs, ys, zs,
                          field=lambda X: b.threshold - field_value(b, X))
    return shade_normals(P, F, lambda X: gradient(b, X), lo, hi)


def solid_mesh(b: Blob, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed object-space mesh ``(P (V, 3), F (T, 3))`` at ``LEVEL_CELLS * level`` cells (for
    the raster's CSG booleans)."""
    P, _, F = mesh(b, LEVEL_CELLS * level)
    return P, F


def analytic_normals(b: Blob, P: np.ndarray):
    """Object-space normals (-grad F) at points P (n, 3), and no cap."""
    return gradient(b, P), np.zeros(len(P), dtype=bool)


def tessellate(obj: Blob, level: int, M: np.ndarray) -> list:
    """The raster's triangles: one Part of :func:`mesh` at level * LEVEL_CELLS cells."""
    P, N, F = mesh(obj, LEVEL_CELLS * level)
    return [make_part(obj, M, P, N, F, None, None)]


def patch_surfaces(obj: Blob, W: np.ndarray, h: float):
    """Radiosity: curved, cut from its tessellation (None)."""
    return None


# --------------------------------------------------------------------------- kernel rows
# (the numba entry points, in .blob_kernels: see .crossing_events for their signatures)


class Par(Columns):
    """Its columns of the primitive table's ``par``: ``COUNT`` components of 5 numbers
    (centre, radius, strength) in ``aux``, and the field's threshold."""

    OFFSET = AUX_OFFSET
    COUNT = 1
    THRESHOLD = 2


def flatten(b, obj, index: int, W: np.ndarray, top: bool) -> int:
    """Its row of the ray tracer's primitive table (:func:`.aux_rows.flatten_aux`)."""
    return flatten_aux(b, obj, index, W, top, PTYPE, params(obj, 0), SOLID)


def params(b: Blob, aux_offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameter row head (:class:`Par`) and aux (5 n,)."""
    return (pack(Par, offset=aux_offset, count=len(b.components), threshold=b.threshold),
            np.ascontiguousarray(b.components, dtype=np.float64).reshape(-1))


# --------------------------------------------------------------------------- exporters
def povray(b: Blob, w, in_csg: bool) -> str:
    """POV-Ray's ``blob``: its field is the same (POV-Ray 3.7's ``Make_Blob``: each spherical
    component adds ``strength (1 - (d/radius)^2)^2`` inside its radius; the solid is where the
    sum exceeds ``threshold``), one ``sphere { <c>, radius, strength s }`` per component;
    ``sturm`` (Sturm sequences instead of the closed-form quartic solver: exact roots, as our
    interval solver)."""
    comps = " ".join(f"sphere {{ {w.vec(c[:3])}, {w.num(c[3])}, strength {w.num(c[4])} }}" for c in b.components)
    return (f"blob {{ threshold {w.num(b.threshold)} {comps} sturm {w.texture(b.material)} "
            f"{w.matrix(b.world_from_object)} }}")


def mitsuba(b: Blob, x) -> list[dict]:
    """No blob in Mitsuba 3: its raster tessellation (marching cubes) at the export's level,
    noted in ``left_out``."""
    level = b.tessellation or x.level
    x.leave(FEATURE, f"no blob primitive in Mitsuba 3: exported as its raster tessellation "
            f"(marching cubes, {LEVEL_CELLS} x level cells along the longest side; level {level})")
    return x.tessellated(b, level)
