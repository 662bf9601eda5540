"""A closed object of every kind, of size about 2 around the origin (scene-file dictionaries, no
material): the objects the camera-inside tests put around the camera and the scale-floor tests
scale."""
from __future__ import annotations

import numpy as np

STAR = [[2.5 * (1.0 if i % 2 == 0 else 0.8) * float(np.cos(t)), 2.5 * (1.0 if i % 2 == 0 else 0.8) * float(np.sin(t))]
        for i, t in enumerate(np.linspace(0.0, 2.0 * np.pi, 11)[:-1])]
CLOSED = {
    "sphere": {"type": "sphere", "center": [0, 0, 0], "radius": 2.0},
    "box": {"type": "box", "min": [-2, -2, -2], "max": [2, 2, 2]},
    "quadric": {"type": "quadric", "shape": "ellipsoid", "radii": [2.0, 1.8, 2.2]},
    "mesh": {"type": "mesh", "generate": {"kind": "icosphere", "subdivisions": 3, "radius": 2.0}},
    "blob": {"type": "blob", "threshold": 0.3, "components": [{"center": [0, 0, 0], "radius": 3.0}]},
    "isosurface": {"type": "isosurface", "function": "x^2 + y^2 + z^2", "threshold": 4.0, "max_gradient": 9.0,
                   "bounds": {"min": [-2.5, -2.5, -2.5], "max": [2.5, 2.5, 2.5]}},
    "lathe": {"type": "lathe", "points": [[0.0, -2.0], [2.0, -1.5], [2.2, 0.0], [2.0, 1.5], [0.0, 2.0]]},
    "prism": {"type": "prism", "polygon": STAR, "heights": [-2.0, 2.0], "transform": {"rotate": [90, 0, 0]}},
    "csg": {"type": "csg", "op": "union", "left": {"type": "sphere", "center": [0, 0, 0], "radius": 2.0},
            "right": {"type": "box", "min": [-1.8, -1.8, -1.0], "max": [1.8, 1.8, 1.0]}},
}
