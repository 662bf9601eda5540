"""``isosurface``: the solid ``f(x, y, z) < threshold`` inside a box (POV-Ray's ``isosurface``
with ``contained_by { box }``, closed where the solid meets the box), ``f`` a user expression
(:mod:`.expression`, compiled once) with a declared Lipschitz bound ``max_gradient`` >= |grad f|.

Ray intersection (both twins, the same steps): clip the ray to the box (slabs); the solid's
status along the chord is ``g(t) = f(O + t D) - threshold < 0`` (NaN counts as outside).
March by sphere tracing (Hart, "Sphere tracing", The Visual Computer 12, 1996): with
``L = max_gradient |D|`` a Lipschitz bound of g in t, g keeps its sign over ``|g(t)| / L``, so
the step ``h = max(|g(t)| / L, h_min)`` cannot jump a crossing unless it is the floor
``h_min = MIN_STEP (t1 - t0)``, a fixed fraction of the chord (only features thinner than
that along the ray, where the surface also comes within ``h_min L`` of the ray in value, may
be missed).  A change of status between two steps is narrowed to adjacent floating-point
numbers (bisection in the readable twin, the Illinois method in the numba one): the accuracy
of the hit is that of evaluating f.  Normals: the exact
gradient of f by forward-mode automatic differentiation of the program; on the box's faces,
the face's normal.

Aux layout: the program's ``(opcode, argument)`` pairs; parameter row ``[aux offset, program
length, threshold, max_gradient, lo (3), hi (3), stack depth]``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...core.columns import Columns, pack
from .. import model as m
from ..parts import make_part
from . import values as val
from .aux_rows import AUX_OFFSET, flatten_aux
from .crossing_events import BISECTIONS
from .expression import Program, compile_expression, evaluate_numpy, gradient_numpy, povray_function
from .marching_cubes import closed_grid, grid_cells, marching_cubes, pad_outside, shade_normals

TYPE = "isosurface"
FEATURE = "isosurfaces"
PTYPE = 8
"""Its ``ptype`` in the ray tracer's primitive table."""
SOLID = True
CONVEX = False
CLOSED_TESSELLATION = True
KERNELS = "workbench.scene.kinds.isosurface_kernels"
COMPOSITE = False
KEYS = frozenset({"function", "threshold", "max_gradient", "bounds"})
REQUIRED = frozenset({"function", "max_gradient", "bounds"})
LEVEL_CELLS = 8
"""Marching-cubes cells along the longest side of the bounds per tessellation level."""
MIN_STEP = 2.0 ** -16
"""Smallest marching step, as a fraction of the ray's chord through the bounds (bounds the
work per ray by 2^16 steps)."""
GRADIENT_CHECK = 17
"""Samples per axis of the grid on which the function and its declared ``max_gradient`` are
checked at load (:func:`check_samples`)."""
SLOPE_MARGIN = 1e-9
"""Relative margin of the finite-difference check of ``max_gradient`` (:func:`check_samples`):
far above the rounding of a few float64 operations (about 1e-16 each), far below any
meaningful excess."""


@dataclass(frozen=True, eq=False)
class Isosurface(m.SceneObject):
    """``function`` < ``threshold`` inside ``[bounds_min, bounds_max]``; ``program`` is the
    compiled function (made from ``function`` when not given)."""

    function: str = "x^2 + y^2 + z^2"
    threshold: float = 1.0
    max_gradient: float = 4.0
    bounds_min: tuple = (-1.5, -1.5, -1.5)
    bounds_max: tuple = (1.5, 1.5, 1.5)
    program: Program | None = None
    kind = "isosurface"

    def __post_init__(self):
        if self.program is None:
            object.__setattr__(self, "program", compile_expression(self.function))


MODEL = Isosurface


# --------------------------------------------------------------------------- parse
def read(t: dict, where: str, common: dict) -> Isosurface:
    """Read ``{function = "...", threshold = T, max_gradient = L, bounds = {min, max}}``; the
    function is sampled over the bounds at load (:func:`check_samples`)."""
    val.check_keys(t, where, val.COMMON | KEYS, REQUIRED)
    if not isinstance(t.get("function"), str):
        val.fail(f"{where}.function", f"expected an expression of x, y, z as a string, got {t.get('function')!r}")
    try:
        prog = compile_expression(t["function"])
    except Exception as e:  # noqa: BLE001 -- WorkbenchError, re-raised with the key in front
        val.fail(f"{where}.function", str(e))
    threshold = val.number(t, where, "threshold", 0.0)
    L = val.number(t, where, "max_gradient", lo=0.0, lo_open=True)
    lo, hi = val.box(t, where, "bounds")
    check_samples(prog, L, lo, hi, where)
    return Isosurface(function=t["function"], threshold=threshold, max_gradient=L,
                      bounds_min=lo, bounds_max=hi, program=prog, **common)


