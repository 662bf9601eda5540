"""Object kind ``box``: axis-aligned in object space (rotate it with ``transform``)."""
from __future__ import annotations

import numpy as np

from ...core import transform as tf
from ...core.columns import Columns, pack
from .. import model as m, readers as rd
from ..parts import make_part, polygons

TYPE = "box"
MODEL = m.Box
FEATURE = "boxes"
PTYPE = BOX = 2
SOLID = True
COMPOSITE = False
CONVEX = True
CLOSED_TESSELLATION = True
KERNELS = None
KEYS = frozenset({"min", "max"})
REQUIRED = frozenset({"min", "max"})


def parse(ctx: rd.Ctx, t: dict, w: str, common: dict) -> m.Box:
    lo, hi = rd.vec(ctx, t, w, "min"), rd.vec(ctx, t, w, "max")
    if any(a >= b for a, b in zip(lo, hi)):
        ctx.fail(f"{w}.max", f"must exceed min on every axis (min {list(lo)}, max {list(hi)})")
    return m.Box(**common, min=lo, max=hi)


def corners(lo, hi) -> np.ndarray:
    """(8, 3) corners of the box ``[lo, hi]``."""
    lo, hi = np.asarray(lo), np.asarray(hi)
    return np.array([np.where(np.array(s, bool), hi, lo) for s in np.ndindex(2, 2, 2)])


def bound_points(b: m.Box) -> np.ndarray:
    return corners(b.min, b.max)


# --------------------------------------------------------------------------- raster
def faces(b: m.Box) -> list[np.ndarray]:
    """Six faces (4, 3), counter-clockwise seen from outside (the raster's order)."""
    lo, hi = np.asarray(b.min), np.asarray(b.max)
    c = np.array([[lo[0], lo[1], lo[2]], [hi[0], lo[1], lo[2]], [hi[0], hi[1], lo[2]], [lo[0], hi[1], lo[2]],
                  [lo[0], lo[1], hi[2]], [hi[0], lo[1], hi[2]], [hi[0], hi[1], hi[2]], [lo[0], hi[1], hi[2]]])
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
    return [c[list(q)] for q in quads]


def tessellate(b: m.Box, level: int, M: np.ndarray) -> list:
    """Each face cut in ``level x level`` cells, face normals."""
    return [make_part(b, M, *polygons(faces(b), level))]


def solid_mesh(b: m.Box, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Closed welded mesh: the 8 corners, two triangles per face."""
    quads = faces(b)
    P = np.unique(np.vstack(quads), axis=0)
    F = []
    for q in quads:
        ids = [int(np.flatnonzero((P == c).all(1))[0]) for c in q]
        F += [(ids[0], ids[1], ids[2]), (ids[0], ids[2], ids[3])]
    return P, np.array(F, dtype=np.int64)


def analytic_normals(b: m.Box, P: np.ndarray):
    """Flat faces: the triangles' own normals (None)."""
    return None


# --------------------------------------------------------------------------- radiosity
def patch_surfaces(b: m.Box, W: np.ndarray, h: float):
    """The six faces as world polygons, in the order -x, +x, -y, +y, -z, +z."""
    x0, y0, z0 = b.min
    x1, y1, z1 = b.max
    return [("polygon", tf.transform_points(W, np.array(f, dtype=np.float64))) for f in (
        [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],   # -x
        [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],   # +x
        [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],   # -y
        [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],   # +y
        [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],   # -z
        [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],   # +z
    )]


# --------------------------------------------------------------------------- ray tracing
class Par(Columns):
    """Its columns of the primitive table's ``par``."""

    MIN = 0, 3
    MAX = 3, 3


def flatten(bld, b: m.Box, index: int, W: np.ndarray, top: bool) -> int:
    """Primitive row (``par``: :class:`Par`)."""
    return bld.add(PTYPE, index, b, W, pack(Par, min=b.min, max=b.max), top=top, solid=SOLID)


def slab(lo, hi, O, D) -> list[tuple[float, int]]:
    """Axis-aligned box by slabs (Kay & Kajiya 1986); face = 1 + 2 axis + (1 for the max side)."""
    t_near, t_far, f_near, f_far = -np.inf, np.inf, 0, 0
    for a in range(3):
        if D[a] == 0.0:
            if not lo[a] <= O[a] <= hi[a]:
                return []
            continue
        (t0, f0), (t1, f1) = sorted([((lo[a] - O[a]) / D[a], 1 + 2 * a), ((hi[a] - O[a]) / D[a], 2 + 2 * a)])
        if t0 > t_near:
            t_near, f_near = t0, f0
        if t1 < t_far:
            t_far, f_far = t1, f1
    return [(t_near, f_near), (t_far, f_far)] if t_near < t_far else []


def hits(b: m.Box, O, D, solid: bool) -> list[tuple[float, int]]:
    return slab(b.min, b.max, O, D)


def face_normal(face: int) -> np.ndarray:
    """Outward normal of slab face ``face >= 1`` (see :func:`slab`)."""
    nrm = np.zeros(3)
    nrm[(face - 1) // 2] = 1.0 if (face - 1) % 2 else -1.0
    return nrm


def normal(b: m.Box, face: int, P) -> np.ndarray:
    return face_normal(face)


def inside(b: m.Box, q) -> bool:
    return bool(np.all(q > b.min) and np.all(q < b.max))


# --------------------------------------------------------------------------- exporters
def povray(b: m.Box, w, in_csg: bool) -> str:
    """POV-Ray's ``box`` through the SDL writer ``w``."""
    return f"box {{ {w.vec(b.min)}, {w.vec(b.max)} {w.texture(b.material)} {w.matrix(b.world_from_object)} }}"


def mitsuba(b: m.Box, x) -> list[dict]:
    """Its twelve triangles (level 1: exact), flat normals."""
    return x.tessellated(b, 1, flat=True)
