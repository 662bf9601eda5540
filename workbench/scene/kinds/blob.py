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

import numba as nb
import numpy as np
from numpy.polynomial import Polynomial

from .. import model as m
from ..parts import make_part
from . import values as val
from .marching_cubes import grid_cells, marching_cubes, shade_normals

TYPE = "blob"
FEATURE = "blobs"
PTYPE = 7
"""Its ``ptype`` in the ray tracer's primitive table."""
SOLID = True
CONVEX = False
COMPOSITE = False
KEYS = frozenset({"threshold", "components"})
REQUIRED = KEYS
LEVEL_CELLS = 8
"""Marching-cubes cells along the longest side of the bounds per tessellation level."""
MAX_COMPONENTS = 256
"""Most components a blob may have (the kernels' cost per ray is quadratic in their number)."""
BISECTIONS = 200
"""Bisection steps cap: enough to reach adjacent floats from any bracket of finite width."""


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
    P, F = marching_cubes(b.threshold - field_value(b, G), xs, ys, zs)
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
# (the numba entry points' shared signatures: see .crossing_events)

def flatten(b, obj, index: int, W: np.ndarray, top: bool) -> int:
    """Its row of the ray tracer's primitive table through the builder ``b`` (the registry's
    interface): ``b.bound`` its bounds, ``b.add_aux`` its variable-length data (returns the
    offset), ``b.add`` the row with :func:`params`' head."""
    b.bound(W, bound_points(obj))
    head, data = params(obj, 0)
    head[0] = b.add_aux(data)
    return b.add(PTYPE, index, obj, W, head, top=top, solid=SOLID)


