"""Smooth lathe profiles: POV-Ray's ``quadratic_spline``, ``cubic_spline`` and ``bezier_spline``
lathes (the readable twin; the numba one is in :mod:`.lathe_kernels`).

The curve
---------
Each spline segment ``i`` is a polynomial curve ``c(s) = (r(s), y(s)) = A s^3 + B s^2 + C s + D``,
``0 <= s <= 1``, of the control points ``P`` (POV-Ray 3.7's ``Lathe::Compute_Lathe``, exactly):

* ``quadratic`` (n >= 3 points, n - 2 segments, from ``P[1]`` to ``P[n-1]``; ``P[0]`` only sets
  the first tangent): segment i from ``P[i+1]`` to ``P[i+2]``,
  ``A = 0``, ``B = (P[i] - 2 P[i+1] + P[i+2]) / 2``, ``C = (P[i+2] - P[i]) / 2``, ``D = P[i+1]``
  (continuous; its tangent jumps at the points);
* ``cubic`` (n >= 4, n - 3 segments, from ``P[1]`` to ``P[n-2]``; Catmull-Rom, C1): segment i
  from ``P[i+1]`` to ``P[i+2]``, ``A = (-P[i] + 3 P[i+1] - 3 P[i+2] + P[i+3]) / 2``,
  ``B = P[i] - 5/2 P[i+1] + 2 P[i+2] - 1/2 P[i+3]``, ``C = (P[i+2] - P[i]) / 2``, ``D = P[i+1]``;
* ``bezier`` (n = 4 m points, m segments): segment i the cubic Bezier curve of
  ``P[4i] .. P[4i+3]`` (Bernstein basis); each segment must start where the previous one ends.

A point ``(x, y, z)`` is on the surface when ``x^2 + z^2 = r(s)^2`` and ``y = y(s)`` for some
segment and ``s``.  The normal is the profile's normal turned about the axis:
``o (y'(s) x / rho, -r'(s), y'(s) z / rho)`` with ``o`` the profile's orientation (as for the
linear lathe, :mod:`.lathe`).

Ray intersection (POV-Ray's elimination, with a root finder of stated accuracy)
-------------------------------------------------------------------------------
With ``u(s) = y(s) - O_y``, the ray ``O + t D`` meets segment ``i`` where ``t = u(s) / D_y`` and

    P(s) = (D_x^2 + D_z^2) u(s)^2 + 2 D_y (O_x D_x + O_z D_z) u(s)
           + D_y^2 (O_x^2 + O_z^2 - r(s)^2) = 0,

a polynomial of degree 2 k in s (k = 2: quartic, k = 3: sextic).  Its real roots in
``[-sigma, 1 + sigma]`` (``sigma = tol.cut``: a ray through a joint is not lost between two
segments) are isolated by the roots of its derivatives (:func:`roots_in`: the roots of ``P^(j)``
cut the interval into pieces where ``P^(j-1)`` is monotone, from the linear ``P^(2k-1)`` up), each
bracketed root narrowed to adjacent floats (bisection here, the Illinois method in numba): the
accuracy is that of evaluating ``P``.  A double (tangent) root is no crossing.  When the ray is
nearly horizontal, ``|D_y| <= STEEP |D_xz|``, the two crossings of one circle of the surface
have nearly the same ``s`` and ``P`` loses them; then the seeds are the roots of
``y(s) = O_y + D_y t_c`` (``t_c`` the ray's closest approach to the axis) in
``[-SEED_MARGIN, 1 + SEED_MARGIN]`` and the two ``t`` where the ray's distance to the axis is
``r(s)``.  Every root ``(s, t)`` is then polished by Newton's method on the unsquared pair
``y(s) - O_y - t D_y = 0``, ``|O_xz + t D_xz|^2 - r(s)^2 = 0`` (its Jacobian vanishes only where
the ray is tangent to the surface), and kept when ``-sigma <= s <= 1 + sigma``.

Inside (a closed profile): even-odd count of the crossings of the horizontal half-line from
``(rho, y)`` outwards, the roots of ``y(s) = y`` in ``[0, 1]`` with ``r(s) > rho``.
"""
from __future__ import annotations

