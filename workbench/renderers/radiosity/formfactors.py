"""Form factors three ways, each reported with its row sums and its reciprocity error.

* ``hemicube`` (Cohen & Greenberg 1985): an item buffer on the five faces of a hemicube around
  each patch centre, drawn with OpenGL (:mod:`.hemicube`); F_ij = sum of the delta form
  factors of the pixels where patch j is the nearest surface.  A point-to-area estimate from
  the patch centre, with occlusion; aliasing and proximity errors are inherent (DESIGN errata 6).
* ``raycast`` (:mod:`.raycast`, numba): cosine-distributed rays from stratified points of patch
  i (Malley's method); F_ij = fraction of rays whose first hit is the front of patch j.  Area
  average, with occlusion, unbiased but noisy (relative error ~ 1 / sqrt(rays * F_ij)).
* ``analytic``: the exact unoccluded point-to-polygon form factor (Lambert's contour formula,
  Hottel & Sarofim 1967; Baum et al. 1989), the receiving polygon first clipped to the
  hemisphere above the point, averaged over patch i by Gauss-Legendre quadrature.

Row sums: sum_j F_ij = 1 in a closed scene (the hemicube's is 1 + O(1/n^2), errata 6).
Reciprocity: A_i F_ij = A_j F_ji.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...core.errors import WorkbenchError
from ...core.tol import tol
from .geometry import Geometry

METHODS = ("hemicube", "raycast", "analytic")
#: pairs exchanging less than this fraction of the largest exchange are left out of the
#: worst-pair reciprocity error (their relative error is noise)
RECIPROCITY_FLOOR = 1e-3


@dataclass
class FormFactors:
    """A form-factor matrix and its report.  Index it, or ``np.asarray`` it, like ``F``.

    F : (P, P) float64, F[i, j] = fraction of the energy leaving i that reaches j.
    row_sums : (P,) sum_j F_ij (1 in a closed scene).
    reciprocity_error : float, ``sum |A_i F_ij - A_j F_ji| / sum (A_i F_ij + A_j F_ji)``
        over all pairs (0 for exact form factors).
    reciprocity_max : float, the largest relative pair error
        ``|A_i F_ij - A_j F_ji| / (A_i F_ij + A_j F_ji)`` over pairs exchanging at least
        ``RECIPROCITY_FLOOR`` of the largest exchange (smaller ones are noise-dominated).
    method, seconds, info : how it was made (resolution, rays, hemicube weight sum, ...).
    """

    F: np.ndarray
    areas: np.ndarray
    method: str
    seconds: float = 0.0
    info: dict = field(default_factory=dict)
    row_sums: np.ndarray = field(init=False)
    reciprocity_error: float = field(init=False)
    reciprocity_max: float = field(init=False)

    def __post_init__(self):
        self.row_sums = self.F.sum(1)
        self.reciprocity_error, self.reciprocity_max = reciprocity(self.F, self.areas)

    def __array__(self, dtype=None, copy=None):
        return self.F if dtype is None else self.F.astype(dtype)

    def __getitem__(self, key):
        return self.F[key]

    @property
    def shape(self):
        return self.F.shape

    def report(self) -> dict:
        """Plain-number summary (for stats and benchmarks)."""
        rs = self.row_sums
        return {"method": self.method, "patches": len(rs), "seconds": self.seconds,
                "row_sum_min": float(rs.min()) if len(rs) else 0.0,
                "row_sum_max": float(rs.max()) if len(rs) else 0.0,
                "reciprocity_error": self.reciprocity_error,
                "reciprocity_max": self.reciprocity_max, **self.info}


def reciprocity(F: np.ndarray, areas: np.ndarray) -> tuple[float, float]:
    """Aggregate and worst-pair relative reciprocity errors of ``F`` (see :class:`FormFactors`)."""
    AF = areas[:, None] * F
    diff = np.abs(AF - AF.T)
    tot = AF + AF.T
    s = float(tot.sum())
    agg = float(diff.sum() / s) if s > 0 else 0.0
    big = tot > RECIPROCITY_FLOOR * tot.max() if tot.size and tot.max() > 0 else np.zeros_like(tot, bool)
    worst = float((diff[big] / tot[big]).max()) if big.any() else 0.0
    return agg, worst


# --------------------------------------------------------------------------- analytic
def point_polygon(points: np.ndarray, normals: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Exact unoccluded form factor from differential areas to a polygon (Lambert's formula).

    F_{dA -> A_j} = 1/(2 pi) sum_k gamma_k  n . (R_k x R_{k+1}) / |R_k x R_{k+1}|,
    with R_k the polygon's vertices relative to the point and gamma_k the angle between R_k
    and R_{k+1}, after clipping the polygon to the half-space in front of the point; only
    the polygon's front face receives (it must face the point).

    Parameters
    ----------
    points, normals : (M, 3) emitting points and their unit normals.
    polygon : (k, 3) planar convex polygon, counter-clockwise seen from its front.

    Returns
    -------
    (M,) form factors in [0, 1].
    """
    from .kernels import point_polygon_ff
    points = np.ascontiguousarray(points, dtype=np.float64)
    normals = np.ascontiguousarray(normals, dtype=np.float64)
    return point_polygon_ff(points, normals, np.ascontiguousarray(polygon, dtype=np.float64),
                            tol.zero)


