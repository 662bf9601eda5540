"""A toy object kind defined outside the package, the worked example of ``docs/kernels.md``:
``disk``, a flat disk of ``radius`` centred on the object-space origin in the ``y = 0`` plane,
its front facing ``+y``.  A thin sheet (no inside).  Registered with
:func:`workbench.scene.kinds.register`; its kernels are in ``toy_disk_kernels``.

Ray ``O + t D``: ``t = -O_y / D_y``, a hit when ``x^2 + z^2 <= r^2`` there."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbench.core.columns import Columns, pack
from workbench.scene import model as m, readers as rd
from workbench.scene.parts import make_part, polygons

TYPE = "disk"
FEATURE = "disks"
PTYPE = 40
SOLID = False
CONVEX = True
COMPOSITE = False
CLOSED_TESSELLATION = False
KERNELS = "toy_disk_kernels"
KEYS = frozenset({"radius"})
REQUIRED = KEYS


@dataclass(frozen=True, eq=False)
class Disk(m.SceneObject):
    radius: float = 1.0
    kind = "disk"


MODEL = Disk


def parse(ctx, t: dict, w: str, common: dict) -> Disk:
    return Disk(**common, radius=rd.num(ctx, t, w, "radius", lo=0.0, lo_open=True))


def bound_points(d: Disk) -> np.ndarray:
    r = d.radius
    return np.array([[-r, 0.0, -r], [r, 0.0, -r], [r, 0.0, r], [-r, 0.0, r]])


def outline(d: Disk, level: int) -> np.ndarray:
    """(8 level, 3) vertices of the regular polygon inscribed in the rim, counter-clockwise
    seen from ``+y``."""
    a = np.arange(8 * level) * (2.0 * np.pi / (8 * level))
    return d.radius * np.stack([np.cos(a), np.zeros_like(a), -np.sin(a)], -1)


def tessellate(d: Disk, level: int, M: np.ndarray) -> list:
    """The inscribed polygon of :func:`outline` as a fan."""
    return [make_part(d, M, *polygons([outline(d, level)], 1))]


class Par(Columns):
    """Its columns of the primitive table's ``par``."""

    RADIUS = 0


def flatten(b, d: Disk, index: int, W: np.ndarray, top: bool) -> int:
    """Primitive row (``par``: :class:`Par`)."""
    return b.add(PTYPE, index, d, W, pack(Par, radius=d.radius), top=top, solid=SOLID)


def hits(d: Disk, O, D, solid: bool = False) -> list[tuple[float, int]]:
    if D[1] == 0.0:
        return []
    t = -O[1] / D[1]
    q = O + t * D
    return [(t, 0)] if q[0] ** 2 + q[2] ** 2 <= d.radius ** 2 else []


def normal(d: Disk, face: int, P) -> np.ndarray:
    return np.array([0.0, 1.0, 0.0])


def inside(d: Disk, q) -> bool:
    return False


def povray(d: Disk, w, in_csg: bool) -> str:
    """POV-Ray's ``disc`` (centre, normal, radius) through the SDL writer ``w``."""
    return (f"disc {{ <0, 0, 0>, <0, 1, 0>, {w.num(d.radius)} {w.texture(d.material)} "
            f"{w.matrix(d.world_from_object)} }}")


def mitsuba(d: Disk, x) -> list[dict]:
    """Its tessellation at the export's level, an open surface."""
    return x.tessellated(d, x.level, flat=True, open_surface=True)
