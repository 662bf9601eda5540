"""The closed, welded object-space meshes the raster's CSG booleans take from each new solid
kind (blob, isosurface, closed lathe, prism): every edge used by exactly two triangles, wound
outwards (positive volume near the solid's)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kind_checks import index_edge_uses, mesh_volume
from workbench.scene.kinds import blob, isosurface, lathe, prism

COMMON = {"material": "m"}
CASES = [
    (blob.read({"threshold": 0.25, "components": [{"center": [0, 0, 0], "radius": 2.0}]}, "o", COMMON),
     4 / 3 * math.pi * 2 ** 1.5, 0.03),
    (isosurface.read({"function": "x^2+y^2+z^2", "threshold": 1.0, "max_gradient": 7.0,
                      "bounds": {"min": [-0.5, -2, -2], "max": [2, 2, 2]}}, "o", COMMON),
     4 / 3 * math.pi - math.pi * 0.25 * 2.5 / 3, 0.03),
    (lathe.read({"points": [[0, 0], [1, 0], [1, 1], [0, 1]]}, "o", COMMON), math.pi, 0.02),
    (prism.read({"polygon": [[0, 0], [2, 0], [2, 2], [1, 1], [0, 2]], "heights": [0, 3]}, "o", COMMON), 9.0, 1e-12),
]


@pytest.mark.parametrize("obj, volume, rel", CASES, ids=lambda c: getattr(c, "kind", ""))
def test_solid_mesh_is_closed_and_outward(obj, volume, rel):
    mod = {"blob": blob, "isosurface": isosurface, "lathe": lathe, "prism": prism}[obj.kind]
    P, F = mod.solid_mesh(obj, 3)
    assert (index_edge_uses(F) == 2).all()
    assert abs(mesh_volume(P, F) - volume) <= rel * volume


def test_isosurface_analytic_normals_mark_the_caps():
    s = CASES[1][0]
    N, cap = isosurface.analytic_normals(s, np.array([[-0.5, 0.1, 0.2], [0.6, 0.0, 0.8]]))
    assert cap.tolist() == [True, False]
    assert N[0].tolist() == [-1.0, 0.0, 0.0] and np.allclose(N[1], [1.2, 0.0, 1.6])
