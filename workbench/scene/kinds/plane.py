"""Object kind ``plane``: a finite rectangle (``size``) centred at ``point`` with unit ``normal``;
a thin sheet (no inside)."""
from __future__ import annotations

import numpy as np

from ...core import transform as tf
from ...core.columns import Columns, pack
from .. import model as m, readers as rd
from ..parts import make_part, polygons

TYPE = "plane"
MODEL = m.Plane
FEATURE = "planes"
PTYPE = RECT = 1
SOLID = False
COMPOSITE = False
CONVEX = True
CLOSED_TESSELLATION = False
KERNELS = None
KEYS = frozenset({"point", "normal", "size", "u_axis"})
REQUIRED = frozenset({"normal", "size"})


def parse(ctx: rd.Ctx, t: dict, w: str, common: dict) -> m.Plane:
    size = rd.vec(ctx, t, w, "size", n=2)
    if min(size) <= 0:
        ctx.fail(f"{w}.size", f"expected two positive numbers [width, height], got {list(size)}")
    return m.Plane(**common, point=rd.vec(ctx, t, w, "point", (0.0, 0.0, 0.0)),
                   normal=tuple(tf.normalize(rd.vec(ctx, t, w, "normal", nonzero=True)).tolist()),
                   size=size, u_axis=rd.vec(ctx, t, w, "u_axis", (1.0, 0.0, 0.0), nonzero=True))


def bound_points(p: m.Plane) -> np.ndarray:
    return p.corners()


def tessellate(p: m.Plane, level: int, M: np.ndarray) -> list:
    """The rectangle cut in ``2 level x 2 level`` cells."""
    return [make_part(p, M, *polygons([p.corners()], 2 * level))]


def patch_surfaces(p: m.Plane, W: np.ndarray, h: float):
    return [("polygon", tf.transform_points(W, np.asarray(p.corners())))]


class Par(Columns):
    """Its columns of the primitive table's ``par``: the rectangle's centre, its unit axes
    ``u``, ``v`` and normal ``n``, and its half sizes along ``u`` and ``v``."""

    POINT = 0, 3
    U = 3, 3
    V = 6, 3
    N = 9, 3
    HALF_U = 12
    HALF_V = 13


def flatten(b, p: m.Plane, index: int, W: np.ndarray, top: bool) -> int:
    """Primitive row (``par``: :class:`Par`)."""
    u, v, n = p.frame()
    return b.add(PTYPE, index, p, W, pack(Par, point=p.point, u=u, v=v, n=n, half_u=p.size[0] / 2,
                                          half_v=p.size[1] / 2), top=top, solid=SOLID)


def hits(p: m.Plane, O, D, solid: bool) -> list[tuple[float, int]]:
    """Finite rectangle: plane ``(P - P0).n = 0``, then ``|(P - P0).u| <= w/2``, same for v."""
    u, v, n = p.frame()
    den = D @ n
    if den == 0.0:
        return []
    t = ((np.asarray(p.point) - O) @ n) / den
    q = O + t * D - np.asarray(p.point)
    return [(t, 0)] if abs(q @ u) <= p.size[0] / 2 and abs(q @ v) <= p.size[1] / 2 else []


def normal(p: m.Plane, face: int, P) -> np.ndarray:
    return p.frame()[2]


def inside(p: m.Plane, q) -> bool:
    return False


# --------------------------------------------------------------------------- exporters
def povray(p: m.Plane, w, in_csg: bool) -> str:
    """POV-Ray's ``polygon`` (its four corners, closed by repeating the first) through the SDL writer ``w``."""
    v = p.corners()
    pts = ", ".join(w.vec(q) for q in [*v, v[0]])
    return f"polygon {{ {len(v) + 1}, {pts} {w.texture(p.material)} {w.matrix(p.world_from_object)} }}"


def mitsuba(p: m.Plane, x) -> list[dict]:
    """Its triangles (level 1: exact), flat normals; an open surface (``thindielectric``)."""
    return x.tessellated(p, 1, flat=True, open_surface=True)
