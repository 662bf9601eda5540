"""Object kind ``sphere``: centre and radius in object space (any ellipsoid through its transform)."""
from __future__ import annotations

import numpy as np

from ...core import transform as tf
from ...core.columns import Columns, pack
from .. import model as m, readers as rd
from ..parts import make_part

TYPE = "sphere"
MODEL = m.Sphere
FEATURE = "spheres"
PTYPE = SPHERE = 0
SOLID = True
COMPOSITE = False
CONVEX = True
CLOSED_TESSELLATION = True
KERNELS = None
KEYS = frozenset({"center", "radius"})
REQUIRED = frozenset({"radius"})


def parse(ctx: rd.Ctx, t: dict, w: str, common: dict) -> m.Sphere:
    return m.Sphere(**common, center=rd.vec(ctx, t, w, "center", (0.0, 0.0, 0.0)),
                    radius=rd.num(ctx, t, w, "radius", lo=0.0, lo_open=True))


def bound_points(s: m.Sphere) -> np.ndarray:
    """(8, 3) corners of the object-space box around the sphere."""
    c, r = np.asarray(s.center), s.radius
    return np.array([c + r * (2 * np.array(q) - 1) for q in np.ndindex(2, 2, 2)])


# --------------------------------------------------------------------------- raster
def uv_sphere(s: m.Sphere, level: int):
    """UV sphere, ``4 level`` rings x ``8 level`` segments, analytic normals: object-space
    ``(P (V, 3), N (V, 3), F (F, 3), None, None)`` (no source polygons)."""
    n_lat, n_lon = 4 * level, 8 * level
    th = np.linspace(0.0, np.pi, n_lat + 1)[1:-1]  # interior rings
    ph = np.arange(n_lon) * (2 * np.pi / n_lon)
    T, Ph = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([np.sin(T) * np.cos(Ph), np.cos(T), -np.sin(T) * np.sin(Ph)], -1).reshape(-1, 3)
    N = np.vstack([[0.0, 1.0, 0.0], ring, [0.0, -1.0, 0.0]])
    top, bottom = 0, len(N) - 1
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)
    F = []
    j = np.arange(n_lon)
    F.append(np.stack([np.full(n_lon, top), idx(0, j), idx(0, j + 1)], -1))
    for i in range(n_lat - 2):
        a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
        F += [np.stack([a, b, c], -1), np.stack([a, c, d], -1)]
    F.append(np.stack([idx(n_lat - 2, j), np.full(n_lon, bottom), idx(n_lat - 2, j + 1)], -1))
    F = np.vstack(F).astype(np.int64)
    P = np.asarray(s.center) + s.radius * N
    return P, N, F, None, None


def tessellate(s: m.Sphere, level: int, M: np.ndarray) -> list:
    return [make_part(s, M, *uv_sphere(s, level))]


def solid_mesh(s: m.Sphere, level: int) -> tuple[np.ndarray, np.ndarray]:
    P, _, F, _, _ = uv_sphere(s, level)
    return P, F


def analytic_normals(s: m.Sphere, P: np.ndarray):
    """Object-space normals at points ``P`` (3T, 3) of its triangles, and no cap."""
    return P - np.asarray(s.center), np.zeros(len(P), dtype=bool)


def patch_surfaces(s: m.Sphere, W: np.ndarray, h: float):
    """Curved: cut from its tessellation (None)."""
    return None


# --------------------------------------------------------------------------- ray tracing
class Par(Columns):
    """Its columns of the primitive table's ``par``."""

    CENTER = 0, 3
    RADIUS = 3


def flatten(b, s: m.Sphere, index: int, W: np.ndarray, top: bool) -> int:
    """Primitive row (``par``: :class:`Par`)."""
    return b.add(PTYPE, index, s, W, pack(Par, center=s.center, radius=s.radius), top=top, solid=SOLID)


def hits(s: m.Sphere, O, D, solid: bool) -> list[tuple[float, int]]:
    """Sphere ``|P - Sc|^2 = Sr^2`` (errata 1: B = 2 D.(O - Sc)).  The discriminant is taken as
    ``r^2 - |f - (f.d) d|^2`` (Haines et al. 2019) to avoid cancellation for small far spheres."""
    return roots(s.center, s.radius, O, D)


def roots(center, radius, O, D) -> list[tuple[float, int]]:
    """Both crossings ``(t, 0)`` of the line ``O + t D`` with a sphere, sorted (see :func:`hits`)."""
    s = np.linalg.norm(D)
    d = D / s
    f = O - np.asarray(center)
    b = f @ d
    disc = radius ** 2 - np.sum((f - b * d) ** 2)
    if not disc > 0.0:
        return []
    q = -b - np.sqrt(disc) if b >= 0 else -b + np.sqrt(disc)
    nf = np.linalg.norm(f)
    c = (nf - radius) * (nf + radius)
    ts = sorted([c / q if q != 0.0 else -np.sqrt(disc), q])
    return [(t / s, 0) for t in ts]


def normal(s: m.Sphere, face: int, P) -> np.ndarray:
    return P - np.asarray(s.center)


def inside(s: m.Sphere, q) -> bool:
    return bool(np.linalg.norm(q - np.asarray(s.center)) < s.radius)


# --------------------------------------------------------------------------- exporters
def povray(s: m.Sphere, w, in_csg: bool) -> str:
    """POV-Ray's ``sphere`` through the SDL writer ``w`` (:class:`workbench.renderers.povray_sdl.Writer`)."""
    return (f"sphere {{ {w.vec(s.center)}, {w.num(s.radius)} {w.texture(s.material)} "
            f"{w.matrix(s.world_from_object)} }}")


def mitsuba(s: m.Sphere, x) -> list[dict]:
    """Mitsuba's analytic ``sphere`` (``to_world`` = world_from_object . T(center) . S(radius))
    when the transform is a similarity, else its tessellation at the export's level, through
    the shape writer ``x`` (:class:`workbench.renderers.mitsuba_export.ShapeWriter`)."""
    k = x.similarity_scale(s.world_from_object)
    if k is None:
        return x.tessellated(s, x.level)
    M = np.asarray(s.world_from_object) @ tf.translate(s.center) @ tf.scale(s.radius)
    c, r = M[:3, 3], k * s.radius
    return [x.analytic({"type": "sphere", "to_world": M.tolist()}, s.material, c - r, c + r)]
