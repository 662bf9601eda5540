"""``lathe``: surface of revolution about the y axis of a profile of ``(r, y)`` points: a polyline
(POV-Ray's ``lathe`` with ``linear_spline``, the default) or, with ``spline = "quadratic" |
"cubic" | "bezier"``, POV-Ray's smooth ``quadratic_spline`` / ``cubic_spline`` / ``bezier_spline``
lathe (:mod:`.lathe_spline` defines those curves, their intersection and normals; this module's
formulas below are the polyline's).

Each segment ``(r0, y0) -> (r1, y1)`` sweeps a piece of a cone (a cylinder when ``r0 = r1``;
an annulus of the plane ``y = y0`` when ``y0 = y1``).  With the segment's radius
``R(y) = r0 + (y - y0) k``, ``k = (r1 - r0) / (y1 - y0)``, and the ray ``O + t D``:
``R(t) = A + B t``, ``A = r0 + (O_y - y0) k``, ``B = D_y k``, the points of the cone satisfy

    (D_x^2 + D_z^2 - B^2) t^2 + 2 (O_x D_x + O_z D_z - A B) t + (O_x^2 + O_z^2 - A^2) = 0

(solved in the stable form, DESIGN errata 7); a root counts when its y lies in the segment's
range (with the rounding slack ``tol.cut (|O| + |t D|)``, as cut quadrics) and on the cone's
nappe ``R(t) >= 0``.  The normal is the segment's: ``(n_r x / rho, n_y, n_r z / rho)`` with
``(n_r, n_y)`` perpendicular to the segment in the (r, y) plane, pointing out of the profile
(its winding decides, by the shoelace area; an open profile's normal points to the right of
its direction of travel, radially outwards for a profile going up).

The lathe is a solid (an inside for CSG, refraction) when its profile is closed: its first
and last points coincide, or both lie on the axis (r = 0).  Inside: the point's ``(rho, y)``
is inside the closed profile (even-odd rule).

Aux layout: ``(r, y)`` per point; parameter row ``[aux offset, points, closed, orientation,
spline code, segments]`` (code 0: linear); a smooth profile's aux is
:func:`.lathe_spline.aux` (``SEG_FLOATS`` per segment).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...core.columns import Columns, pack
from ...core.tol import tol
from .. import model as m
from ..parts import make_part
from . import lathe_spline as spl
from . import values as val
from .aux_rows import AUX_OFFSET, flatten_aux
from .crossing_events import alternate
from .outline import first_crossing

TYPE = "lathe"
FEATURE = "lathes"
PTYPE = 9
"""Its ``ptype`` in the ray tracer's primitive table."""
SOLID = True
"""When its profile is closed (:func:`solid`); an open lathe is a sheet."""
CONVEX = False
CLOSED_TESSELLATION = False
KERNELS = "workbench.scene.kinds.lathe_kernels"
COMPOSITE = False
KEYS = frozenset({"points", "spline"})
REQUIRED = frozenset({"points"})
LEVEL_STEPS = 8
"""Angular steps per tessellation level (as a sphere's segments)."""
MAX_POINTS = 256
TOL_CUT = tol.cut
TOL_ZERO = tol.zero
"""``tol.cut`` and ``tol.zero`` as compile-time constants of the kernels."""


@dataclass(frozen=True, eq=False)
class Lathe(m.SceneObject):
    """Profile ``points`` (k, 2) of ``(r, y)`` (r >= 0 on the curve) joined by ``spline``
    (one of :data:`.lathe_spline.SPLINES`)."""

    points: np.ndarray = field(default_factory=lambda: np.array([[1.0, -1.0], [1.0, 1.0]]))
    spline: str = "linear"
    kind = "lathe"

    @property
    def smooth(self) -> bool:
        return self.spline != "linear"

    @property
    def segments(self) -> np.ndarray:
        """(S, 2, 4) the curve's polynomial segments (:func:`.lathe_spline.segments`)."""
        return spl.segments(self.points, self.spline)

    @property
    def closed(self) -> bool:
        """A solid: the curve's first and last points equal, or both on the axis."""
        a, b = spl.ends(self.points, self.spline)
        return bool((a == b).all() or (a[0] == 0.0 and b[0] == 0.0))

    @property
    def orientation(self) -> float:
        """+1 when the profile, closed by its last-to-first edge, winds counter-clockwise in the
        (r, y) plane (or is open), -1 when clockwise: the sign that makes normals outward."""
        if not self.closed:
            return 1.0
        if self.smooth:
            return 1.0 if spl.signed_area2(self.segments) >= 0.0 else -1.0
        r, y = self.points[:, 0], self.points[:, 1]
        area2 = float(np.sum(r * np.roll(y, -1) - np.roll(r, -1) * y))
        return 1.0 if area2 >= 0.0 else -1.0