def gauss_points(geom: Geometry, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss-Legendre points on every triangle (collapsed-square map, Duffy 1982).

    Returns points (T, order^2, 3), weights (T, order^2) summing to each triangle's area, and
    the owning patch (T,).
    """
    x, w = np.polynomial.legendre.leggauss(order)
    x, w = (x + 1) / 2, w / 2
    u, s = np.meshgrid(x, x, indexing="ij")
    wu, ws = np.meshgrid(w, w, indexing="ij")
    u, s, wq = u.ravel(), s.ravel(), (wu * ws).ravel()
    t = geom.tris
    a2 = np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)  # 2 * area
    pts = (t[:, None, 0] + u[None, :, None] * (t[:, None, 1] - t[:, None, 0])
           + (u * s)[None, :, None] * (t[:, None, 2] - t[:, None, 1]))
    weights = a2[:, None] * (u * wq)[None, :]
    return pts, weights, geom.tri_patch


def analytic(geom: Geometry, order: int = 8) -> np.ndarray:
    """F (P, P): the exact point-to-polygon factor averaged over patch i by an ``order``^2
    Gauss-Legendre rule per triangle.  Unoccluded.  Exact as ``order`` grows."""
    from .kernels import analytic_matrix
    pts, w, owner = gauss_points(geom, order)
    P = len(geom)
    polys = geom.polygons
    offsets = np.zeros(P + 1, dtype=np.int64)
    offsets[1:] = np.cumsum([len(p) for p in polys])
    flat = np.ascontiguousarray(np.concatenate(polys), dtype=np.float64)
    F = analytic_matrix(np.ascontiguousarray(pts.reshape(-1, 3)), np.ascontiguousarray(w.ravel()),
                        np.repeat(owner, pts.shape[1]).astype(np.int64),
                        np.ascontiguousarray(geom.normals), flat, offsets, P, tol.zero)
    area = geom.areas
    return np.divide(F, area[:, None], out=np.zeros_like(F), where=area[:, None] > 0)


def analytic_pairs(geom: Geometry, I, J, order: int = 8) -> np.ndarray:
    """F_ij (K,) of the listed pairs only, as :func:`analytic` computes them."""
    pts, w, owner = gauss_points(geom, order)
    out = np.zeros(len(I))
    for k, (i, j) in enumerate(zip(I, J)):
        if i == j or geom.areas[i] <= 0:
            continue
        sel = owner == i
        P = pts[sel].reshape(-1, 3)
        ff = point_polygon(P, np.broadcast_to(geom.normals[i], P.shape), geom.polygons[j])
        out[k] = (w[sel].ravel() * ff).sum() / geom.areas[i]
    return out


# --------------------------------------------------------------------------- dispatcher
def compute(geom: Geometry, method: str = "hemicube", resolution: int = 128, *,
            rotate: bool = False, rays: int = 4096, order: int = 8, seed: int = 0,
            normalize: bool = True, on_rows=None) -> FormFactors:
    """Form-factor matrix of ``geom`` by ``method`` (see the module docstring).

    Parameters
    ----------
    resolution : hemicube resolution (pixels across the top face, even).
    rotate : hemicube: rotate each hemicube by a random angle about the normal (aliasing).
    normalize : hemicube: scale the delta form factors to sum to exactly 1 (errata 6).
    rays : raycast: rays per patch.
    order : analytic: Gauss-Legendre order per triangle edge.
    on_rows : hemicube: ``on_rows(done, total)`` after each batch of rows (the other methods
        compute the matrix in one call and report nothing).
    """
    if method not in METHODS:
        raise WorkbenchError(f"form factor method must be one of {', '.join(METHODS)}, got {method!r}")
    t0 = time.perf_counter()
    info: dict = {}
    if method == "hemicube":
        from .hemicube import Hemicube
        hc = Hemicube(geom, resolution, rotate=rotate, seed=seed, normalize=normalize)
        try:
            F = hc.matrix(on_rows)
            info = hc.info()
        finally:  # GL objects are not garbage-collected: free them on every path
            hc.release()
    elif method == "raycast":
        from .raycast import raycast
        F = raycast(geom, rays, seed)
        info = {"rays_per_patch": int(rays)}
    else:
        F = analytic(geom, order)
        info = {"quadrature_order": int(order)}
    return FormFactors(F, geom.areas, method, time.perf_counter() - t0, info)