import math

import numpy as np

from ...core.tol import tol

SPLINES = ("linear", "quadratic", "cubic", "bezier")
"""The ``spline`` key's values, with POV-Ray's ``linear_spline`` .. ``bezier_spline``."""
CODE = {name: i for i, name in enumerate(SPLINES)}
"""The spline's code in the kernels' parameter row (0: the linear lathe's own path)."""
LEAST = {"linear": 2, "quadratic": 3, "cubic": 4, "bezier": 4}
"""Fewest control points of each spline."""
STEEP = 1e-3
"""Rays with ``|D_y| <= STEEP |D_xz|`` are seeded from ``y(s) = const`` (see the docstring)."""
SEED_MARGIN = 0.25
"""How far outside ``[0, 1]`` the nearly horizontal rays' seeds are looked for."""
NEWTON = 4
"""Newton steps of the polish (quadratic convergence from a root bracketed to adjacent floats)."""
SIGMA = tol.cut
"""Slack of ``s`` beyond ``[0, 1]``: a ray through a joint meets one of its two segments."""
PROFILE_STEPS = 2
"""Profile pieces per spline segment per tessellation level."""
SEG_FLOATS = 11
"""Aux floats per segment: r's and y's coefficients (ascending powers of s), rmax, ymin, ymax."""


# --------------------------------------------------------------------------- the curve
def segments(P: np.ndarray, spline: str) -> np.ndarray:
    """(S, 2, 4) coefficients, ascending powers of s: ``c[i, 0]`` r(s), ``c[i, 1]`` y(s) of
    segment i (see the module docstring)."""
    P = np.asarray(P, dtype=np.float64)
    n = len(P)
    out = []
    if spline == "linear":
        for i in range(n - 1):
            out.append([P[i], P[i + 1] - P[i], 0.0 * P[i], 0.0 * P[i]])
    elif spline == "quadratic":
        for i in range(n - 2):
            p0, p1, p2 = P[i], P[i + 1], P[i + 2]
            out.append([p1, 0.5 * (p2 - p0), 0.5 * p0 - p1 + 0.5 * p2, 0.0 * p0])
    elif spline == "cubic":
        for i in range(n - 3):
            p0, p1, p2, p3 = P[i], P[i + 1], P[i + 2], P[i + 3]
            out.append([p1, 0.5 * (p2 - p0), p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3,
                        -0.5 * p0 + 1.5 * p1 - 1.5 * p2 + 0.5 * p3])
    elif spline == "bezier":
        for i in range(0, n - 3, 4):
            p0, p1, p2, p3 = P[i], P[i + 1], P[i + 2], P[i + 3]
            out.append([p0, 3.0 * (p1 - p0), 3.0 * p0 - 6.0 * p1 + 3.0 * p2, p3 - 3.0 * p2 + 3.0 * p1 - p0])
    else:
        raise ValueError(spline)
    return np.transpose(np.array(out, dtype=np.float64), (0, 2, 1))


def ends(P: np.ndarray, spline: str) -> tuple[np.ndarray, np.ndarray]:
    """The curve's first and last points (control points it passes through)."""
    first = {"linear": 0, "quadratic": 1, "cubic": 1, "bezier": 0}[spline]
    last = {"linear": -1, "quadratic": -1, "cubic": -2, "bezier": -1}[spline]
    return P[first], P[last]


def peval(c, s: float) -> float:
    """``sum_i c[i] s^i`` (Horner)."""
    v = 0.0
    for a in reversed(c):
        v = v * s + a
    return v


def deriv(c) -> list[float]:
    return [i * c[i] for i in range(1, len(c))]


def extremes(c, lo: float = 0.0, hi: float = 1.0) -> tuple[float, float]:
    """Smallest and largest value of the polynomial ``c`` on ``[lo, hi]`` (at the ends and the
    roots of its derivative)."""
    vals = [peval(c, lo), peval(c, hi)] + [peval(c, s) for s in roots_in(deriv(c), lo, hi)]
    return min(vals), max(vals)