MODEL = Lathe


# --------------------------------------------------------------------------- parse
def read(t: dict, where: str, common: dict) -> Lathe:
    """Read ``{points = [[r, y], ...], spline = "linear"}`` (linear: at least 2 points, r >= 0,
    no zero-length segment, no two segments meeting but at the point consecutive ones share
    (:func:`.outline.first_crossing`: a self-crossing profile has no consistent inside);
    smooth: :func:`_read_smooth`)."""
    val.check_keys(t, where, val.COMMON | KEYS, REQUIRED)
    spline = t.get("spline", "linear")
    if spline not in spl.SPLINES:
        val.fail(f"{where}.spline", f"expected one of {', '.join(map(repr, spl.SPLINES))}, got {spline!r}")
    P = val.points(t, where, "points", 2, least=spl.LEAST[spline], most=MAX_POINTS)
    if spline != "linear":
        return _read_smooth(P, spline, where, common)
    if (P[:, 0] < 0).any():
        i = int(np.argmax(P[:, 0] < 0))
        val.fail(f"{where}.points[{i}]", f"radius must be >= 0, got {float(P[i, 0])!r}")
    seg = np.diff(P, axis=0)
    if ((seg == 0).all(1)).any():
        i = int(np.argmax((seg == 0).all(1)))
        val.fail(f"{where}.points[{i + 1}]", "repeats the previous point (a zero-length segment)")
    if (P[:, 0] == 0.0).all():
        val.fail(f"{where}.points", "every point is on the axis (r = 0): the profile sweeps no surface")
    repeat = (P[0] == P[-1]).all()
    crossing = first_crossing(P[:-1] if repeat else P, loop=bool(repeat))
    if crossing is not None:
        i, j = crossing
        val.fail(f"{where}.points", f"the profile crosses itself: segment {i} ({P[i].tolist()} -> "
                 f"{P[i + 1].tolist()}) meets segment {j} ({P[j].tolist()} -> {P[j + 1].tolist()})")
    return Lathe(points=P, **common)


def _read_smooth(P: np.ndarray, spline: str, where: str, common: dict) -> Lathe:
    """A smooth profile: a bezier's points come in fours, each segment starting where the
    previous ended; no segment is a single point; the curve's radius is >= 0 (control points
    off the curve may have any radius) and somewhere > 0."""
    if spline == "bezier":
        if len(P) % 4:
            val.fail(f"{where}.points", f"a bezier profile has 4 points per segment, got {len(P)}")
        for i in range(4, len(P), 4):
            if (P[i] != P[i - 1]).any():
                val.fail(f"{where}.points[{i}]", f"a bezier segment must start where the previous ends "
                         f"(points[{i - 1}] = {P[i - 1].tolist()})")
    segs = spl.segments(P, spline)
    rmax = 0.0
    for i, seg in enumerate(segs):
        if (seg[:, 1:] == 0.0).all():
            val.fail(f"{where}.points", f"{spline} segment {i} is a single point")
        lo, hi = spl.extremes(seg[0])
        size = float(np.abs(seg).max())
        if lo < -tol.cut * size:
            val.fail(f"{where}.points", f"the {spline} curve's radius dips to {lo:.6g} < 0 on segment {i}: "
                     "move its control points away from the axis")
        rmax = max(rmax, hi)
    if rmax <= 0.0:
        val.fail(f"{where}.points", "the curve is on the axis (r = 0): the profile sweeps no surface")
    return Lathe(points=P, spline=spline, **common)


