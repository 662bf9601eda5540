"""Fill a fresh numba cache in the background while the test run starts (``conftest.py``).

On a fresh clone (or after any edit of core, scene or renderers: the cache folder is keyed by
the code, :mod:`workbench.core.jit_cache`) every kernel is JIT-compiled once, ~5 minutes of
one core, nearly all inside the first test that reaches each kernel.  This process compiles,
on the machine's other core, the kernels the run reaches late (radiosity, the octree and the
traversal statistics, the wavefront ray tracer, the path tracer), in tiny renders through the
public API (the same call paths, hence the same compiled signatures, as the tests'); the run
then loads them from the cache.  A render that fails here is ignored: the tests that use the
kernel compile it themselves and report the failure.

    python tests/jit_warmup.py
"""
from __future__ import annotations

import sys

JOBS = (
    ("cornell_spheres", "pathtrace", {"spp": 2}),
    ("kinds", "pathtrace", {"spp": 2}),
    ("bricks", "raytrace", {}),
    ("cornell", "radiosity", {}),
    ("cornell", "radiosity", {"form_factors": "raycast", "solver": "progressive"}),
    ("cornell", "radiosity", {"solver": "progressive", "shot_rows": "raycast"}),
    ("cornell", "hybrid", {}),
    ("whitted", "raycast", {"accel": "octree", "traversal_stats": True}),
)
"""(scene, method, options) rendered at :data:`SIZE`, in the order the run first needs their
kernels (the ray tracer's fused path, the first one needed, is left to the run)."""
SIZE = (8, 6)


def main() -> int:
    import workbench
    for scene, method, options in JOBS:
        try:
            workbench.render(workbench.load_scene(scene), method, width=SIZE[0], height=SIZE[1],
                             **options)
        except Exception as e:  # the tests that use the kernel report it
            print(f"jit warm-up: {scene} {method} {options}: {e}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
