"""Compile the numba kernels into the run's cache, in a process of its own on the core the
test run leaves idle (started by ``conftest.py`` when the cache of the current code is cold).

A default test run on a fresh clone spends most of its time in numba's cold compiles (the ray
tracer's batched kernels, its per-pixel kernel for area lights, the path tracer, the kinds'
root finders), one after another, on one core while the other waits.  This process renders
tiny images with the options that reach each family of kernels, in the order the test files
first need them; the tests then load what it has written (numba writes each cache file to a
temporary name and renames it into place: "Cache Sharing" in numba's developer notes on
caching), or compile it themselves if they get there first.  Nothing here is asserted: a
failure is the tests' to find.

Usage: python tests/warm_kernels.py  (NUMBA_CACHE_DIR as the test run's)
"""
from __future__ import annotations

import sys

#: (bundled scene, method, options), in the order the test files first need them, except the
#: first: the ray tracer's batched kernels (point lights), which the run's first ray-traced test
#: (``test_compare_report``) compiles meanwhile; they come last, loaded from the cache by then.
RENDERS = [
    ("cornell", "raytrace", {}),                          # per-pixel kernel (area lights)
    ("cornell_spheres", "pathtrace", {"spp": 1}),
    ("kinds", "raytrace", {}),                            # every kind's kernels
    ("kinds", "pathtrace", {"spp": 1}),
    ("mesh", "raytrace", {"accel": "octree"}),
    ("mesh", "raytrace", {"traversal_stats": True}),
    ("cornell", "radiosity", {"form_factors": "raycast", "rays": 16}),
    ("cornell", "radiosity", {"solver": "progressive", "shot_rows": "raycast", "rays": 16}),
    ("whitted", "zbuffer", {}),
    ("whitted", "raytrace", {}),                          # batched Whitted kernels
]


def main() -> None:
    import workbench
    for scene, method, options in RENDERS:
        try:
            workbench.render(workbench.load_scene(scene), method, width=8, height=6, **options)
        except Exception as e:  # noqa: BLE001 - a warm-up only; the tests report failures
            print(f"warm_kernels: {scene} {method} {options}: {e}", file=sys.stderr)


if __name__ == "__main__":
    main()
