"""pyrender through OSMesa (Debian libosmesa6), the fallback when EGL is missing: the same
image as through EGL.

PyOpenGL picks one platform per process, so each platform renders in its own interpreter with
``PYOPENGL_PLATFORM`` set.  Both run Mesa's llvmpipe with pyrender's shaders; they differ in one
respect: pyrender's framebuffer is multisampled through EGL and not through OSMesa, so pixels
along silhouettes differ (by up to the full contrast of the edge).  Those pixels are left out:
every pixel whose 3x3 neighbourhood sees more than one object (or the background) at pixel
centres, by the ray tracer's ``intersect`` (about 8 % of the Whitted image at 96x72).  Elsewhere
the images agree to one 8-bit step (pyrender's output is 8-bit, decoded with a 2.2 power: a step
is at most 2.2/255 = 0.0086 in linear terms), allowing 0.5 % of the pixels up to 0.05 where
the tessellated silhouette falls outside the analytic one's neighbourhood.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
STEP = 2.2 / 255.0
CODE = """
import sys
import numpy as np
import workbench
r = workbench.render(workbench.load_scene("whitted"), "pyrender", width=96, height=72)
print(r.stats["gl_renderer"])
np.save(sys.argv[1], r.image)
"""


def _render(platform: str, out: Path) -> str:
    env = dict(os.environ, PYOPENGL_PLATFORM=platform)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    p = subprocess.run([sys.executable, "-c", CODE, str(out)], capture_output=True, text=True, env=env,
                       timeout=300)
    assert p.returncode == 0, p.stderr[-3000:]
    return p.stdout.strip().splitlines()[-1]


def test_pyrender_through_osmesa_matches_egl(tmp_path):
    osmesa = _render("osmesa", tmp_path / "osmesa.npy")
    egl = _render("egl", tmp_path / "egl.npy")
    assert "osmesa" in osmesa and "egl" in egl  # the platform each child actually used
    a, b = np.load(tmp_path / "osmesa.npy"), np.load(tmp_path / "egl.npy")
    assert a.mean() > 0.05  # a rendered scene, not a black frame
    d = np.abs(a - b).max(-1)
    inner = ~_silhouettes(*a.shape[:2])
    assert inner.mean() > 0.8
    assert (d[inner] > STEP).mean() <= 0.005, (d[inner] > STEP).mean()
    assert d[inner].max() <= 0.05, d[inner].max()
    assert d[~inner].max() > STEP  # the multisampled edges differ: the mask is not empty for nothing


def _silhouettes(height: int, width: int) -> np.ndarray:
    """(H, W) bool: pixels whose 3x3 neighbourhood holds more than one object index (-1 = none)
    at pixel centres."""
    import workbench
    from numpy.lib.stride_tricks import sliding_window_view
    scene = workbench.load_scene("whitted")
    o, d = scene.camera.with_resolution(width, height).rays()
    _, _, obj = workbench.raytrace.intersect(scene, o.reshape(-1, 3), d.reshape(-1, 3))
    win = sliding_window_view(np.pad(np.asarray(obj).reshape(height, width), 1, mode="edge"), (3, 3))
    return win.max((-1, -2)) != win.min((-1, -2))
