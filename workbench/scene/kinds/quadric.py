"""Object kind ``quadric``: ``P^T Q P = 0`` with ``Q`` symmetric (4, 4), given as ``Q`` or as a
named shape with radii (axis of symmetry y), cut to the object-space box ``bounds``.  On its own
it is the open cut surface; as a CSG leaf the solid ``P^T Q P < 0`` within its bounds (capped).

Raster: named shapes are parametric surfaces of revolution (``4 level`` rows x ``8 level``
segments) cut along the bounds' planes; a general Q is a marching-tetrahedra level set
(manifold3d) of about ``8 level`` cells along the bounds' diagonal, vertices pulled onto the
surface by Newton steps.  Normals: the gradient ``Q P``.
"""
from __future__ import annotations

import numpy as np

from ...core.columns import Columns, pack
from ...core.errors import WorkbenchError
from ...core.tol import tol
from .. import model as m, readers as rd
from ..parts import fix_normals, make_part
from .box import corners, face_normal, slab
from .sphere import uv_sphere

TYPE = "quadric"
MODEL = m.Quadric
FEATURE = "quadrics"
PTYPE = QUADRIC = 4
SOLID = True
COMPOSITE = False
CONVEX = False
CLOSED_TESSELLATION = False
KERNELS = None
KEYS = frozenset({"Q", "shape", "radii", "bounds"})
REQUIRED = frozenset()
SHAPES = ("ellipsoid", "cylinder", "cone", "hyperboloid", "hyperboloid2", "paraboloid")


def parse(ctx: rd.Ctx, t: dict, w: str, common: dict) -> m.Quadric:
    if ("Q" in t) == ("shape" in t):
        ctx.fail(f"{w}.Q", "give exactly one of Q (4x4 symmetric matrix) or shape")
    natural = None
    if "Q" in t:
        Q = rd.matrix(ctx, t, w, "Q")
        # entry by entry: Q_ij and Q_ji scale alike under a transform of the quadric
        asym = np.abs(Q - Q.T) - tol.symmetric * np.maximum(np.abs(Q), np.abs(Q.T))
        if (asym > 0).any():
            i, j = np.unravel_index(np.argmax(asym), Q.shape)
            ctx.fail(f"{w}.Q", f"matrix is not symmetric (Q[{i}][{j}] = {Q[i, j]} but Q[{j}][{i}] = {Q[j, i]})")
        if not Q[:3].any():   # exactly: a tiny term is a huge quadric, not none
            ctx.fail(f"{w}.Q", "degenerate quadric (no x, y or z terms)")
        shape = "general"
    else:
        shape = rd.string(ctx, t, w, "shape", choices=SHAPES)
        radii = rd.vec(ctx, t, w, "radii", (1.0, 1.0, 1.0))
        if min(radii) <= 0:
            ctx.fail(f"{w}.radii", f"expected three positive numbers, got {list(radii)}")
        Q, natural = quadric_matrix(shape, radii)
    if "bounds" in t:
        bt = t["bounds"]
        rd.check_keys(ctx, bt, f"{w}.bounds", {"min", "max"}, {"min", "max"})
        lo, hi = rd.vec(ctx, bt, f"{w}.bounds", "min"), rd.vec(ctx, bt, f"{w}.bounds", "max")
        if any(a >= b for a, b in zip(lo, hi)):
            ctx.fail(f"{w}.bounds.max", "must exceed bounds.min on every axis")
    elif natural is not None:
        lo, hi = natural
    else:
        ctx.fail(f"{w}.bounds", f"required for an unbounded quadric ({shape}): bounds = {{min = [..], max = [..]}}")
    return m.Quadric(**common, Q=m._ro(Q), bounds_min=lo, bounds_max=hi, shape=shape)


def bound_points(q: m.Quadric) -> np.ndarray:
    return corners(q.bounds_min, q.bounds_max)