def _point(axes, index) -> list:
    return [float(f"{float(a[i]):.6g}") for a, i in zip(axes, index)]


def check_samples(prog: Program, L: float, lo, hi, where: str):
    """Sample f on a ``GRADIENT_CHECK^3`` grid over the bounds and refuse (one line, naming the
    key and a sample point):

    - a non-finite value (``x/0``, ``sqrt(-1 - x^2)``, ``log(0*x)``): the solid would be
      silently empty or everywhere;
    - a declared Lipschitz bound ``L`` below |grad f| at a sample (the exact gradient; a
      sample where it is not finite, as at the apex of a cone, is left to the next test);
    - ``L`` below the slope between two neighbouring samples a, b along an axis: by the mean
      value theorem a field with |grad f| <= L has |f(a) - f(b)| <= L |a - b|, so a larger
      difference means a steeper or discontinuous field (``floor``).  Refused only beyond
      ``L |a - b| (1 + SLOPE_MARGIN) + SLOPE_MARGIN max(|f(a)|, |f(b)|)``, which covers the
      rounding of f's evaluation and of ``a - b``.
    """
    axes = [np.linspace(a, b, GRADIENT_CHECK) for a, b in zip(lo, hi)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    f, g = gradient_numpy(prog, X, Y, Z)
    bad = ~np.isfinite(f)
    if bad.any():
        i = np.unravel_index(np.argmax(bad), bad.shape)
        val.fail(f"{where}.function", f"{prog.text!r} is {f[i]} at {_point(axes, i)} (sampled over the "
                 "bounds): the function must be finite in its bounds")
    norm = np.linalg.norm(g, axis=-1)
    norm = np.where(np.isfinite(norm), norm, 0.0)
    worst = np.unravel_index(np.argmax(norm), norm.shape)
    if norm[worst] > L:
        val.fail(f"{where}.max_gradient", f"{L:g} is below |grad f| = {norm[worst]:.6g} found at "
                 f"{_point(axes, worst)}: the root search could step over the surface")
    for axis in range(3):
        shape = [1, 1, 1]
        shape[axis] = GRADIENT_CHECK - 1
        h = np.diff(axes[axis]).reshape(shape)
        fa, fb = np.delete(f, -1, axis), np.delete(f, 0, axis)
        df = np.abs(fb - fa)
        over = df > L * h * (1.0 + SLOPE_MARGIN) + SLOPE_MARGIN * np.maximum(np.abs(fa), np.abs(fb))
        if over.any():
            slope = np.where(over, df / h, 0.0)
            i = np.unravel_index(np.argmax(slope), slope.shape)
            j = list(i)
            j[axis] += 1
            val.fail(f"{where}.max_gradient", f"{L:g} is below |f(a) - f(b)| / |a - b| = {slope[i]:.6g} "
                     f"between the samples a = {_point(axes, i)} and b = {_point(axes, j)}: the function "
                     "is steeper than declared (or jumps) and the root search could step over the surface")


def parse(ctx, t: dict, where: str, common: dict) -> Isosurface:
    """:func:`read` with its error handed to the scene reader's ``ctx.fail``."""
    return val.parse_with(ctx, read, t, where, common)


def bound_points(s: Isosurface) -> np.ndarray:
    """(8, 3) corners of the bounds."""
    lo, hi = bounds(s)
    return np.array([np.where(np.array(q, bool), hi, lo) for q in np.ndindex(2, 2, 2)])


def bounds(s: Isosurface) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(s.bounds_min, dtype=np.float64), np.asarray(s.bounds_max, dtype=np.float64)


# --------------------------------------------------------------------------- readable twin
def inside(s: Isosurface, P) -> np.ndarray:
    """f(P) < threshold and P in the bounds (bool, shape of P without its last axis)."""
    P = np.asarray(P, dtype=np.float64)
    lo, hi = bounds(s)
    f = evaluate_numpy(s.program, P[..., 0], P[..., 1], P[..., 2])
    return (f < s.threshold) & (P >= lo).all(-1) & (P <= hi).all(-1)


def _slab(lo, hi, O, D):
    """Kay & Kajiya slabs: ``(t0, face0, t1, face1)`` of the line in the box, or None; face =
    1 + 2 axis + (1 on the max side)."""
    t0, t1, f0, f1 = -np.inf, np.inf, 0, 0
    for a in range(3):
        if D[a] == 0.0:
            if not lo[a] <= O[a] <= hi[a]:
                return None
            continue
        ta, tb = (lo[a] - O[a]) / D[a], (hi[a] - O[a]) / D[a]
        fa, fb = 1 + 2 * a, 2 + 2 * a
        if ta > tb:
            ta, tb, fa, fb = tb, ta, fb, fa
        if ta > t0:
            t0, f0 = ta, fa
        if tb < t1:
            t1, f1 = tb, fb
    return (t0, f0, t1, f1) if t0 < t1 else None


def crossings(s: Isosurface, O, D) -> list[tuple[float, int]]:
    """Every crossing of the solid's boundary by the line ``O + t D`` (object space), sorted,
    as ``(t, face)`` (face 0: the function's surface; 1..6: a face of the bounds); they
    alternate entering / leaving."""
    O, D = np.asarray(O, dtype=np.float64), np.asarray(D, dtype=np.float64)
    lo, hi = bounds(s)
    chord = _slab(lo, hi, O, D)
    if chord is None:
        return []
    t0, f0, t1, f1 = chord

    def g(t):
        return float(evaluate_numpy(s.program, *(O + t * D))) - s.threshold

    L = s.max_gradient * float(np.linalg.norm(D))
    h_min = MIN_STEP * (t1 - t0)
    out = []
    t, gt = t0, g(t0)
    status = gt < 0.0
    if status:
        out.append((t0, f0))
    while t < t1:
        h = abs(gt) / L if math.isfinite(gt) else h_min
        tn = min(t + max(h, h_min), t1)
        gn = g(tn)
        if (gn < 0.0) != status:
            a, b = t, tn
            for _ in range(BISECTIONS):
                mid = 0.5 * (a + b)
                if mid <= a or mid >= b:
                    break
                if (g(mid) < 0.0) == status:
                    a = mid
                else:
                    b = mid
            out.append((b, 0))
            status = not status
            tn, gn = b, g(b)
        t, gt = tn, gn
    if status:
        out.append((t1, f1))
    return out


def hits(s: Isosurface, O, D, solid: bool = True) -> list[tuple[float, int]]:
    """The registry's name for :func:`crossings` (an isosurface is always a solid)."""
    return crossings(s, O, D)


def normal(s: Isosurface, face: int, P) -> np.ndarray:
    """Unit outward normal at P (3,): grad f on the function's surface, the box face's normal
    on a face of the bounds; zero where f has no finite, non-zero gradient."""
    if face >= 1:
        n = np.zeros(3)
        n[(face - 1) // 2] = 1.0 if (face - 1) % 2 else -1.0
        return n
    _, g = gradient_numpy(s.program, *np.asarray(P, dtype=np.float64))
    ln = np.linalg.norm(g)
    return g / ln if np.isfinite(ln) and ln > 0.0 else np.zeros(3)


def intersect(s: Isosurface, O, D, tmin: float = 0.0, tmax: float = np.inf):
    """First crossing ``tmin < t < tmax``: ``(t, unit normal)``, or ``(inf, None)``."""
    for t, f in crossings(s, O, D):
        if tmin < t < tmax:
            return t, normal(s, f, np.asarray(O) + t * np.asarray(D))
    return np.inf, None


# --------------------------------------------------------------------------- tessellation
def mesh(s: Isosurface, resolution: int):
    """Marching cubes over the bounds (``resolution`` cells along their longest side), closed
    on the bounds' faces: ``(P (V, 3), N (V, 3) unit outward normals, F (T, 3) int64)``."""
    P, F = _closed_mesh(s, resolution)
    return shade_normals(P, F, lambda Q: gradient_numpy(s.program, Q[:, 0], Q[:, 1], Q[:, 2])[1], *bounds(s))


def _closed_mesh(s: Isosurface, resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """Marching cubes of ``f - threshold`` over the bounds, padded outside (closed on them)."""
    lo, hi = bounds(s)
    xs, ys, zs = closed_grid(lo, hi, grid_cells(lo, hi, resolution, f"isosurface {s.name!r}"))
    X, Y, Z = np.meshgrid(xs[1:-1], ys[1:-1], zs[1:-1], indexing="ij")
    return marching_cubes(pad_outside(evaluate_numpy(s.program, X, Y, Z) - s.threshold), xs, ys, zs,
                          field=lambda Q: evaluate_numpy(s.program, Q[:, 0], Q[:, 1], Q[:, 2]) - s.threshold)


def solid_mesh(s: Isosurface, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed object-space mesh ``(P (V, 3), F (T, 3))`` at ``LEVEL_CELLS * level`` cells (for
    the raster's CSG booleans; caps included, vertices shared)."""
    return _closed_mesh(s, LEVEL_CELLS * level)


def analytic_normals(s: Isosurface, P: np.ndarray):
    """Object-space normals at points P (n, 3): grad f, or the face's normal on the bounds
    (``cap`` True there)."""
    P = np.asarray(P, dtype=np.float64)
    lo, hi = bounds(s)
    N = gradient_numpy(s.program, P[:, 0], P[:, 1], P[:, 2])[1]
    cap = np.zeros(len(P), dtype=bool)
    for axis in range(3):
        for side, plane in ((-1.0, lo[axis]), (1.0, hi[axis])):
            on = P[:, axis] == plane
            N[on] = 0.0
            N[on, axis] = side
            cap |= on
    return N, cap


def tessellate(obj: Isosurface, level: int, M: np.ndarray) -> list:
    """The raster's triangles: one Part of :func:`mesh` at level * LEVEL_CELLS cells."""
    P, N, F = mesh(obj, LEVEL_CELLS * level)
    return [make_part(obj, M, P, N, F, None, None)]


def patch_surfaces(obj: Isosurface, W: np.ndarray, h: float):
    """Radiosity: curved, cut from its tessellation (None)."""
    return None


# --------------------------------------------------------------------------- kernel rows
# (the numba entry points, in .isosurface_kernels: see .crossing_events for their signatures)


class Par(Columns):
    """Its columns of the primitive table's ``par``: its expression's program (``LENGTH``
    codes in ``aux``, an operand stack ``DEPTH`` deep), the level, the bound on the field's
    gradient, and the bounds box."""

    OFFSET = AUX_OFFSET
    LENGTH = 1
    THRESHOLD = 2
    MAX_GRADIENT = 3
    BOUNDS_MIN = 4, 3
    BOUNDS_MAX = 7, 3
    DEPTH = 10


def flatten(b, obj, index: int, W: np.ndarray, top: bool) -> int:
    """Its row of the ray tracer's primitive table (:func:`.aux_rows.flatten_aux`)."""
    return flatten_aux(b, obj, index, W, top, PTYPE, params(obj, 0), SOLID)


def params(s: Isosurface, aux_offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameter row head (:class:`Par`) and aux (the program's code)."""
    return (pack(Par, offset=aux_offset, length=s.program.length, threshold=s.threshold,
                 max_gradient=s.max_gradient, bounds_min=s.bounds_min, bounds_max=s.bounds_max,
                 depth=s.program.depth),
            np.ascontiguousarray(s.program.code))


# --------------------------------------------------------------------------- exporters
POVRAY_ACCURACY = 1e-7
"""POV-Ray's isosurface ``accuracy`` (its root search stops below it) as a fraction of the
bounds' longest side (POV-Ray's default 0.001 is absolute and coarse)."""


def povray(s: Isosurface, w, in_csg: bool) -> str:
    """POV-Ray's ``isosurface``: ``function { }`` (:func:`.expression.povray_function`, read
    back from the compiled program), ``contained_by { box }`` of the bounds (closed there, as
    ours: no ``open``), ``threshold`` (inside is ``f < threshold`` in both), ``max_gradient``,
    ``accuracy`` :data:`POVRAY_ACCURACY` of the bounds; inside CSG ``all_intersections``
    (POV-Ray keeps only the first crossing of a ray by default)."""
    lo, hi = bounds(s)
    acc = POVRAY_ACCURACY * float((hi - lo).max())
    every = " all_intersections" if in_csg else ""
    return (f"isosurface {{ function {{ {povray_function(s.program)} }} "
            f"contained_by {{ box {{ {w.vec(lo)}, {w.vec(hi)} }} }} threshold {w.num(s.threshold)} "
            f"max_gradient {w.num(s.max_gradient)} accuracy {w.num(acc)}{every} "
            f"{w.texture(s.material)} {w.matrix(s.world_from_object)} }}")


def mitsuba(s: Isosurface, x) -> list[dict]:
    """No implicit surface in Mitsuba 3: its raster tessellation (marching cubes, closed on
    the bounds) at the export's level, noted in ``left_out``."""
    level = s.tessellation or x.level
    x.leave(FEATURE, f"no implicit surface in Mitsuba 3: exported as its raster tessellation "
            f"(marching cubes, {LEVEL_CELLS} x level cells along the bounds' longest side; level {level})")
    return x.tessellated(s, level)