def parse(ctx, t: dict, where: str, common: dict) -> Lathe:
    """:func:`read` with its error handed to the scene reader's ``ctx.fail``."""
    return val.parse_with(ctx, read, t, where, common)


def solid(la: Lathe) -> bool:
    """Has an inside (its profile is closed)."""
    return la.closed


def bound_points(la: Lathe) -> np.ndarray:
    """(8, 3) corners of :func:`bounds`."""
    lo, hi = bounds(la)
    return np.array([np.where(np.array(s, bool), hi, lo) for s in np.ndindex(2, 2, 2)])


def bounds(la: Lathe) -> tuple[np.ndarray, np.ndarray]:
    if la.smooth:
        a = spl.aux(la.segments).reshape(-1, spl.SEG_FLOATS)
        r = a[:, 8].max()
        return np.array([-r, a[:, 9].min(), -r]), np.array([r, a[:, 10].max(), r])
    r = la.points[:, 0].max()
    return (np.array([-r, la.points[:, 1].min(), -r]), np.array([r, la.points[:, 1].max(), r]))


# --------------------------------------------------------------------------- readable twin
def _quadratic(a: float, b: float, c: float) -> list[float]:
    """Real roots, stable form; linear when ``|a c| <= tol.zero b^2``; a double root is none."""
    if abs(a * c) <= tol.zero * b * b:
        return [] if b == 0.0 else [-c / b]
    disc = b * b - 4.0 * a * c
    if not disc > 0.0:
        return []
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    return [q / a, c / q if q != 0.0 else -q / a]


def segment_hits(la: Lathe, i: int, O, D) -> list[float]:
    """Parameters t where the line meets the surface swept by segment ``i``."""
    (r0, y0), (r1, y1) = la.points[i], la.points[i + 1]
    ox, oy, oz = O
    dx, dy, dz = D
    out = []
    if y0 == y1:                         # annulus of the plane y = y0
        if dy != 0.0:
            t = (y0 - oy) / dy
            rho = math.hypot(ox + t * dx, oz + t * dz)
            if min(r0, r1) <= rho <= max(r0, r1):
                out.append(t)
        return out
    k = (r1 - r0) / (y1 - y0)
    A, B = r0 + (oy - y0) * k, dy * k
    for t in _quadratic(dx * dx + dz * dz - B * B, 2.0 * (ox * dx + oz * dz - A * B), ox * ox + oz * oz - A * A):
        slack = TOL_CUT * (max(abs(ox), abs(oy), abs(oz)) + abs(t) * max(abs(dx), abs(dy), abs(dz)))
        y = oy + t * dy
        if min(y0, y1) - slack <= y <= max(y0, y1) + slack and A + B * t >= -slack * abs(k):
            out.append(t)
    return out


def inside(la: Lathe, P) -> np.ndarray:
    """Even-odd test of ``(rho, y)`` against the closed profile (False everywhere when open)."""
    P = np.asarray(P, dtype=np.float64)
    rho, y = np.hypot(P[..., 0], P[..., 2]), P[..., 1]
    res = np.zeros(rho.shape, dtype=bool)
    if not la.closed:
        return res
    if la.smooth:
        segs = la.segments
        return np.vectorize(lambda a, b: spl.inside(segs, float(a), float(b)), otypes=[bool])(rho, y)
    p = la.points
    for (ra, ya), (rb, yb) in zip(p, np.roll(p, -1, axis=0)):
        if ya == yb:
            continue
        cross = (ya > y) != (yb > y)
        r_at = ra + (y - ya) * (rb - ra) / (yb - ya)
        res ^= cross & (rho < r_at)
    return res


def crossings(la: Lathe, O, D) -> list[tuple[float, int]]:
    """Crossings ``(t, segment)`` of the line with the surface, sorted.  A closed lathe's
    alternate entering / leaving (:func:`.crossing_events.alternate`); an open one's are
    every hit."""
    O, D = np.asarray(O, dtype=np.float64), np.asarray(D, dtype=np.float64)
    hits = all_hits(la, O, D)
    if not la.closed:
        return sorted(hits)
    return alternate(hits, lambda t: bool(inside(la, O + t * D)))