def sample(seg: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """``m + 1`` points (m+1, 2) of one segment at s = 0, 1/m, .., 1 and the tangents (m+1, 2)."""
    s = np.linspace(0.0, 1.0, m + 1)
    pw = s[:, None] ** np.arange(4)
    dpw = np.concatenate([np.zeros((m + 1, 1)), pw[:, :3] * np.arange(1, 4)], axis=1)
    return pw @ seg.T, dpw @ seg.T


# --------------------------------------------------------------------------- roots
def _bisect(c, a: float, b: float) -> float:
    """The end past the change of ``peval(c) > 0`` in ``[a, b]``, narrowed to adjacent floats."""
    sa = peval(c, a) > 0.0
    while True:
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            return b
        if (peval(c, m) > 0.0) == sa:
            a = m
        else:
            b = m


def roots_in(c, lo: float, hi: float) -> list[float]:
    """Points in ``(lo, hi]`` where ``peval(c) > 0`` changes (odd-multiplicity roots), sorted:
    the roots of each derivative isolate the monotone pieces of the one above it."""
    chain = [[float(a) for a in c]]
    while len(chain[-1]) > 2:
        chain.append(deriv(chain[-1]))
    crit: list[float] = []
    for p in reversed(chain):
        pts = [lo] + crit + [hi]
        crit = [_bisect(p, a, b) for a, b in zip(pts[:-1], pts[1:])
                if b > a and (peval(p, a) > 0.0) != (peval(p, b) > 0.0)]
    return crit


# --------------------------------------------------------------------------- ray
def ray_poly(seg: np.ndarray, O, D) -> list[float]:
    """Coefficients (ascending) of ``P(s)`` of the module docstring (degree 6)."""
    u = seg[1].copy()
    u[0] -= O[1]
    r = seg[0]
    a = D[0] * D[0] + D[2] * D[2]
    m = O[0] * D[0] + O[2] * D[2]
    q = O[0] * O[0] + O[2] * O[2]
    uu, rr = np.convolve(u, u), np.convolve(r, r)
    out = a * uu
    out[:4] += 2.0 * D[1] * m * u
    out += -D[1] * D[1] * rr
    out[0] += D[1] * D[1] * q
    return out.tolist()


def polish(seg: np.ndarray, O, D, s: float, t: float) -> tuple[float, float]:
    """Newton steps on ``y(s) - O_y - t D_y = 0``, ``|O_xz + t D_xz|^2 - r(s)^2 = 0``; a step
    that is not finite or moves s by more than ``SEED_MARGIN`` is not taken."""
    r, y = seg[0], seg[1]
    dr, dy = deriv(r), deriv(y)
    for _ in range(NEWTON):
        rs, ys, drs, dys = peval(r, s), peval(y, s), peval(dr, s), peval(dy, s)
        px, pz = O[0] + t * D[0], O[2] + t * D[2]
        f1 = ys - O[1] - t * D[1]
        f2 = px * px + pz * pz - rs * rs
        j11, j12, j21, j22 = dys, -D[1], -2.0 * rs * drs, 2.0 * (px * D[0] + pz * D[2])
        det = j11 * j22 - j12 * j21
        if det == 0.0:
            break
        ds = (-f1 * j22 + j12 * f2) / det
        dt = (-j11 * f2 + j21 * f1) / det
        if not (math.isfinite(ds) and math.isfinite(dt)) or abs(ds) > SEED_MARGIN:
            break
        s, t = s + ds, t + dt
    return s, t


def meets_hull(seg: np.ndarray, O, D) -> bool:
    """Whether the line meets the cylinder ``rho <= rmax``, ``ymin <= y <= ymax`` around the
    segment's Bezier control points (the curve lies in their convex hull), padded by ``SIGMA``
    of their size: a quick reject."""
    b = np.stack([seg[:, 0], seg[:, 0] + seg[:, 1] / 3.0, seg[:, 0] + 2.0 * seg[:, 1] / 3.0 + seg[:, 2] / 3.0,
                  seg.sum(1)], 1)
    pad = SIGMA * float(np.abs(b).max())
    rmax, ylo, yhi = b[0].max() + pad, b[1].min() - pad, b[1].max() + pad
    lo, hi = -math.inf, math.inf
    if D[1] == 0.0:
        if not ylo <= O[1] <= yhi:
            return False
    else:
        ta, tb = (ylo - O[1]) / D[1], (yhi - O[1]) / D[1]
        lo, hi = min(ta, tb), max(ta, tb)
    a = D[0] * D[0] + D[2] * D[2]
    m = O[0] * D[0] + O[2] * D[2]
    c = O[0] * O[0] + O[2] * O[2] - rmax * rmax
    if a == 0.0:
        return c <= 0.0
    disc = m * m - a * c
    if disc < 0.0:
        return False
    sq = math.sqrt(disc)
    return max(lo, (-m - sq) / a) <= min(hi, (-m + sq) / a)


def segment_hits(seg: np.ndarray, O, D) -> list[tuple[float, float]]:
    """``(t, s)`` of every crossing of the line with the segment's surface."""
    if not meets_hull(seg, O, D):
        return []
    a = D[0] * D[0] + D[2] * D[2]
    found = []
    if abs(D[1]) > STEEP * math.sqrt(a):
        for s in roots_in(ray_poly(seg, O, D), -SIGMA, 1.0 + SIGMA):
            found.append(polish(seg, O, D, s, (peval(seg[1], s) - O[1]) / D[1]))
    else:
        m = O[0] * D[0] + O[2] * D[2]
        q = O[0] * O[0] + O[2] * O[2]
        tc = -m / a
        yc = seg[1].copy()
        yc[0] -= O[1] + D[1] * tc
        for s0 in roots_in(yc, -SEED_MARGIN, 1.0 + SEED_MARGIN):
            R = peval(seg[0], s0)
            for t0 in _quadratic(a, 2.0 * m, q - R * R):
                found.append(polish(seg, O, D, s0, t0))
    return [(t, s) for s, t in found if -SIGMA <= s <= 1.0 + SIGMA]


def _quadratic(a: float, b: float, c: float) -> list[float]:
    """Real roots of ``a t^2 + b t + c`` (a > 0), stable form; none when not two."""
    disc = b * b - 4.0 * a * c
    if not disc > 0.0:
        return []
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))     # nonzero when disc > 0
    return [q / a, c / q]