def params(b: Blob, aux_offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameter row head ``[aux offset, n, T]`` (3,) and aux (5 n,)."""
    return (np.array([aux_offset, len(b.components), b.threshold], dtype=np.float64),
            np.ascontiguousarray(b.components, dtype=np.float64).reshape(-1))


@nb.njit(cache=True, error_model="numpy", inline="always")
def _poly(p0, p1, p2, p3, p4, v):
    return (((p4 * v + p3) * v + p2) * v + p1) * v + p0


@nb.njit(cache=True, error_model="numpy")
def _change(p0, p1, p2, p3, p4, a, b):
    """The end past the change of ``poly > 0`` in ``[a, b]`` (where it differs at the ends),
    narrowed to adjacent floats by the Illinois method (regula falsi that halves the value kept
    at an end that stays twice; Dowell & Jarratt, BIT 11, 1971): superlinear, and a
    bisection step wherever the secant point is not strictly inside the bracket."""
    fa, fb = _poly(p0, p1, p2, p3, p4, a), _poly(p0, p1, p2, p3, p4, b)
    sa = fa > 0.0
    side = 0
    for _ in range(BISECTIONS):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        c = (a * fb - b * fa) / (fb - fa)
        if not (a < c < b):
            c = m
        fc = _poly(p0, p1, p2, p3, p4, c)
        if (fc > 0.0) == sa:
            a, fa = c, fc
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            b, fb = c, fc
            if side == 1:
                fa *= 0.5
            side = 1
    return b


@nb.njit(cache=True, error_model="numpy")
def _first_change(p0, p1, p2, p3, p4, lo, hi, c1, c2, c3):
    """First point in ``(lo, hi]`` past which ``poly > 0`` differs from its value at ``lo``,
    given the polynomial is monotone between the sorted breakpoints ``c1 <= c2 <= c3``
    (inf when unused); inf when none."""
    s0 = _poly(p0, p1, p2, p3, p4, lo) > 0.0
    a = lo
    for i in range(4):
        c = c1 if i == 0 else (c2 if i == 1 else (c3 if i == 2 else hi))
        if c > hi:
            c = hi
        if c <= a:
            continue
        if (_poly(p0, p1, p2, p3, p4, c) > 0.0) != s0:
            return _change(p0, p1, p2, p3, p4, a, c)
        a = c
    return np.inf


@nb.njit(cache=True, error_model="numpy")
def _quadratic_roots(A, B, C):
    """Sorted real roots of ``A v^2 + B v + C`` (inf when absent); a double root counts as none."""
    if A == 0.0:
        if B == 0.0:
            return np.inf, np.inf
        return -C / B, np.inf
    disc = B * B - 4.0 * A * C
    if not disc > 0.0:
        return np.inf, np.inf
    q = -0.5 * (B + math.copysign(math.sqrt(disc), B))
    r0, r1 = q / A, (C / q if q != 0.0 else -q / A)
    return min(r0, r1), max(r0, r1)


@nb.njit(cache=True, error_model="numpy")
def _quartic_change(p0, p1, p2, p3, p4, lo, hi):
    """First sign change of ``p0 + p1 v + ... + p4 v^4`` in ``(lo, hi]``: the critical points
    (roots of the cubic ``p'``, each bracketed between the roots of ``p''``) cut it into
    monotone pieces."""
    s1, s2 = _quadratic_roots(12.0 * p4, 6.0 * p3, 2.0 * p2)
    # roots of p' = p1 + 2 p2 v + 3 p3 v^2 + 4 p4 v^3 on its monotone pieces
    c = lo
    r1, r2, r3 = np.inf, np.inf, np.inf
    for i in range(3):
        x = _first_change(p1, 2.0 * p2, 3.0 * p3, 4.0 * p4, 0.0, c, hi, s1, s2, np.inf)
        if x == np.inf:
            break
        if i == 0:
            r1 = x
        elif i == 1:
            r2 = x
        else:
            r3 = x
        c = x
    return _first_change(p0, p1, p2, p3, p4, lo, hi, r1, r2, r3)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _chord_nb(aux, j, ox, oy, oz, ux, uy, uz):
    fx, fy, fz = ox - aux[j], oy - aux[j + 1], oz - aux[j + 2]
    r = aux[j + 3]
    b = fx * ux + fy * uy + fz * uz
    px, py, pz = fx - b * ux, fy - b * uy, fz - b * uz
    disc = r * r - (px * px + py * py + pz * pz)
    if not disc > 0.0:
        return False, 0.0, 0.0
    sq = math.sqrt(disc)
    q = -b - sq if b >= 0.0 else -b + sq
    nf = math.sqrt(fx * fx + fy * fy + fz * fz)
    t0 = (nf - r) * (nf + r) / q if q != 0.0 else -sq
    return True, min(t0, q), max(t0, q)


@nb.njit(cache=True, error_model="numpy")
def _interval_quartic(aux, off, n, T, ox, oy, oz, ux, uy, uz, tm):
    """Coefficients (in ``v = t - tm``) of the field minus T on the interval containing ``tm``."""
    p0, p1, p2, p3, p4 = -T, 0.0, 0.0, 0.0, 0.0
    for i in range(n):
        j = off + 5 * i
        ok, ta, tb = _chord_nb(aux, j, ox, oy, oz, ux, uy, uz)
        if ok and ta < tm < tb:
            r2 = aux[j + 3] * aux[j + 3]
            s = aux[j + 4]
            gx, gy, gz = ox + tm * ux - aux[j], oy + tm * uy - aux[j + 1], oz + tm * uz - aux[j + 2]
            a = 1.0 - (gx * gx + gy * gy + gz * gz) / r2
            b = -2.0 * (gx * ux + gy * uy + gz * uz) / r2
            c = -1.0 / r2
            p0 += s * a * a
            p1 += s * 2.0 * a * b
            p2 += s * (b * b + 2.0 * a * c)
            p3 += s * 2.0 * b * c
            p4 += s * c * c
    return p0, p1, p2, p3, p4


@nb.njit(cache=True, error_model="numpy")
def _next_end(aux, off, n, ox, oy, oz, ux, uy, uz, after):
    """Smallest chord endpoint > ``after`` (inf when none)."""
    best = np.inf
    for i in range(n):
        ok, ta, tb = _chord_nb(aux, off + 5 * i, ox, oy, oz, ux, uy, uz)
        if ok:
            if after < ta < best:
                best = ta
            if after < tb < best:
                best = tb
    return best


@nb.njit(cache=True, error_model="numpy")
def blob_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out, cap):
    """Crossings of the surface by ``O + t D`` with ``tmin < t < tmax``, sorted, written to
    ``out`` (at most ``cap``; ``cap = 1`` gives the first hit).  Returns their count.  The
    intervals between chord endpoints are visited in order without sorting (each next endpoint
    is a minimum search), so nothing is allocated."""
    off, n, T = int(par[k, 0]), int(par[k, 1]), par[k, 2]
    s = math.sqrt(dx * dx + dy * dy + dz * dz)
    ux, uy, uz = dx / s, dy / s, dz / s
    lo_t, hi_t = tmin * s, tmax * s
    m = 0
    e0 = _next_end(aux, off, n, ox, oy, oz, ux, uy, uz, -np.inf)
    while e0 < hi_t and m < cap:
        e1 = _next_end(aux, off, n, ox, oy, oz, ux, uy, uz, e0)
        if e1 == np.inf:
            break
        if e1 > lo_t:
            tm = 0.5 * (e0 + e1)
            p0, p1, p2, p3, p4 = _interval_quartic(aux, off, n, T, ox, oy, oz, ux, uy, uz, tm)
            a, b = max(e0, lo_t) - tm, min(e1, hi_t) - tm
            while m < cap:
                v = _quartic_change(p0, p1, p2, p3, p4, a, b)
                if v == np.inf:
                    break
                t = tm + v
                if t > lo_t and t < hi_t:
                    out[m] = t / s
                    m += 1
                a = v
        e0 = e1
    return m


@nb.njit(cache=True, error_model="numpy")
def blob_first(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, out_f, stack):
    """Nearest hit ``tmin < t < tmax``: ``(t, 0)``, ``(inf, 0)`` on a miss."""
    if blob_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, tmin, tmax, out_t, 1) == 1:
        return out_t[0], 0
    return np.inf, 0


@nb.njit(cache=True, error_model="numpy")
def blob_events(par, k, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, cap, stack):
    """Interval list along the whole line (entering / leaving alternate); returns the count."""
    m = blob_crossings(par, k, aux, ox, oy, oz, dx, dy, dz, -np.inf, np.inf, out_t, cap)
    for i in range(m):
        out_f[i] = 0
    return m


@nb.njit(cache=True, error_model="numpy")
def blob_normal(par, k, aux, face, x, y, z, stack):
    """Outward normal -grad F at the object-space point (not normalised)."""
    off, n = int(par[k, 0]), int(par[k, 1])
    nx, ny, nz = 0.0, 0.0, 0.0
    for i in range(n):
        j = off + 5 * i
        r2 = aux[j + 3] * aux[j + 3]
        gx, gy, gz = x - aux[j], y - aux[j + 1], z - aux[j + 2]
        q = 1.0 - (gx * gx + gy * gy + gz * gz) / r2
        if q > 0.0:
            w = 4.0 * aux[j + 4] * q / r2
            nx += w * gx
            ny += w * gy
            nz += w * gz
    return nx, ny, nz


@nb.njit(cache=True, error_model="numpy")
def blob_inside(par, k, aux, x, y, z, stack):
    """F(x, y, z) > T."""
    off, n = int(par[k, 0]), int(par[k, 1])
    F = 0.0
    for i in range(n):
        j = off + 5 * i
        q = 1.0 - ((x - aux[j]) ** 2 + (y - aux[j + 1]) ** 2 + (z - aux[j + 2]) ** 2) / (aux[j + 3] * aux[j + 3])
        if q > 0.0:
            F += aux[j + 4] * q * q
    return F > par[k, 2]