def all_hits(la: Lathe, O, D) -> list[tuple[float, int]]:
    """``(t, segment)`` of every crossing of the line with every segment's surface."""
    if la.smooth:
        return [(t, i) for i, seg in enumerate(la.segments) for t, _ in spl.segment_hits(seg, O, D)]
    return [(t, i) for i in range(len(la.points) - 1) for t in segment_hits(la, i, O, D)]


def hits(la: Lathe, O, D, solid: bool = False) -> list[tuple[float, int]]:
    """The registry's name for :func:`crossings`."""
    return crossings(la, O, D)


def normal(la: Lathe, face: int, P) -> np.ndarray:
    """Unit normal of segment ``face`` at P (3,) (outward for a closed lathe)."""
    if la.smooth:
        return spl.normal(la.segments[face], la.orientation, P)
    (r0, y0), (r1, y1) = la.points[face], la.points[face + 1]
    nr, ny = la.orientation * (y1 - y0), -la.orientation * (r1 - r0)
    rho = math.hypot(P[0], P[2])
    if rho == 0.0:
        return np.array([0.0, math.copysign(1.0, ny), 0.0])
    n = np.array([nr * P[0] / rho, ny, nr * P[2] / rho])
    return n / np.linalg.norm(n)


def intersect(la: Lathe, O, D, tmin: float = 0.0, tmax: float = np.inf):
    """First hit ``tmin < t < tmax``: ``(t, unit normal)``, or ``(inf, None)``."""
    O, D = np.asarray(O, dtype=np.float64), np.asarray(D, dtype=np.float64)
    hits = [(t, i) for t, i in all_hits(la, O, D) if tmin < t < tmax]
    if not hits:
        return np.inf, None
    t, i = min(hits)
    return t, normal(la, i, O + t * D)


# --------------------------------------------------------------------------- tessellation
def mesh(la: Lathe, steps: int):
    """Each segment swept in ``steps`` angular steps: ``(P, N, F)`` with the segment's normal on
    its own vertices (smooth around the axis, creased between segments).  A smooth profile's
    segments are cut in ``steps * PROFILE_STEPS / LEVEL_STEPS`` pieces each (at least 1) with
    the curve's normals (:func:`.lathe_spline.mesh`)."""
    if la.smooth:
        return spl.mesh(la.segments, spl.ends(la.points, la.spline)[1], la.orientation, steps,
                        max(1, steps * spl.PROFILE_STEPS // LEVEL_STEPS))
    ang = np.linspace(0.0, 2.0 * np.pi, steps + 1)
    c, s = np.cos(ang), np.sin(ang)
    c[-1], s[-1] = 1.0, 0.0          # the seam's two copies at exactly the same place
    Ps, Ns, Fs, base = [], [], [], 0
    for i in range(len(la.points) - 1):
        (r0, y0), (r1, y1) = la.points[i], la.points[i + 1]
        nr, ny = la.orientation * (y1 - y0), -la.orientation * (r1 - r0)
        ln = math.hypot(nr, ny)
        nr, ny = nr / ln, ny / ln
        ring = [np.stack([r * c, np.full_like(c, y), r * s], -1) for r, y in ((r0, y0), (r1, y1))]
        Ps.append(np.concatenate(ring))
        Ns.append(np.tile(np.stack([nr * c, np.full_like(c, ny), nr * s], -1), (2, 1)))
        a = np.arange(steps)
        q = np.stack([a, a + 1, steps + 2 + a, steps + 1 + a], -1) + base
        Fs.append(np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]))
        base += 2 * (steps + 1)
    P, N, F = np.concatenate(Ps), np.concatenate(Ns), np.concatenate(Fs)
    fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    keep = np.linalg.norm(fn, axis=1) > 0.0
    F, fn = F[keep], fn[keep]
    back = (fn * N[F].sum(1)).sum(1) < 0.0
    F[back] = F[back][:, ::-1]
    return P, N, F.astype(np.int64)


