"""Object kind ``polygon``: a planar polygon, counter-clockwise seen from its front; a concave
one is cut into convex pieces (:mod:`..polygon_pieces`).  A thin sheet (no inside).  Area
lights become polygons of this kind (:meth:`workbench.scene.model.Scene.area_light_polygons`)."""
from __future__ import annotations

import numpy as np

from ...core import transform as tf
from ...core.columns import Columns, pack
from ...core.errors import NotApplicable
from .. import model as m, readers as rd
from ..parts import make_part, polygons
from ..polygon_pieces import convex_pieces

TYPE = "polygon"
MODEL = m.Polygon
FEATURE = "polygons"
PTYPE = POLYGON = 3
SOLID = False
COMPOSITE = False
CONVEX = True
CLOSED_TESSELLATION = False
KERNELS = None
KEYS = frozenset({"vertices"})
REQUIRED = frozenset({"vertices"})


def parse(ctx: rd.Ctx, t: dict, w: str, common: dict) -> m.Polygon:
    return m.Polygon(**common, vertices=m._ro(rd.polygon_vertices(ctx, t, w)))


def bound_points(p: m.Polygon) -> np.ndarray:
    return np.asarray(p.vertices, dtype=np.float64)


def tessellate(p: m.Polygon, level: int, M: np.ndarray) -> list:
    """Fan of triangles of each convex piece, each cut in ``level^2``; one flat-shading point
    (the mean of the vertices) for the whole polygon."""
    P, N, F, fn, fc = polygons(convex_pieces(p.vertices), level)
    fc[:] = np.asarray(p.vertices).mean(0)
    return [make_part(p, M, P, N, F, fn, fc)]


def patch_surfaces(p: m.Polygon, W: np.ndarray, h: float):
    return [("polygon", tf.transform_points(W, np.asarray(q))) for q in convex_pieces(p.vertices)]


# --------------------------------------------------------------------------- ray tracing
class Par(Columns):
    """Its columns of the primitive table's ``par`` (one row per convex piece): the unit
    normal ``n``, the plane's offset ``n . centroid``, and the piece's vertices in ``poly_v``."""

    NORMAL = 0, 3
    OFFSET = 3
    FIRST = 4
    COUNT = 5


def flatten(b, p: m.Polygon, index: int, W: np.ndarray, top: bool, *, shadow: bool = True) -> int:
    """One primitive row per convex piece (``par``: :class:`Par`); returns the last row."""
    pieces = convex_pieces(p.vertices)
    if len(pieces) > 1 and not top:
        raise NotApplicable(f"object {p.name or index}: a concave polygon inside a CSG "
                            "tree is not supported by the ray tracer")
    return [_convex_row(b, q, index, p, W, top, shadow) for q in pieces][-1]


def _convex_row(b, verts, index, p, W, top, shadow) -> int:
    v = np.asarray(verts, dtype=np.float64)
    n = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
    n = n / np.linalg.norm(n)
    row = b.add(PTYPE, index, p, W, pack(Par, normal=n, offset=float(n @ v.mean(0)), first=b.n_poly, count=len(v)),
                top=top, solid=SOLID, shadow=shadow)
    b.poly_v.append(v)
    b.n_poly += len(v)
    return row


def hits(p: m.Polygon, O, D, solid: bool) -> list[tuple[float, int]]:
    """Planar polygon: the closest hit of its convex pieces (the polygon itself, or the
    triangles of a concave one)."""
    found = [h for piece in convex_pieces(p.vertices) for h in convex_hits(piece, O, D)]
    return [min(found)] if found else []


def convex_hits(v, O, D) -> list[tuple[float, int]]:
    """Convex planar polygon (k, 3): plane hit, then the point is left of every edge (seen
    from the front, vertices counter-clockwise)."""
    n = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
    n = n / np.linalg.norm(n)
    den = D @ n
    if den == 0.0:
        return []
    t = (n @ v.mean(0) - n @ O) / den
    q = O + t * D
    for a, c in zip(v, np.roll(v, -1, axis=0)):
        if np.cross(c - a, q - a) @ n < 0.0:
            return []
    return [(t, 0)]


def normal(p: m.Polygon, face: int, P) -> np.ndarray:
    return np.asarray(p.normal)


def inside(p: m.Polygon, q) -> bool:
    return False


# --------------------------------------------------------------------------- exporters
def povray(p: m.Polygon, w, in_csg: bool) -> str:
    """POV-Ray's ``polygon`` (its vertices, closed by repeating the first) through the SDL writer ``w``."""
    v = np.asarray(p.vertices)
    pts = ", ".join(w.vec(q) for q in [*v, v[0]])
    return f"polygon {{ {len(v) + 1}, {pts} {w.texture(p.material)} {w.matrix(p.world_from_object)} }}"


def mitsuba(p: m.Polygon, x) -> list[dict]:
    """Its triangles (level 1: exact), flat normals; an open surface (``thindielectric``)."""
    return x.tessellated(p, 1, flat=True, open_surface=True)
