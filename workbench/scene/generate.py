"""Procedural meshes for bundled scenes (nothing is downloaded at run time)."""
from __future__ import annotations

import numpy as np


def generate_mesh(kind: str, *, subdivisions: int = 4, seed: int = 0, amplitude: float = 0.15,
                  radius: float = 1.0):
    """A ``trimesh.Trimesh``.

    ``icosphere``: 20 * 4**subdivisions triangles.  ``blob``: an icosphere displaced along its
    normals by a smooth random field (sum of 8 seeded spherical bumps, ``amplitude`` relative
    to ``radius``): watertight, about 80k triangles at ``subdivisions = 6``.  ``torus``: major
    radius ``radius``, minor ``radius / 3``, 2 * (8 * 2**s)**2 triangles.
    """
    import trimesh
    if kind == "torus":
        n = 8 * 2 ** subdivisions
        # built at unit size, then scaled: trimesh merges vertices closer than an absolute
        # 1e-8, which collapses a small torus to no triangles
        unit = trimesh.creation.torus(1.0, 1.0 / 3.0, major_sections=n, minor_sections=n)
        return trimesh.Trimesh(np.asarray(unit.vertices) * radius, unit.faces, process=False)
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    v = np.asarray(mesh.vertices)
    if kind == "blob":
        rng = np.random.default_rng(seed)
        centres = rng.normal(size=(8, 3))
        centres /= np.linalg.norm(centres, axis=1, keepdims=True)
        weights = rng.uniform(-1.0, 1.0, size=8)
        field = (weights * np.exp(-4.0 * np.sum((v[:, None, :] - centres[None]) ** 2, -1))).sum(1)
        v = v * (1.0 + amplitude * field)[:, None]
    return trimesh.Trimesh(v * radius, mesh.faces, process=False)