def quadric_matrix(shape: str, radii) -> tuple[np.ndarray, tuple | None]:
    """Symmetric Q (4, 4) of a named quadric (axis of symmetry y) and its natural bounds
    (``None`` when unbounded).  Inside is ``P^T Q P < 0``."""
    a, b, c = (1.0 / r ** 2 for r in radii)
    if shape == "ellipsoid":
        return np.diag([a, b, c, -1.0]), (tuple(-r for r in radii), tuple(radii))
    if shape == "cylinder":
        return np.diag([a, 0.0, c, -1.0]), None
    if shape == "cone":
        return np.diag([a, -b, c, 0.0]), None
    if shape == "hyperboloid":  # one sheet
        return np.diag([a, -b, c, -1.0]), None
    if shape == "hyperboloid2":  # two sheets
        return np.diag([-a, b, -c, -1.0]), None
    if shape == "paraboloid":  # x^2/a^2 + z^2/c^2 - y/b = 0, opens towards +y
        Q = np.diag([a, 0.0, c, 0.0])
        Q[1, 3] = Q[3, 1] = -0.5 / radii[1]
        return Q, None
    raise KeyError(shape)


def _quadric_value(Q: np.ndarray, P: np.ndarray) -> np.ndarray:
    """``P^T Q P`` with P lifted to w = 1 (N,)."""
    H = np.concatenate([P, np.ones((len(P), 1))], 1)
    return np.einsum("ni,ij,nj->n", H, Q, H)


