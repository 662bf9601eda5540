"""``prism``: a closed simple polygon of the xz plane (possibly concave) extruded along y
between ``y0 < y1``, with caps (POV-Ray's ``prism`` with ``linear_sweep``).

Walls: the ray's projection ``(O_x, O_z) + t (D_x, D_z)`` meets edge ``P_i + s E_i`` at
``t = (P_i - O) x E_i / (D x E_i)``, ``s = (P_i - O) x D / (D x E_i)`` (2D cross products),
kept for ``0 <= s <= 1`` and ``y0 <= O_y + t D_y <= y1`` (with the rounding slack
``tol.cut (|O| + |t D|)``).  Caps: the plane ``y = y0`` or ``y1``, kept when the point is
inside the polygon (even-odd rule).  Normals: a wall's outward normal ``(E_z, 0, -E_x)``
(times the sign of the polygon's area in (x, z), so that a clockwise polygon also faces
out), the caps' ``-y`` and ``+y``.  Faces: 0 bottom cap, 1 top cap, ``2 + i`` wall of edge i.
The raster's caps are :func:`workbench.scene.polygon_pieces.ear_triangles` of the polygon.

Aux layout: ``(x, z)`` per vertex; parameter row ``[aux offset, vertices, y0, y1, orientation]``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core.tol import tol
from ...core.columns import Columns, pack
from .. import model as m
from ..parts import make_part
from ..polygon_pieces import convex_pieces, ear_triangles
from . import values as val
from .aux_rows import AUX_OFFSET, flatten_aux
from .crossing_events import alternate
from .lathe import weld
from .outline import first_crossing

TYPE = "prism"
FEATURE = "prisms"
PTYPE = 10
"""Its ``ptype`` in the ray tracer's primitive table."""
SOLID = True
CONVEX = False
CLOSED_TESSELLATION = True
KERNELS = "workbench.scene.kinds.prism_kernels"
COMPOSITE = False
KEYS = frozenset({"polygon", "heights"})
REQUIRED = KEYS
MAX_VERTICES = 256
TOL_CUT = tol.cut
"""``tol.cut`` as a compile-time constant of the kernels."""


@dataclass(frozen=True, eq=False)
class Prism(m.SceneObject):
    """``polygon`` (k, 2) of ``(x, z)`` vertices, extruded from ``y0`` to ``y1``."""

    polygon: np.ndarray = field(default_factory=lambda: np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]))
    y0: float = 0.0
    y1: float = 1.0
    kind = "prism"

    @property
    def orientation(self) -> float:
        """Sign of the polygon's area in (x, z) (shoelace): +1 counter-clockwise from x to z."""
        x, z = self.polygon[:, 0], self.polygon[:, 1]
        return 1.0 if float(np.sum(x * np.roll(z, -1) - np.roll(x, -1) * z)) >= 0.0 else -1.0


MODEL = Prism


# --------------------------------------------------------------------------- parse
def read(t: dict, where: str, common: dict) -> Prism:
    """Read ``{polygon = [[x, z], ...], heights = [y0, y1]}``: at least 3 vertices, a simple
    polygon (no two non-adjacent edges meet, no repeated vertex), ``y0 < y1``."""
    val.check_keys(t, where, val.COMMON | KEYS, REQUIRED)
    P = val.points(t, where, "polygon", 2, least=3, most=MAX_VERTICES)
    y0, y1 = val.vector(t, where, "heights", n=2)
    if not y0 < y1:
        val.fail(f"{where}.heights", f"expected [y0, y1] with y0 < y1, got {[y0, y1]}")
    k = len(P)
    for i in range(k):
        if (P[i] == P[(i + 1) % k]).all():
            val.fail(f"{where}.polygon[{(i + 1) % k}]", "repeats the previous vertex")
    crossing = first_crossing(P, loop=True)
    if crossing is not None:
        i, j = crossing
        val.fail(f"{where}.polygon", f"not simple: edge {i} ({P[i].tolist()} -> {P[(i + 1) % k].tolist()}) "
                 f"meets edge {j} ({P[j].tolist()} -> {P[(j + 1) % k].tolist()})")
    area2 = float(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1]))
    diam = float(np.ptp(P, axis=0).max())
    if abs(area2) <= tol.degenerate * diam * max(diam, float(np.abs(P).max())):
        val.fail(f"{where}.polygon", "has no area")
    return Prism(polygon=P, y0=y0, y1=y1, **common)


def parse(ctx, t: dict, where: str, common: dict) -> Prism:
    """:func:`read` with its error handed to the scene reader's ``ctx.fail``."""
    return val.parse_with(ctx, read, t, where, common)


