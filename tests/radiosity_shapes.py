"""Test geometry for the radiosity tests: squares, discs and closed boxes as patch lists."""
from __future__ import annotations

import numpy as np


def grid(origin, eu, ev, n: int, m: int | None = None) -> list[np.ndarray]:
    """The parallelogram origin + [0,1] eu + [0,1] ev cut into n x m quads, counter-clockwise
    seen from the side eu x ev points to."""
    m = n if m is None else m
    o, eu, ev = (np.asarray(x, dtype=np.float64) for x in (origin, eu, ev))
    return [np.array([o + a / n * eu + b / m * ev, o + (a + 1) / n * eu + b / m * ev,
                      o + (a + 1) / n * eu + (b + 1) / m * ev, o + a / n * eu + (b + 1) / m * ev])
            for a in range(n) for b in range(m)]


def disc(centre, radius, normal_sign: int, sides: int, rings: int = 1) -> list[np.ndarray]:
    """A disc in a plane z = centre[2] as a polygon (rings = 1) or cut into polar patches
    (a triangle fan at the centre, trapezoids outside); facing +z (sign 1) or -z (sign -1)."""
    c = np.asarray(centre, dtype=np.float64)
    ang = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
    ring = lambda r: c + r * np.stack([np.cos(ang), np.sin(ang), np.zeros_like(ang)], 1)
    if rings == 1:
        p = ring(radius)
        return [p if normal_sign > 0 else p[::-1]]
    out = []
    rs = np.linspace(0.0, radius, rings + 1)
    for k in range(rings):
        inner, outer = ring(rs[k]), ring(rs[k + 1])
        for s in range(sides):
            t = (s + 1) % sides
            p = (np.array([c, outer[s], outer[t]]) if k == 0 else
                 np.array([inner[s], outer[s], outer[t], inner[t]]))
            out.append(p if normal_sign > 0 else p[::-1])
    return out


def inside_box(size=1.0, n: int = 2) -> list[np.ndarray]:
    """The six faces of a cube [0, size]^3, each cut n x n, facing inwards."""
    s = float(size)
    e = np.eye(3) * s
    faces = []
    for ax in range(3):
        u, v = e[(ax + 1) % 3], e[(ax + 2) % 3]
        faces += grid(np.zeros(3), v, u, n)          # at 0, normal +ax (v x u = -ax? fixed below)
        faces += grid(e[ax], u, v, n)
    out = []
    centre = np.full(3, s / 2)
    for p in faces:   # orient every face towards the centre
        nrm = np.cross(p[1] - p[0], p[2] - p[0])
        out.append(p if nrm @ (centre - p.mean(0)) > 0 else p[::-1])
    return out


def parallel_squares_F(c: float) -> float:
    """Howell C-11 for unit squares a = b = 1 at distance c (closed form)."""
    X = Y = 1.0 / c
    x1, y1 = np.sqrt(1 + X * X), np.sqrt(1 + Y * Y)
    return float(2 / (np.pi * X * Y) * (np.log(np.sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y)))
                                         + X * y1 * np.arctan(X / y1) + Y * x1 * np.arctan(Y / x1)
                                         - X * np.arctan(X) - Y * np.arctan(Y)))


def coaxial_discs_F(r1: float, r2: float, h: float) -> float:
    """Howell C-41: from disc r1 to a parallel coaxial disc r2 at distance h."""
    R1, R2 = r1 / h, r2 / h
    S = 1 + (1 + R2 * R2) / (R1 * R1)
    return float(0.5 * (S - np.sqrt(S * S - 4 * (r2 / r1) ** 2)))
