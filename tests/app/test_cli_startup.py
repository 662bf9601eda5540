"""A ray-traced render through the console script imports none of the heavy modules it does not
use (issue #28: start-up was most of a warm ``workbench render whitted -m raytrace``): no GL,
no window, no plots, no mesh library, no outside reference, no ``scipy.linalg`` (numba's BLAS
probe, skipped by :mod:`workbench.core.numba_start`), none of the other renderers, the reports
or the studies.  The child runs the console script as ``__main__`` (``runpy``) with an
``atexit`` handler that writes the names of its loaded modules (``sys.modules``) to a file:
the program runs its ``atexit`` handlers before it ends with ``os._exit``."""
from __future__ import annotations

import subprocess
import sys

from ui_command import WORKBENCH

UNUSED = ("moderngl", "glcontext", "OpenGL", "imgui_bundle", "matplotlib", "pyrender", "trimesh",
          "manifold3d", "mitsuba", "drjit", "flip_evaluator", "tqdm", "dask", "distributed",
          "scipy.linalg", "scipy.spatial", "scipy.ndimage", "scipy.sparse",
          "workbench.renderers.gl", "workbench.renderers.raster", "workbench.renderers.reference",
          "workbench.renderers.radiosity", "workbench.renderers.pathtrace", "workbench.renderers.povray",
          "workbench.compare.report", "workbench.compare.study", "workbench.compare.stress",
          "workbench.app.ui.main")
"""Modules (and their submodules) a ray-traced render does not need."""


CHILD = """import atexit, runpy, sys
modules_file = sys.argv.pop(1)
atexit.register(lambda: open(modules_file, "w").write("\\n".join(sorted(sys.modules))))
del sys.argv[0]  # the console script, then its arguments
runpy.run_path(sys.argv[0], run_name="__main__")
"""
"""``python -c CHILD FILE SCRIPT ARGS...``: run the console script SCRIPT with ARGS as the program;
the names of the modules loaded at its end written to FILE."""


def test_a_raytrace_render_imports_only_what_it_uses(tmp_path):
    out, listing = tmp_path / "t.png", tmp_path / "modules.txt"
    p = subprocess.run([sys.executable, "-c", CHILD, str(listing), WORKBENCH, "render", "whitted", "-m", "raytrace",
                        "--size", "32x24", "--set", "progress=false", "-o", str(out)],
                       capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert p.returncode == 0 and out.is_file(), p.stderr[-2000:]
    loaded = set(listing.read_text().split())
    assert {"numba", "numpy", "workbench.renderers.raytrace.kernels"} <= loaded  # the listing is read right
    heavy = sorted(m for m in loaded if any(m == u or m.startswith(u + ".") for u in UNUSED))
    assert not heavy, heavy


REGISTRIES = ("numba.np.arraymath", "numba.np.npyimpl", "numba.np.linalg", "numba.typed.dictimpl",
              "numba.cpython.unicode")
"""Numba modules that only its target-context refresh imports: a render whose kernels all come
from the disk cache loads none of them (:func:`workbench.core.numba_start.load_cache_hits_without_registries`)."""


def test_a_warm_render_loads_kernels_without_numbas_registries(tmp_path):
    runs = []
    for i in range(2):  # the first run fills the cache if this test process has not yet
        out, listing = tmp_path / f"t{i}.png", tmp_path / f"modules{i}.txt"
        p = subprocess.run([sys.executable, "-c", CHILD, str(listing), WORKBENCH, "render", "whitted", "-m", "raytrace",
                            "--size", "32x24", "--set", "progress=false", "-o", str(out)],
                           capture_output=True, text=True, cwd=tmp_path, timeout=600)
        assert p.returncode == 0 and out.is_file(), p.stderr[-2000:]
        runs.append(set(listing.read_text().split()))
    assert "workbench.renderers.raytrace.kernels" in runs[1]
    assert not sorted(m for m in REGISTRIES if m in runs[1])
    assert (tmp_path / "t0.png").read_bytes() == (tmp_path / "t1.png").read_bytes()