def bound_points(p: Prism) -> np.ndarray:
    """(8, 3) corners of :func:`bounds`."""
    lo, hi = bounds(p)
    return np.array([np.where(np.array(s, bool), hi, lo) for s in np.ndindex(2, 2, 2)])


def bounds(p: Prism) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = p.polygon.min(0), p.polygon.max(0)
    return np.array([lo[0], p.y0, lo[1]]), np.array([hi[0], p.y1, hi[1]])


# --------------------------------------------------------------------------- readable twin
def _in_polygon(poly, x, z):
    """Even-odd rule (crossings of the ray toward +x)."""
    res = np.zeros(np.shape(x), dtype=bool)
    for (xa, za), (xb, zb) in zip(poly, np.roll(poly, -1, axis=0)):
        if za == zb:
            continue
        res ^= ((za > z) != (zb > z)) & (x < xa + (z - za) * (xb - xa) / (zb - za))
    return res


def inside(p: Prism, P) -> np.ndarray:
    """``y0 < y < y1`` and (x, z) inside the polygon."""
    P = np.asarray(P, dtype=np.float64)
    return (p.y0 < P[..., 1]) & (P[..., 1] < p.y1) & _in_polygon(p.polygon, P[..., 0], P[..., 2])


def piece_hits(p: Prism, O, D) -> list[tuple[float, int]]:
    """Every ``(t, face)`` where the line meets a wall or a cap."""
    ox, oy, oz = O
    dx, dy, dz = D
    out = []
    if dy != 0.0:
        for face, yc in ((0, p.y0), (1, p.y1)):
            t = (yc - oy) / dy
            if _in_polygon(p.polygon, ox + t * dx, oz + t * dz):
                out.append((t, face))
    k = len(p.polygon)
    for i in range(k):
        (px, pz), (qx, qz) = p.polygon[i], p.polygon[(i + 1) % k]
        ex, ez = qx - px, qz - pz
        den = dx * ez - dz * ex
        if den == 0.0:
            continue
        wx, wz = px - ox, pz - oz
        t = (wx * ez - wz * ex) / den
        s = (wx * dz - wz * dx) / den
        slack = TOL_CUT * (max(abs(ox), abs(oy), abs(oz)) + abs(t) * max(abs(dx), abs(dy), abs(dz)))
        if 0.0 <= s <= 1.0 and p.y0 - slack <= oy + t * dy <= p.y1 + slack:
            out.append((t, 2 + i))
    return out


def crossings(p: Prism, O, D) -> list[tuple[float, int]]:
    """Crossings ``(t, face)`` of the line with the solid's boundary, sorted, alternating
    entering / leaving (:func:`.crossing_events.alternate`)."""
    O, D = np.asarray(O, dtype=np.float64), np.asarray(D, dtype=np.float64)
    return alternate(piece_hits(p, O, D), lambda t: bool(inside(p, O + t * D)))


def hits(p: Prism, O, D, solid: bool = True) -> list[tuple[float, int]]:
    """The registry's name for :func:`crossings`."""
    return crossings(p, O, D)


def normal(p: Prism, face: int, P=None) -> np.ndarray:
    """Unit outward normal of ``face``."""
    if face < 2:
        return np.array([0.0, 1.0 if face == 1 else -1.0, 0.0])
    k = len(p.polygon)
    (px, pz), (qx, qz) = p.polygon[face - 2], p.polygon[(face - 1) % k]
    n = p.orientation * np.array([qz - pz, 0.0, -(qx - px)])
    return n / np.linalg.norm(n)


def intersect(p: Prism, O, D, tmin: float = 0.0, tmax: float = np.inf):
    """First hit ``tmin < t < tmax``: ``(t, unit normal)``, or ``(inf, None)``."""
    h = [(t, f) for t, f in piece_hits(p, np.asarray(O, dtype=np.float64), np.asarray(D, dtype=np.float64)) if tmin < t < tmax]
    if not h:
        return np.inf, None
    t, f = min(h)
    return t, normal(p, f)


# --------------------------------------------------------------------------- tessellation
def mesh(p: Prism):
    """Walls (one quad per edge, flat normals) and caps (ear clipping of the polygon):
    ``(P, N, F)`` counter-clockwise seen from outside."""
    k = len(p.polygon)
    x, z = p.polygon[:, 0], p.polygon[:, 1]
    Ps, Ns, Fs, base = [], [], [], 0
    for face, yc in ((0, p.y0), (1, p.y1)):
        V = np.stack([x, np.full(k, yc), z], -1)
        tri = ear_triangles(V)
        Ps.append(V)
        Ns.append(np.tile(normal(p, face), (k, 1)))
        Fs.append(tri + base)
        base += k
    for i in range(k):
        j = (i + 1) % k
        Ps.append(np.array([[x[i], p.y0, z[i]], [x[j], p.y0, z[j]], [x[j], p.y1, z[j]], [x[i], p.y1, z[i]]]))
        Ns.append(np.tile(normal(p, 2 + i), (4, 1)))
        Fs.append(np.array([[0, 1, 2], [0, 2, 3]]) + base)
        base += 4
    P, N, F = np.concatenate(Ps), np.concatenate(Ns), np.concatenate(Fs).astype(np.int64)
    fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    back = (fn * N[F[:, 0]]).sum(1) < 0.0
    F[back] = F[back][:, ::-1]
    return P, N, F