def _quadric_gradient(Q: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Outward (towards ``P^T Q P > 0``) gradient ``2 (Q P)_xyz`` (N, 3)."""
    H = np.concatenate([P, np.ones((len(P), 1))], 1)
    return 2.0 * (H @ Q.T)[:, :3]


def _unit_quadric(q: m.Quadric) -> tuple[np.ndarray, np.ndarray]:
    """The quadric in the unit frame of its bounds: ``(Qu, S)``.

    S (4, 4) maps the frame's coordinates onto the world's (the bounds' centre at the origin,
    half their diagonal as unit length), and ``Qu = S^T Q S / max |S^T Q S|``: the same surface,
    ``P^T Qu P`` of order 1 over the bounds, and the same Qu for the quadric scaled, moved or
    multiplied by any constant.  Work done in this frame (level set, gradient floors) does not
    depend on the scene's scale."""
    Q = np.asarray(q.Q, dtype=np.float64)
    lo, hi = np.asarray(q.bounds_min, dtype=np.float64), np.asarray(q.bounds_max, dtype=np.float64)
    S = np.eye(4)
    S[:3, :3] *= 0.5 * float(np.linalg.norm(hi - lo))
    S[:3, 3] = 0.5 * (lo + hi)
    Qu = S.T @ Q @ S
    return Qu / np.abs(Qu).max(), S


def _quadric_solid(q: m.Quadric, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed mesh of ``{P^T Q P <= 0} ∩ bounds`` by marching tetrahedra (manifold3d level
    set, about ``8 level`` cells along the bounds' diagonal): points (V, 3), faces (F, 3).

    The signed function handed to manifold3d is ``min(-q(P) / |grad q(P)|, distance inside
    the box)`` (first-order distance to the quadric), evaluated with plain floats because
    manifold3d calls it once per grid point.  The level set is built in
    :func:`_unit_quadric`'s frame (so that manifold3d's own tolerances, and the floor
    ``tol.normal_cancel`` of ``|grad q|``, which vanishes at an ellipsoid's centre, meet the
    same numbers at every scale); its points are then scaled and moved onto the bounds."""
    import manifold3d
    Qu, S = _unit_quadric(q)
    Q = [[float(x) for x in row] for row in Qu]
    k, c = float(S[0, 0]), S[:3, 3]
    lo = [float(x) for x in (np.asarray(q.bounds_min) - c) / k]
    hi = [float(x) for x in (np.asarray(q.bounds_max) - c) / k]
    h = 2.0 / (8.0 * level)          # the frame's diagonal is 2
    floor = tol.normal_cancel

    def sdf(x, y, z):
        p = (x, y, z, 1.0)
        qp = [Q[i][0] * x + Q[i][1] * y + Q[i][2] * z + Q[i][3] for i in range(4)]
        value = qp[0] * p[0] + qp[1] * p[1] + qp[2] * p[2] + qp[3]
        grad = 2.0 * (qp[0] * qp[0] + qp[1] * qp[1] + qp[2] * qp[2]) ** 0.5
        inside_box = min(x - lo[0], y - lo[1], z - lo[2], hi[0] - x, hi[1] - y, hi[2] - z)
        return min(-value / max(grad, floor), inside_box)

    pad = 2.5 * h    # the lower box faces half a cell off the grid: no sdf sign left to rounding there
    bounds = [lo[0] - pad, lo[1] - pad, lo[2] - pad, hi[0] + pad, hi[1] + pad, hi[2] + pad]
    mesh = manifold3d.Manifold.level_set(sdf, bounds, h).to_mesh()
    U = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    return c + k * U, np.asarray(mesh.tri_verts, dtype=np.int64)


def _named_radii(q: m.Quadric) -> tuple[float, float, float]:
    """(ra, rb, rc) of a named quadric, read back from its Q (see :func:`quadric_matrix`)."""
    Q = np.asarray(q.Q)
    ra, rc = 1.0 / np.sqrt(abs(Q[0, 0])), 1.0 / np.sqrt(abs(Q[2, 2]))
    rb = -0.5 / Q[1, 3] if q.shape == "paraboloid" else (1.0 / np.sqrt(abs(Q[1, 1])) if Q[1, 1] else 1.0)
    return ra, rb, rc


def _revolution(q: m.Quadric, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Parametric surface of a named quadric (elliptic surface of revolution about y),
    ``x = ra rho(t) cos(phi)``, ``z = -rc rho(t) sin(phi)``, ``y = y(t)``, over the bounds'
    y range, before cutting to the bounds: points, faces (outward winding)."""
    ra, rb, rc = _named_radii(q)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    n_t, n_phi = 4 * level, 8 * level
    t = np.linspace(0.0, 1.0, n_t + 1)
    sheets = []  # (rho(t), y(t)) rows, each sheet swept about y
    if q.shape == "ellipsoid":
        th = np.pi * t
        sheets.append((np.sin(th), rb * np.cos(th)))
    elif q.shape == "paraboloid":
        y0, y1 = max(lo[1], 0.0), max(hi[1], 0.0)
        y = y0 + (y1 - y0) * t
        sheets.append((np.sqrt(np.maximum(y / rb, 0.0)), y))
    elif q.shape == "hyperboloid2":
        ymax = max(abs(lo[1]), abs(hi[1]))
        rho = np.sqrt(max(ymax * ymax / (rb * rb) - 1.0, 0.0)) * t
        sheets += [(rho, rb * np.sqrt(1.0 + rho * rho)), (rho[::-1], -rb * np.sqrt(1.0 + rho[::-1] ** 2))]
    else:
        y = np.union1d(lo[1] + (hi[1] - lo[1]) * t, [0.0] if lo[1] < 0 < hi[1] else [])[::-1]
        rho = {"cylinder": np.ones_like(y), "cone": np.abs(y) / rb,
               "hyperboloid": np.sqrt(1.0 + (y / rb) ** 2)}[q.shape]
        sheets.append((rho, y))
    phi = np.arange(n_phi) * (2 * np.pi / n_phi)
    Ps, Fs, off = [], [], 0
    for rho, y in sheets:
        R, Ph = np.meshgrid(rho, phi, indexing="ij")
        P = np.stack([ra * R * np.cos(Ph), np.broadcast_to(y[:, None], R.shape), -rc * R * np.sin(Ph)], -1)
        i, j = np.meshgrid(np.arange(len(rho) - 1), np.arange(n_phi), indexing="ij")
        a, b = (i * n_phi + j).ravel(), (i * n_phi + (j + 1) % n_phi).ravel()
        c, d = a + n_phi, b + n_phi
        Ps.append(P.reshape(-1, 3))
        Fs.append(np.vstack([np.stack([a, c, d], -1), np.stack([a, d, b], -1)]) + off)
        off += len(Ps[-1])
    P, F = np.vstack(Ps), np.vstack(Fs).astype(np.int64)
    # orient outwards (gradient of P^T Q P) by the area-weighted majority
    if np.sum(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
              * _quadric_gradient(np.asarray(q.Q), P[F].mean(1))) < 0:
        F = F[:, ::-1]
    return P, F


def _cut_to_bounds(P: np.ndarray, F: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Keep the part of a triangle mesh inside the box [lo, hi] (triangles split along the box
    planes, no caps)."""
    from trimesh.intersections import slice_faces_plane
    for axis in range(3):
        for sign, plane in ((1.0, lo[axis]), (-1.0, hi[axis])):
            if len(F) == 0:
                return P, F
            n = np.zeros(3)
            n[axis] = sign
            origin = np.zeros(3)
            origin[axis] = plane
            P, F = slice_faces_plane(P, F, n, origin)[:2]
    return np.asarray(P, dtype=np.float64), np.asarray(F, dtype=np.int64)


def _general_quadric(q: m.Quadric, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Surface of a general quadric inside its bounds: the level-set solid with its box caps
    removed."""
    P, F = _quadric_solid(q, level)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    on_cap = np.zeros(len(F), dtype=bool)
    for axis in range(3):
        for plane in (lo[axis], hi[axis]):
            on_cap |= (np.abs(P[F][:, :, axis] - plane) <= tol.planar * (hi[axis] - lo[axis])).all(1)
    # vertices of the crease between surface and caps are interpolated across it: pull every
    # vertex onto the surface (Newton steps along the gradient), staying inside the bounds
    Qu, S = _unit_quadric(q)
    k, c = S[0, 0], S[:3, 3]
    U, ulo, uhi = (P - c) / k, (lo - c) / k, (hi - c) / k   # in the unit frame
    for _ in range(3):
        g = _quadric_gradient(Qu, U)
        g2 = np.maximum(np.sum(g * g, -1), tol.normal_cancel ** 2)
        U = np.clip(U - (_quadric_value(Qu, U) / g2)[:, None] * g, ulo, uhi)
    P = np.clip(c + k * U, lo, hi)
    return P, F[~on_cap]


def _surface(q: m.Quadric, level: int):
    """Open surface of a quadric cut to its bounds: named shapes parametric, general Q by
    marching tetrahedra; normals from the gradient ``Q P``."""
    if q.shape == "general":
        P, F = _general_quadric(q, level)
    else:
        P, F = _cut_to_bounds(*_revolution(q, level), np.asarray(q.bounds_min), np.asarray(q.bounds_max))
    if len(F) == 0:
        raise WorkbenchError(f"quadric {q.name or q.shape!r}: no surface inside its bounds "
                             f"{list(q.bounds_min)}..{list(q.bounds_max)}")
    used = np.unique(F)
    remap = np.full(len(P), -1)
    remap[used] = np.arange(len(used))
    P, F = P[used], remap[F]
    N = fix_normals(_quadric_gradient(np.asarray(q.Q), P), P, F)
    return P, N, F, None, None


def _closed_named_quadric(q: m.Quadric, level: int):
    """Closed welded mesh (points, faces) of an ellipsoid inside its bounds, or of a cylinder
    whose x/z bounds do not cut it (a tube and two cap fans); None for the other cases (the
    level set handles them)."""
    ra, rb, rc = _named_radii(q)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    if q.shape == "ellipsoid" and np.all(lo <= [-ra, -rb, -rc]) and np.all(hi >= [ra, rb, rc]):
        P, _, F, _, _ = uv_sphere(m.Sphere(q.material), level)
        return P * [ra, rb, rc], F
    if q.shape == "cylinder" and np.all(lo[[0, 2]] <= [-ra, -rc]) and np.all(hi[[0, 2]] >= [ra, rc]):
        n_phi, n_y = 8 * level, 2 * level
        phi = np.arange(n_phi) * (2 * np.pi / n_phi)
        ring = np.stack([ra * np.cos(phi), np.zeros(n_phi), -rc * np.sin(phi)], -1)
        ys = np.linspace(lo[1], hi[1], n_y + 1)
        P = np.vstack([ring + [0.0, y, 0.0] for y in ys] + [[[0.0, lo[1], 0.0]], [[0.0, hi[1], 0.0]]])
        j = np.arange(n_phi)
        F = []
        for i in range(n_y):
            a, b = i * n_phi + j, i * n_phi + (j + 1) % n_phi
            F += [np.stack([a, b, b + n_phi], -1), np.stack([a, b + n_phi, a + n_phi], -1)]
        bottom, top, last = len(P) - 2, len(P) - 1, n_y * n_phi
        F += [np.stack([np.full(n_phi, bottom), (j + 1) % n_phi, j], -1),
              np.stack([np.full(n_phi, top), last + j, last + (j + 1) % n_phi], -1)]
        F = np.vstack(F).astype(np.int64)
        # outward winding (the tube's by the quadric gradient)
        fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
        centroid_dir = P[F].mean(1) - P.mean(0)
        if np.sum(fn * centroid_dir) < 0:
            F = F[:, ::-1]
        return P, F
    return None


def tessellate(q: m.Quadric, level: int, M: np.ndarray) -> list:
    return [make_part(q, M, *_surface(q, level))]


def solid_mesh(q: m.Quadric, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed mesh of the solid within the bounds: ellipsoids and uncut cylinders directly,
    the rest by the level set."""
    closed = _closed_named_quadric(q, level)
    return closed if closed is not None else _quadric_solid(q, level)


def analytic_normals(q: m.Quadric, P: np.ndarray):
    """Object-space gradient normals at points ``P`` (3T, 3) of its triangles, and which
    points lie on triangles of the caps that close it at its bounds (flat there)."""
    n_obj = _quadric_gradient(np.asarray(q.Q), P)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    T = P.reshape(-1, 3, 3)
    on = np.zeros(len(T), dtype=bool)
    for axis in range(3):
        for plane in (lo[axis], hi[axis]):
            on |= (np.abs(T[:, :, axis] - plane) <= tol.planar * (hi[axis] - lo[axis])).all(1)
    return n_obj, np.repeat(on, 3)


def patch_surfaces(q: m.Quadric, W: np.ndarray, h: float):
    """Curved: cut from its tessellation (None)."""
    return None


# --------------------------------------------------------------------------- ray tracing
class Par(Columns):
    """Its columns of the primitive table's ``par``: the upper triangle of the symmetric
    ``Q`` row by row (``Q00 Q01 Q02 Q03 Q11 Q12 Q13 Q22 Q23 Q33``), then its bounds box."""

    Q = 0, 10
    BOUNDS_MIN = 10, 3
    BOUNDS_MAX = 13, 3


def flatten(b, q: m.Quadric, index: int, W: np.ndarray, top: bool) -> int:
    """Primitive row (``par``: :class:`Par`)."""
    Q = np.asarray(q.Q)
    return b.add(PTYPE, index, q, W, pack(Par, q=Q[np.triu_indices(4)], bounds_min=q.bounds_min,
                                          bounds_max=q.bounds_max), top=top, solid=SOLID)


def is_linear(A: float, B: float, C: float) -> bool:
    """``|A C| <= tol.zero B^2``: the second root ``-B/A`` lies beyond ``1/tol.zero`` times the
    first ``-C/B`` (or ``A = B = 0``).  Homogeneous in the coefficients and in the unit of
    ``t``: a quadric at scale 1e6 is not taken for a plane."""
    return abs(A * C) <= tol.zero * (B * B)


def solve_quadratic(A: float, B: float, C: float) -> list[float]:
    """Real roots of ``A t^2 + B t + C = 0``, sorted.

    Stable form (DESIGN errata 7): ``q = -(B + sign(B) sqrt(B^2 - 4AC)) / 2``, roots ``q / A``
    and ``C / q``.  A negligible ``A`` (:func:`is_linear`) is linear: ``t = -C / B``.  A
    double root (tangent ray) is no intersection, as the course says ("le cas tangent sera
    ignoré")."""
    if is_linear(A, B, C):
        return [] if B == 0.0 else [-C / B]
    disc = B * B - 4.0 * A * C
    if not disc > 0.0:
        return []
    q = -0.5 * (B + np.copysign(np.sqrt(disc), B if B != 0.0 else 1.0))
    r = sorted([q / A, C / q if q != 0.0 else -q / A])
    return r


def quadric_coefficients(Q, O, D) -> tuple[float, float, float]:
    """``A = D^T Q D``, ``B = 2 D^T Q P0``, ``C = P0^T Q P0`` with ``D`` lifted with w = 0 and
    ``P0`` with w = 1 (errata 2: every cross term of C carries its factor 2)."""
    Q = np.asarray(Q)
    P0, D4 = np.append(O, 1.0), np.append(D, 0.0)
    return float(D4 @ Q @ D4), float(2.0 * D4 @ Q @ P0), float(P0 @ Q @ P0)


def surface_hits(q: m.Quadric, O, D) -> list[tuple[float, int]]:
    """Roots of a quadric whose point lies in the object-space bounds (an open, cut surface)."""
    A, B, C = quadric_coefficients(q.Q, O, D)
    lo, hi = np.asarray(q.bounds_min), np.asarray(q.bounds_max)
    out = []
    for t in solve_quadratic(A, B, C):
        P = O + t * D
        slack = tol.cut * (np.abs(O).max() + abs(t) * np.abs(D).max())  # rounding of O + t D
        if np.all((lo - slack <= P) & (P <= hi + slack)):
            out.append((t, 0))
    return out


def solid_hits(q: m.Quadric, O, D) -> list[tuple[float, int]]:
    """Interval list of the solid ``P^T Q P < 0`` intersected with its bounds box (CSG leaf)."""
    box = slab(q.bounds_min, q.bounds_max, O, D)
    if not box:
        return []
    A, B, C = quadric_coefficients(q.Q, O, D)
    roots = solve_quadratic(A, B, C)
    inf = np.inf
    if is_linear(A, B, C):
        inside = ([(-inf, roots[0])] if B > 0 else [(roots[0], inf)]) if roots else ([(-inf, inf)] if C < 0 else [])
    elif A > 0:
        inside = [(roots[0], roots[1])] if roots else []
    else:
        inside = [(-inf, roots[0]), (roots[1], inf)] if roots else [(-inf, inf)]
    (s0, fs0), (s1, fs1) = box
    out = []
    for a, b in inside:
        (a, fa) = (s0, fs0) if s0 > a else (a, 0)
        (b, fb) = (s1, fs1) if s1 < b else (b, 0)
        if a < b:
            out += [(a, fa), (b, fb)]
    return out


def hits(q: m.Quadric, O, D, solid: bool) -> list[tuple[float, int]]:
    return solid_hits(q, O, D) if solid else surface_hits(q, O, D)


def normal(q: m.Quadric, face: int, P) -> np.ndarray:
    """The gradient ``Q P`` (halved), or a cut face's normal (``face >= 1``)."""
    if face >= 1:
        return face_normal(face)
    return (np.asarray(q.Q) @ np.append(P, 1.0))[:3]


def inside(q: m.Quadric, x) -> bool:
    P = np.r_[x, 1.0]
    return bool(P @ np.asarray(q.Q) @ P < 0.0 and bool(np.all(x >= q.bounds_min) and np.all(x <= q.bounds_max)))


# --------------------------------------------------------------------------- exporters
def povray(q: m.Quadric, w, in_csg: bool) -> str:
    """POV-Ray's ``quadric`` (``A x^2 + B y^2 + C z^2 + D xy + E xz + F yz + G x + H y + I z +
    J`` from the symmetric ``Q``: ``A = Q00, D = 2 Q01, G = 2 Q03, J = Q33``...; inside is
    ``< 0`` in both) ``clipped_by`` its bounds box (an open, cut surface, as the ray tracer)
    or, inside CSG, ``intersection``-ed with it (a solid with caps)."""
    Q = np.asarray(q.Q, dtype=np.float64)
    coef = (f"{w.vec([Q[0, 0], Q[1, 1], Q[2, 2]])}, {w.vec([2 * Q[0, 1], 2 * Q[0, 2], 2 * Q[1, 2]])}, "
            f"{w.vec([2 * Q[0, 3], 2 * Q[1, 3], 2 * Q[2, 3]])}, {w.num(Q[3, 3])}")
    box = f"box {{ {w.vec(q.bounds_min)}, {w.vec(q.bounds_max)} }}"
    tail = f"{w.texture(q.material)} {w.matrix(q.world_from_object)}"
    if in_csg:
        return f"intersection {{ quadric {{ {coef} }} {box} {tail} }}"
    return f"quadric {{ {coef} clipped_by {{ {box} }} {tail} }}"


def mitsuba(q: m.Quadric, x) -> list[dict]:
    """Its tessellation at the export's level, smooth normals."""
    return x.tessellated(q, x.level)
