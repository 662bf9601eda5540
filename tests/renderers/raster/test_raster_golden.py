"""Golden images: every bundled scene by flat, Gouraud and Phong at 96 x 72 (no MSAA), the bare
local model (``standins="off"``: the stand-ins for global effects are tested in
tests/renderers/raster/test_raster_standins.py), against PNGs in tests/golden/raster/.  llvmpipe output varies slightly across Mesa versions, so the
comparison is on 8-bit sRGB with tolerances: mean absolute difference <= 2 levels and at most
1 % of pixels off by more than 24 levels (edges move by a pixel between rasterisers).

Regenerate (after an intended change, looking at the images):
    WORKBENCH_UPDATE_GOLDEN=1 .venv/bin/python -m pytest tests/renderers/raster/test_raster_golden.py

``hashes.json`` records the SHA-256 of each scene file the images were made from.  A missing
golden image, and a scene file changed since its images were made, are failures whose message
gives the command above: a comparison that cannot be made is never skipped.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pytest

import workbench
from workbench.core.imageio import save_png8, to_srgb8
from workbench.scene.library import bundled

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "raster"
HASHES = GOLDEN / "hashes.json"
W, H = 96, 72
SCENES = [p.stem for p in bundled()]


def _scene_hash(name: str) -> str:
    from workbench.scene.library import resolve
    return hashlib.sha256(resolve(name).read_bytes()).hexdigest()


@pytest.mark.parametrize("scene_name", SCENES)
@pytest.mark.parametrize("method", ["flat", "gouraud", "phong"])
def test_golden(gl_ctx, scene_name, method):
    from PIL import Image
    r = workbench.render(workbench.load_scene(scene_name), method, width=W, height=H, standins="off")
    assert r.stats["nonfinite_pixels"] == 0
    got = to_srgb8(r.image).astype(np.int16)
    path = GOLDEN / f"{scene_name}_{method}.png"
    hashes = json.loads(HASHES.read_text()) if HASHES.is_file() else {}
    if os.environ.get("WORKBENCH_UPDATE_GOLDEN") == "1":
        save_png8(path, got.astype(np.uint8))
        hashes[scene_name] = _scene_hash(scene_name)
        HASHES.write_text(json.dumps(dict(sorted(hashes.items())), indent=1) + "\n")
    regenerate = "WORKBENCH_UPDATE_GOLDEN=1 .venv/bin/python -m pytest tests/renderers/raster/test_raster_golden.py"
    assert path.is_file(), f"no golden image {path.name}: create it with `{regenerate}`"
    assert hashes.get(scene_name) == _scene_hash(scene_name), (
        f"scenes/{scene_name}.toml changed since {path.name} was made: look at the new image, then "
        f"regenerate with `{regenerate}`")
    want = np.asarray(Image.open(path).convert("RGB"), dtype=np.int16)
    diff = np.abs(got - want).max(-1)
    assert diff.mean() <= 2.0, f"{path.name}: mean difference {diff.mean():.2f} levels"
    assert (diff > 24).mean() <= 0.01, f"{path.name}: {(diff > 24).mean():.2%} pixels differ by > 24 levels"


@pytest.mark.parametrize("scene_name", SCENES)
def test_pyrender_renders_every_bundled_scene(gl_ctx, scene_name):
    scene = workbench.load_scene(scene_name)
    r = workbench.render(scene, "pyrender", width=48, height=36)
    ph = workbench.render(scene, "phong", width=48, height=36)
    assert r.stats["nonfinite_pixels"] == 0
    # same camera: the covered pixels mostly agree (IoU of the depth masks; pyrender does not
    # cut the opacity grid out of the envmap scene, hence not 1)
    a, b = np.isfinite(r.depth), np.isfinite(ph.depth)
    assert (a & b).sum() / max((a | b).sum(), 1) > 0.85