def level_mesh(la: Lathe, level: int):
    """:func:`mesh` at ``LEVEL_STEPS * level`` angular steps (a smooth profile's segments cut in
    ``PROFILE_STEPS * level`` pieces each)."""
    return mesh(la, LEVEL_STEPS * level)


def solid_mesh(la: Lathe, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed, welded object-space mesh ``(P, F)`` of a closed lathe at ``LEVEL_STEPS * level``
    steps (for the raster's CSG booleans)."""
    P, _, F = level_mesh(la, level)
    return weld(P, F)


def weld(P: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices at the same position; drop the triangles that collapse."""
    P, same = np.unique(P, axis=0, return_inverse=True)
    F = same.reshape(-1)[F]
    return P, F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]


def tessellate(obj: Lathe, level: int, M: np.ndarray) -> list:
    """The raster's triangles: one Part of :func:`level_mesh`."""
    P, N, F = level_mesh(obj, level)
    return [make_part(obj, M, P, N, F, None, None)]


def patch_surfaces(obj: Lathe, W: np.ndarray, h: float):
    """Radiosity: curved, cut from its tessellation (None)."""
    return None


def analytic_normals(obj: Lathe, P: np.ndarray):
    """Flat triangles for the raster's CSG booleans (None): its mesh's normals are the
    segments' own along the profile."""
    return None


# --------------------------------------------------------------------------- kernel rows
# (the numba entry points, in .lathe_kernels: see .crossing_events for their signatures)


class Par(Columns):
    """Its columns of the primitive table's ``par``: its profile's ``POINTS`` in ``aux`` (a
    polyline's points, or a spline's ``SEGMENTS`` of :func:`.lathe_spline.aux`), whether it is
    closed, its orientation, and the spline's code (0: a polyline)."""

    OFFSET = AUX_OFFSET
    POINTS = 1
    CLOSED = 2
    ORIENTATION = 3
    SPLINE = 4
    SEGMENTS = 5


def flatten(b, obj, index: int, W: np.ndarray, top: bool) -> int:
    """Its row of the ray tracer's primitive table (:func:`.aux_rows.flatten_aux`)."""
    return flatten_aux(b, obj, index, W, top, PTYPE, params(obj, 0), solid(obj))


def params(la: Lathe, aux_offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameter row head (:class:`Par`) and aux: (2 k,) the points of a polyline,
    :func:`.lathe_spline.aux` of a smooth profile."""
    head = dict(offset=aux_offset, points=len(la.points), closed=float(la.closed), orientation=la.orientation)
    if la.smooth:
        segs = la.segments
        return pack(Par, **head, spline=spl.CODE[la.spline], segments=len(segs)), spl.aux(segs)
    return (pack(Par, **head, spline=0.0, segments=len(la.points) - 1),
            np.ascontiguousarray(la.points, dtype=np.float64).reshape(-1))


# --------------------------------------------------------------------------- exporters
def povray(la: Lathe, w, in_csg: bool) -> str:
    """POV-Ray's ``lathe { X_spline k, <r, y>... }``: the profile's 2D points ``(r, y)``
    swept about the y axis, as ours; ``spline = X`` names POV-Ray's own curve (linear,
    quadratic, cubic, bezier: :mod:`.lathe_spline` follows POV-Ray's segment formulas), so the
    points go over unchanged."""
    pts = ", ".join(w.vec(q) for q in la.points)
    return (f"lathe {{ {la.spline}_spline {len(la.points)}, {pts} {w.texture(la.material)} "
            f"{w.matrix(la.world_from_object)} }}")


def mitsuba(la: Lathe, x) -> list[dict]:
    """No lathe in Mitsuba 3: its raster tessellation (``LEVEL_STEPS`` x level angular steps)
    at the export's level, an open surface when its profile is open; noted in ``left_out``."""
    level = la.tessellation or x.level
    x.leave(FEATURE, f"no lathe primitive in Mitsuba 3: exported as its raster tessellation "
            f"({LEVEL_STEPS} x level angular steps; level {level})")
    return x.tessellated(la, level, open_surface=not la.closed)