def solid_mesh(p: Prism, level: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Closed, welded object-space mesh ``(P, F)`` (exact at any level)."""
    P, _, F = mesh(p)
    return weld(P, F)


def patch_surfaces(p: Prism, W: np.ndarray, h: float):
    """Radiosity: the walls (rectangles) and the caps' convex pieces, as world polygons
    ``("polygon", (k, 3))`` counter-clockwise seen from outside, for the patch builder to cut
    at about ``h``."""
    W = np.asarray(W, dtype=np.float64)
    mirror = np.linalg.det(W[:3, :3]) < 0.0     # a mirroring transform flips the winding
    k = len(p.polygon)
    x, z = p.polygon[:, 0], p.polygon[:, 1]
    polys = []
    for face, y in ((0, p.y0), (1, p.y1)):
        cap = np.stack([x, np.full(k, y), z], -1)
        newell = np.cross(cap[1:-1] - cap[0], cap[2:] - cap[0]).sum(0)
        polys.extend(convex_pieces(cap if newell @ normal(p, face) > 0.0 else cap[::-1]))
    for i in range(k):
        j = (i + 1) % k
        quad = np.array([[x[i], p.y0, z[i]], [x[j], p.y0, z[j]], [x[j], p.y1, z[j]], [x[i], p.y1, z[i]]])
        polys.append(quad if np.cross(quad[1] - quad[0], quad[3] - quad[0]) @ normal(p, 2 + i) > 0.0 else quad[::-1])
    return [("polygon", (q[::-1] if mirror else q) @ W[:3, :3].T + W[:3, 3]) for q in polys]


def tessellate(obj: Prism, level: int, M: np.ndarray) -> list:
    """The raster's triangles: one Part of :func:`mesh` (exact: ``level`` plays no part)."""
    P, N, F = mesh(obj)
    return [make_part(obj, M, P, N, F, None, None)]


def analytic_normals(obj: Prism, P: np.ndarray):
    """Flat triangles for the raster's CSG booleans (None): its mesh's normals are the
    segments' own."""
    return None


# --------------------------------------------------------------------------- kernel rows
# (the numba entry points, in .prism_kernels: see .crossing_events for their signatures)


class Par(Columns):
    """Its columns of the primitive table's ``par``: its polygon's ``VERTICES`` (x, z) pairs in
    ``aux``, its heights and its orientation (the sign of the polygon's area)."""

    OFFSET = AUX_OFFSET
    VERTICES = 1
    Y0 = 2
    Y1 = 3
    ORIENTATION = 4


def flatten(b, obj, index: int, W: np.ndarray, top: bool) -> int:
    """Its row of the ray tracer's primitive table (:func:`.aux_rows.flatten_aux`)."""
    return flatten_aux(b, obj, index, W, top, PTYPE, params(obj, 0), SOLID)


def params(p: Prism, aux_offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameter row head (:class:`Par`) and aux (2 k,)."""
    return (pack(Par, offset=aux_offset, vertices=len(p.polygon), y0=p.y0, y1=p.y1, orientation=p.orientation),
            np.ascontiguousarray(p.polygon, dtype=np.float64).reshape(-1))


# --------------------------------------------------------------------------- exporters
def povray(p: Prism, w, in_csg: bool) -> str:
    """POV-Ray's ``prism { linear_sweep linear_spline y0, y1, k + 1, <x, z>... }``: POV-Ray's
    2D points are ``(x, z)`` swept along y between the two heights, as ours; the polygon is
    closed by repeating its first vertex (a linear spline prism needs it)."""
    P = [*p.polygon, p.polygon[0]]
    pts = ", ".join(w.vec(q) for q in P)
    return (f"prism {{ linear_sweep linear_spline {w.num(p.y0)}, {w.num(p.y1)}, {len(P)}, {pts} "
            f"{w.texture(p.material)} {w.matrix(p.world_from_object)} }}")


def mitsuba(p: Prism, x) -> list[dict]:
    """No prism in Mitsuba 3: its raster tessellation (exact: walls and ear-clipped caps),
    flat normals, noted in ``left_out``."""
    x.leave(FEATURE, "no prism primitive in Mitsuba 3: exported as its triangles (exact)")
    return x.tessellated(p, 1, flat=True)
