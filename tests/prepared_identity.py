"""Images of every bundled scene and ``tests/data/all_kinds.toml`` by ten methods at 64 x 48, to
compare two checkouts of the workbench to the last bit (how the prepared-scene step was checked,
``workbench.scene.prepared``; see the README's "The prepared scene").

Render in each checkout (``PYTHONPATH`` on it, its own ``NUMBA_CACHE_DIR``), then compare::

    python tests/prepared_identity.py render BEFORE.npz      # in the older tree
    python tests/prepared_identity.py render AFTER.npz       # in this one
    python tests/prepared_identity.py compare BEFORE.npz AFTER.npz

A method that refuses a scene (radiosity without emitters) is recorded by its message.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
METHODS = {"flat": {}, "gouraud": {}, "phong": {}, "zbuffer": {}, "pyrender": {}, "raycast": {},
           "raytrace": {}, "radiosity": {"patch_size": 0.12, "hemicube_resolution": 32},
           "hybrid": {"patch_size": 0.12, "hemicube_resolution": 32}, "pathtrace": {"spp": 2}}
SIZE = (64, 48)


def render_all(out: str) -> None:
    """Write ``{"scene/method": image (H, W, 3) float32 or a 0-d message}`` to ``out``."""
    import workbench
    from workbench.core.errors import WorkbenchError
    images = {}
    paths = sorted((ROOT / "scenes").glob("*.toml")) + [ROOT / "tests" / "data" / "all_kinds.toml"]
    for path in paths:
        scene = workbench.load_scene(str(path))
        for method, options in METHODS.items():
            try:
                images[f"{path.stem}/{method}"] = workbench.render(scene, method, width=SIZE[0], height=SIZE[1],
                                                                   **options).image
            except WorkbenchError as e:
                images[f"{path.stem}/{method}"] = np.array(f"{type(e).__name__}: {e}")
    np.savez(out, **images)


def compare(before: str, after: str) -> int:
    """Print every image or message that differs; returns how many do."""
    a, b = np.load(before), np.load(after)
    if sorted(a.files) != sorted(b.files):
        print("different sets of renders:", sorted(set(a.files) ^ set(b.files)))
        return 1
    same = differ = 0
    for k in sorted(a.files):
        x, y = a[k], b[k]
        if x.ndim == 0 or y.ndim == 0:
            if x.ndim != y.ndim or str(x) != str(y):
                differ += 1
                print(f"{k}: {x} -> {y}")
        elif x.shape == y.shape and np.array_equal(x, y):
            same += 1
        else:
            differ += 1
            n = int((x != y).any(-1).sum()) if x.shape == y.shape else x.size
            print(f"{k}: {n} pixels differ, largest difference {float(np.abs(x - y).max()) if x.shape == y.shape else 'shape'}")
    print(f"{same} images equal to the last bit, {differ} renders differ, "
          f"{sum(a[k].ndim == 0 for k in a.files)} refusals")
    return differ


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "render":
        render_all(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(1 if compare(sys.argv[2], sys.argv[3]) else 0)
    else:
        print("usage: prepared_identity.py render OUT.npz | compare BEFORE.npz AFTER.npz", file=sys.stderr)
        sys.exit(2)