def param_at(seg: np.ndarray, x: float, y: float, z: float) -> float:
    """The curve parameter of a surface point: among the roots of ``y(s) = y`` and
    ``r(s) = rho`` near ``[0, 1]`` (and its ends), the one whose curve point is nearest."""
    rho = math.hypot(x, z)
    cy, cr = seg[1].copy(), seg[0].copy()
    cy[0] -= y
    cr[0] -= rho
    cand = [0.0, 1.0] + roots_in(cy, -SEED_MARGIN, 1.0 + SEED_MARGIN) + roots_in(cr, -SEED_MARGIN, 1.0 + SEED_MARGIN)
    return min(cand, key=lambda s: math.hypot(peval(seg[0], s) - rho, peval(seg[1], s) - y))


def normal(seg: np.ndarray, orientation: float, P) -> np.ndarray:
    """Unit outward normal of the segment's surface at ``P`` (3,)."""
    x, y, z = (float(v) for v in P)
    s = param_at(seg, x, y, z)
    nr, ny = orientation * peval(deriv(seg[1]), s), -orientation * peval(deriv(seg[0]), s)
    rho = math.hypot(x, z)
    if rho == 0.0 or nr == ny == 0.0:
        return np.array([0.0, math.copysign(1.0, ny), 0.0])
    n = np.array([nr * x / rho, ny, nr * z / rho])
    return n / np.linalg.norm(n)


