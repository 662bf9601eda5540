"""Renders of the bundled scenes and of ``tests/data/all_kinds.toml`` (every object kind) by
flat, Phong, ray casting, Whitted ray tracing, radiosity and path tracing, small and with fixed
seeds: what :mod:`tests.test_kinds_identity` compares between two checkouts of the workbench.

Run as a script (``python tests/kinds_identity.py OUT.npz``) with ``PYTHONPATH`` on the checkout
to render; it uses only the public API (``load_scene``, ``render``), which both checkouts share.
A method that refuses a scene (no emitters for radiosity) is recorded by its message.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

SCENES = ("whitted", "csg", "quadrics", "mesh", "cornell_spheres",
          str(Path(__file__).resolve().parent / "data" / "all_kinds.toml"))
METHODS = {
    "flat": {}, "phong": {}, "raycast": {}, "raytrace": {},
    "radiosity": {"patch_size": 0.12, "hemicube_resolution": 32},
}
"""The path tracer was also bit-identical across the move (checked then); it has changed on
purpose since (area lights traced as BVH triangles, the grazing-angle shadow-ray fix)."""
NEW_ONLY = {"phong": {"standins": "off"}}
"""Options that only this checkout has, given to it alone: the old tree drew the bare local model."""
SIZE = (40, 30)


def render_all(new: bool = False) -> dict[str, np.ndarray]:
    """``{"scene/method": image (H, W, 3) float32}``, or a 0-d string array with the message of
    the error a method raised (``new``: this checkout, with :data:`NEW_ONLY`)."""
    import workbench
    from workbench.core.errors import WorkbenchError
    out = {}
    for name in SCENES:
        scene = workbench.load_scene(name)
        for method, options in METHODS.items():
            key = f"{Path(name).stem}/{method}"
            try:
                extra = NEW_ONLY.get(method, {}) if new else {}
                out[key] = workbench.render(scene, method, width=SIZE[0], height=SIZE[1],
                                            **options, **extra).image
            except WorkbenchError as e:
                out[key] = np.array(f"{type(e).__name__}: {e}")
    return out


if __name__ == "__main__":
    np.savez(sys.argv[1], **render_all())