def inside(segs: np.ndarray, rho: float, y: float) -> bool:
    """Even-odd count of the crossings of the half-line ``(> rho, y)`` with the curve."""
    res = False
    for seg in segs:
        cy = seg[1].copy()
        cy[0] -= y
        for s in roots_in(cy, 0.0, 1.0):
            if peval(seg[0], s) > rho:
                res = not res
    return res


def signed_area2(segs: np.ndarray, per_seg: int = 64) -> float:
    """Twice the signed area of the curve closed by its last-to-first edge (shoelace of
    ``per_seg`` pieces per segment): positive counter-clockwise in the (r, y) plane."""
    pts = np.concatenate([sample(seg, per_seg)[0][:-1] for seg in segs] + [sample(segs[-1], 1)[0][-1:]])
    r, y = pts[:, 0], pts[:, 1]
    return float(np.sum(r * np.roll(y, -1) - np.roll(r, -1) * y))


# --------------------------------------------------------------------------- tessellation
def mesh(segs: np.ndarray, end: np.ndarray, orientation: float, steps: int, per_seg: int):
    """The surface swept in ``steps`` angular steps, each segment cut in ``per_seg`` pieces:
    ``(P (V, 3), N (V, 3), F (F, 3))`` with the curve's own normals on the vertices (smooth
    along the curve within a segment).

    Each segment's last ring is placed at the next segment's first point (``D``, exact) and
    the curve's at ``end`` (its last control point on the curve, :func:`ends`), not at
    ``A + B + C + D``, whose rounding would leave the rings a joint apart by an ulp (so the
    welded mesh of a closed profile would not be closed) and an end on the axis at r ~ 1e-17
    instead of 0."""
    ang = np.linspace(0.0, 2.0 * np.pi, steps + 1)
    c, s = np.cos(ang), np.sin(ang)
    c[-1], s[-1] = 1.0, 0.0
    Ps, Ns, Fs, base = [], [], [], 0
    a = np.arange(steps)
    for i, seg in enumerate(segs):
        pts, tan = sample(seg, per_seg)
        pts[-1] = segs[i + 1][:, 0] if i + 1 < len(segs) else end
        nr, ny = orientation * tan[:, 1], -orientation * tan[:, 0]
        ln = np.hypot(nr, ny)
        ln[ln == 0.0] = 1.0
        nr, ny = nr / ln, ny / ln
        for k in range(per_seg + 1):
            Ps.append(np.stack([pts[k, 0] * c, np.full_like(c, pts[k, 1]), pts[k, 0] * s], -1))
            Ns.append(np.stack([nr[k] * c, np.full_like(c, ny[k]), nr[k] * s], -1))
        for k in range(per_seg):
            b0 = base + k * (steps + 1)
            q = np.stack([a, a + 1, steps + 2 + a, steps + 1 + a], -1) + b0
            Fs.append(np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]))
        base += (per_seg + 1) * (steps + 1)
    P, N, F = np.concatenate(Ps), np.concatenate(Ns), np.concatenate(Fs)
    fn = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    keep = np.linalg.norm(fn, axis=1) > 0.0
    F, fn = F[keep], fn[keep]
    back = (fn * N[F].sum(1)).sum(1) < 0.0
    F[back] = F[back][:, ::-1]
    return P, N, F.astype(np.int64)


# --------------------------------------------------------------------------- kernel rows
def aux(segs: np.ndarray) -> np.ndarray:
    """(S * SEG_FLOATS,) per segment: r's 4 coefficients, y's 4, then rmax, ymin, ymax padded
    by ``tol.cut`` of the segment's size (the kernels' quick reject)."""
    rows = []
    for seg in segs:
        _, rmax = extremes(seg[0])
        ylo, yhi = extremes(seg[1])
        pad = tol.cut * max(abs(rmax), abs(ylo), abs(yhi))
        rows.append(np.concatenate([seg[0], seg[1], [rmax + pad, ylo - pad, yhi + pad]]))
    return np.concatenate(rows)
