"""Mitsuba 3 as an outside reference renderer (method ``mitsuba``), as pyrender is for raster.

The scene is exported by :mod:`.mitsuba_export` (mapping table there) and rendered by Mitsuba's
``path`` integrator (``volpath`` when the scene has a participating medium; unbounded depth,
Russian roulette) with a box pixel filter: each pixel is
the box-filtered average of the radiance over its square, linear float32 RGB, not clipped.

Child process
-------------
Every render runs in a child process (:mod:`.mitsuba_child`): ``mi.set_variant`` is global,
process-wide state that any other code importing Mitsuba would share (and could change under
us), and the LLVM variant *aborts* the process on this machine (Debian's LLVM 15), which must
not take the workbench (or its UI) down.  The child costs about half a second of start-up,
small beside a reference render.

Variant
-------
``variant = "auto"`` probes ``llvm_ad_rgb`` once per renderer instance by rendering a tiny
scene in a throw-away child process; if that fails (abort, missing library) it uses
``scalar_rgb``.  ``RenderResult.stats["variant"]`` says which variant ran and why.

Progress
--------
With ``on_progress(phase, done, total, unit)`` (the window's progress bar) the child's
progress file is read while it runs (:func:`child_progress`, :mod:`.watch`): its start-up and
the scene's loading report no amount done, then the samples per pixel done.  Only the scalar
variant reports within a pass (block by block); the LLVM variant renders a pass as one kernel,
so its count moves once per pass (half the samples each).  An exception from ``on_progress``
(a cancelled job) ends the child.

Noise
-----
The ``spp`` samples are taken as two independent passes of ``spp/2`` samples (different seeds);
the image is their sample-weighted mean and the per-pixel standard error of that mean is
estimated from their difference: with pass means ``a`` (``n1`` samples) and ``b`` (``n2``),
``s^2 = (a - b)^2 / (1/n1 + 1/n2)`` estimates the per-sample variance and
``stderr = s / sqrt(n1 + n2)`` (for ``n1 = n2``: ``|a - b| / 2``).  It is an unbiased variance
estimate with one degree of freedom per pixel: noisy pixel by pixel, exact on average.
``stats["stderr"]`` holds it, (H, W, 3) float32, and ``stats["stderr_rms"]`` its RMS.
"""
from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..core.tol import tol
from ..scene.model import Scene
from ..scene.tessellate import MAX_LEVEL
from .base import Knob, Option, RenderResult, callback
from .estimates import triangle_bound
from .watch import relay, run_watched
from . import support as sp
from .mitsuba_export import MODEL_NOTES, RR_DEPTH, export_scene
from ..scene import features as F
from ..scene.features import scene_needs
from ..scene.kinds import kind_of
from ..scene.kinds.hypertexture import MAX_GRID

FALLBACK_VARIANT = "scalar_rgb"
FAST_VARIANT = "llvm_ad_rgb"
VARIANTS = ("auto", FALLBACK_VARIANT, FAST_VARIANT)
MAX_SPP = 1 << 20
"""Largest accepted samples per pixel (a render of 2^20 spp already takes days here)."""
INSTALL_HINT = ("Mitsuba 3 is not installed: pip install -e '.[reference]' (bash workbench.sh installs it), "
                "or pip install 'mitsuba>=3.5'")

#: A tiny scene whose render exercises the path integrator, a BSDF and an emitter (the probe).
_PROBE = ("import sys, mitsuba as mi; mi.set_variant(sys.argv[1]); "
          "s = mi.load_dict({'type': 'scene', 'integrator': {'type': 'path', 'max_depth': -1}, "
          "'sensor': {'type': 'perspective', 'film': {'type': 'hdrfilm', 'width': 4, 'height': 4}}, "
          "'ball': {'type': 'sphere', 'center': [0, 0, 5], 'bsdf': {'type': 'dielectric'}}, "
          "'wall': {'type': 'rectangle', 'bsdf': {'type': 'diffuse'}, "
          "         'emitter': {'type': 'area', 'radiance': {'type': 'rgb', 'value': 1.0}}}, "
          "'lamp': {'type': 'point', 'position': [0, 2, 3]}}); "
          "import numpy as np; print(float(np.asarray(mi.render(s, spp=4)).sum()))")
_PROBE_TIMEOUT_S = 120.0

#: Memory of the child process before any scene data: the interpreter, numpy and Mitsuba's
#: libraries (measured peak RSS of a 16x16 render of the Cornell box: about 150 MB).
CHILD_BASE_BYTES = 200 * 2**20
#: Per triangle: the PLY copy, Mitsuba's float32 mesh (positions, normals, faces) and its BVH.
BYTES_PER_TRIANGLE = 256
#: Per pixel: the film (RGB, weight and alpha as float32, per block and for the whole image),
#: each pass's image in the child and the parent, and the parent's mean and stderr images.
BYTES_PER_PIXEL = 4 * (5 * 2 + 3 * 2 * 2 + 3 * 2)


def workbench_root() -> str:
    """The folder holding the ``workbench`` package (the child imports this checkout)."""
    return str(Path(__file__).resolve().parents[2])


def mitsuba_installed() -> bool:
    return importlib.util.find_spec("mitsuba") is not None


def probe_variant(variant: str, timeout: float = _PROBE_TIMEOUT_S) -> tuple[bool, str]:
    """Whether ``variant`` renders a tiny scene in a child process, with the failure's last line."""
    try:
        out = subprocess.run([sys.executable, "-c", _PROBE, variant], capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f"probe timed out after {timeout:.0f} s"
    if out.returncode == 0:
        return True, "probe rendered"
    tail = out.stderr.decode(errors="replace").strip().splitlines()
    why = f"exit status {out.returncode}" + (" (aborted)" if out.returncode in (-6, 134) else "")
    return False, why + (f": {tail[-1][:200]}" if tail else "")


def combine_passes(passes: np.ndarray, spp: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Mean image and per-pixel standard error from two independent passes.

    Parameters
    ----------
    passes : (2, H, W, 3) the passes' images (each the mean of its own samples).
    spp : the two passes' sample counts ``n1, n2``.

    Returns
    -------
    image : (H, W, 3) float32, ``(n1 a + n2 b) / (n1 + n2)``.
    stderr : (H, W, 3) float32, ``|a - b| / sqrt((1/n1 + 1/n2) (n1 + n2))`` (module docstring);
        0 where a pass is not finite (the image's non-finite pixels are counted by ``render``).
    """
    a, b = (np.asarray(p, dtype=np.float64) for p in passes)
    n1, n2 = (float(n) for n in spp)
    image = (n1 * a + n2 * b) / (n1 + n2)
    stderr = np.abs(a - b) / np.sqrt((1.0 / n1 + 1.0 / n2) * (n1 + n2))
    # a non-finite pass value: render() zeroes and counts the image's; the noise image gets 0 too
    stderr = np.where(np.isfinite(stderr), stderr, 0.0)
    return image.astype(np.float32), stderr.astype(np.float32)


def child_progress(folder: str, spp: int) -> tuple:
    """What the child's progress file (:func:`.mitsuba_child.report`) tells, as
    ``on_progress``'s (phase, done, total, unit): starting (no file yet: Python and Mitsuba
    loading) and loading the scene report no amount done; then samples per pixel done of
    ``spp``."""
    try:
        with open(os.path.join(folder, "progress.txt"), encoding="ascii") as f:
            words = f.read().split()
    except OSError:
        words = []
    if words[:1] == ["load"]:
        return ("Mitsuba loading the scene", 0, None, "")
    if words[:1] == ["render"] and len(words) == 2:
        return ("Mitsuba", int(float(words[1])), spp, "spp")
    return ("Mitsuba starting", 0, None, "")


def run_child(plan: dict, folder: str, timeout: float, on_progress=None) -> tuple[np.ndarray, dict]:
    """Write ``plan.json`` into ``folder``, render in the child, return (passes, child
    timings); ``on_progress(phase, done, total, unit)`` hears :func:`child_progress` while it
    runs (an exception from it ends the child)."""
    with open(os.path.join(folder, "plan.json"), "w", encoding="utf-8") as f:
        json.dump(plan, f)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([workbench_root()] + [p for p in [env.get("PYTHONPATH")] if p])
    spp = sum(n for n, _ in plan["passes"])
    if os.path.exists(os.path.join(folder, "progress.txt")):  # a failed child's, before a retry
        os.remove(os.path.join(folder, "progress.txt"))
    poll = relay(lambda last: child_progress(folder, spp), on_progress, child_progress(folder, spp))
    try:
        code, _, err = run_watched([sys.executable, "-m", "workbench.renderers.mitsuba_child", folder],
                                   folder, env, timeout, poll)
    except subprocess.TimeoutExpired:
        raise WorkbenchError(f"method 'mitsuba': the render took longer than timeout = {timeout:g} s") from None
    res_path = os.path.join(folder, "result.json")
    if code != 0 or not os.path.isfile(res_path):
        tail = err.strip().splitlines()[-3:]
        raise WorkbenchError(f"method 'mitsuba': the Mitsuba child process failed (exit status "
                             f"{code}): {' | '.join(tail)[-600:]}")
    with open(res_path, encoding="utf-8") as f:
        info = json.load(f)
    return np.load(os.path.join(folder, "passes.npy")), info


class MitsubaRenderer:
    """The registered ``mitsuba`` method (see the module docstring and :mod:`.mitsuba_export`)."""

    name = "mitsuba"
    ui_kind = "cpu"
    support = sp.declare(
        approximated={**{f: "exported as its raster tessellation (no such primitive in Mitsuba 3)"
                         for f in (F.BLOBS, F.ISOSURFACES, F.LATHES)},
                      F.OPACITY: "constant opacity cuts an object out or keeps it opaque; maps not exported",
                      F.REFRACTION: "exact Fresnel split only (Mitsuba's dielectric)",
                      F.POINT_LIGHTS: "isotropic, inverse-square (falloff 'none' matched at the scene's centre)",
                      F.EMITTERS: "emissive surfaces emit from their front side only",
                      F.HYPERTEXTURES: "a heterogeneous medium on a grid (the object's grid, else option "
                                       "volume_grid), trilinear; emission left out (Mitsuba 3 has no "
                                       "emissive media)"},
        left_out={**MODEL_NOTES, F.SOLID_TEXTURES: MODEL_NOTES[F.TEXTURES],
                  F.IMAGE_TEXTURES: MODEL_NOTES[F.TEXTURES]})
    knob = Knob("spp", (4, 16, 64, 256, 1024, 4096), 64, "samples per pixel (two independent halves)")
    options = {
        "spp": Option(int, 64, "samples per pixel, >= 2 (two independent passes of spp/2: noise estimate)"),
        "seed": Option(int, 0, "seed of the two passes (seeds 2 seed and 2 seed + 1), >= 0"),
        "variant": Option(str, "auto", "Mitsuba variant: auto probes llvm_ad_rgb and falls back to scalar_rgb",
                          VARIANTS),
        "tessellation": Option(int, 16, f"tessellation level of quadrics and CSG, 1..{MAX_LEVEL} "
                                        "(spheres are analytic)"),
        "volume_grid": Option(int, 64, f"grid resolution of a hypertexture without its own grid, "
                                       f"2..{MAX_GRID} (the density sampled at the cells' centres)"),
        "background_light": Option(bool, True, "a non-black background becomes a constant environment "
                                               "emitter that lights the scene (false: black)"),
        "timeout": Option(float, 3600.0, "seconds before the child render is stopped"),
        "on_progress": Option(callback, None, "callback on_progress(phase, done, total, unit) while "
                              "the child runs: samples per pixel done (within a pass only the "
                              "scalar variant reports; total None: no amount reported)"),
    }

    def __init__(self):
        self._variant_checks: dict[str, tuple[bool, str]] = {}  # per instance, never module-wide

    def _check(self, variant: str) -> tuple[bool, str]:
        if variant not in self._variant_checks:
            self._variant_checks[variant] = probe_variant(variant)
        return self._variant_checks[variant]

    def choose_variant(self, requested: str) -> tuple[str, str]:
        """(variant to run, why)."""
        if requested != "auto":
            return requested, "requested"
        ok, why = self._check(FAST_VARIANT)
        if ok:
            return FAST_VARIANT, f"{FAST_VARIANT} probe rendered"
        return FALLBACK_VARIANT, f"{FAST_VARIANT} unusable here ({why}): fell back to {FALLBACK_VARIANT}"

    memory_options = ("tessellation", "volume_grid")

    def estimate_bytes(self, scene: Scene, width: int, height: int, **options) -> int:
        """Peak memory of a render (child process and the parent's images), bytes: a fixed child
        base, per pixel and per triangle of the meshes, bounded by the raster's
        :func:`.estimates.triangle_bound` at the export's level (the exporter writes every
        object's raster tessellation, or less: analytic spheres, flat kinds at level 1; the
        marching-cubes kinds grow with the level as their surface does, from their level-1
        count), plus each kind's own data (``mitsuba_bytes``: a medium's grids)."""
        level = int(options.get("tessellation", self.options["tessellation"].default))
        grid = int(options.get("volume_grid", self.options["volume_grid"].default))
        extra = sum(getattr(kind_of(o), "mitsuba_bytes", lambda o, g: 0)(o, grid) for o in scene.objects)
        return int(CHILD_BASE_BYTES + BYTES_PER_PIXEL * width * height
                   + BYTES_PER_TRIANGLE * triangle_bound(scene, level) + extra)

    def render(self, scene: Scene, width: int, height: int, *, spp: int = 64, seed: int = 0,
               variant: str = "auto", tessellation: int = 16, volume_grid: int = 64,
               background_light: bool = True, timeout: float = 3600.0, on_progress=None) -> RenderResult:
        if not mitsuba_installed():
            raise WorkbenchError(f"method 'mitsuba': {INSTALL_HINT}")
        if not 2 <= spp <= MAX_SPP:
            raise WorkbenchError(f"method 'mitsuba': spp must be within 2..{MAX_SPP} (two passes for the "
                                 f"noise estimate), got {spp}")
        if seed < 0:
            raise WorkbenchError(f"method 'mitsuba': seed must be >= 0, got {seed}")
        if not 1 <= tessellation <= MAX_LEVEL:
            raise WorkbenchError(f"method 'mitsuba': tessellation must be within 1..{MAX_LEVEL}, got {tessellation}")
        if not 2 <= volume_grid <= MAX_GRID:
            raise WorkbenchError(f"method 'mitsuba': volume_grid must be within 2..{MAX_GRID}, got {volume_grid}")
        if not timeout > 0:
            raise WorkbenchError(f"method 'mitsuba': timeout must be > 0 seconds, got {timeout}")
        t0 = time.perf_counter()
        if on_progress is not None:
            on_progress("Mitsuba choosing its variant", 0, None, "")
        run_variant, why = self.choose_variant(variant)
        t_probe = time.perf_counter() - t0
        n1 = spp // 2
        passes_spec = [[n1, 2 * seed], [spp - n1, 2 * seed + 1]]
        with tempfile.TemporaryDirectory(prefix="workbench-mitsuba-") as folder:
            t0 = time.perf_counter()
            ex = export_scene(scene, folder, tessellation, spp, background_light, volume_grid)
            t_export = time.perf_counter() - t0
            plan = {"variant": run_variant, "scene": ex.scene_dict, "passes": passes_spec}
            t0 = time.perf_counter()
            try:
                passes, info = run_child(plan, folder, timeout, on_progress)
            except WorkbenchError:
                if run_variant == FALLBACK_VARIANT or variant != "auto":
                    raise
                # the LLVM variant passed the probe but died on this scene: scalar instead
                plan["variant"], why = FALLBACK_VARIANT, f"{run_variant} failed on this scene: fell back to {FALLBACK_VARIANT}"
                run_variant = FALLBACK_VARIANT
                passes, info = run_child(plan, folder, timeout, on_progress)
            t_child = time.perf_counter() - t0
        image, stderr = combine_passes(passes, [n1, spp - n1])
        t_render = float(sum(info["passes"]))
        timings = {"probe": t_probe, "export": t_export, "load": info["load"], "render": t_render,
                   "process": t_child - t_render - info["load"], "compile": 0.0}
        stats = {"variant": run_variant, "variant_reason": why, "mitsuba_version": info["mitsuba_version"],
                 "spp": spp, "seed": seed, "passes": passes_spec, "triangles": ex.triangles, "shapes": ex.shapes,
                 "integrator": f"{ex.scene_dict['integrator']['type']} (max_depth -1, Russian roulette "
                               f"from depth {RR_DEPTH})",
                 "pixel_filter": "box (pixel's box-filtered average), not clipped",
                 "samples_per_second": spp * width * height / max(t_render, tol.zero),
                 "render_cpu_seconds": info["cpu"], "child_peak_rss_bytes": info["peak_rss_bytes"],
                 "stderr": stderr, "stderr_rms": float(np.sqrt(np.mean(stderr.astype(np.float64) ** 2)))}
        needs = scene_needs(scene)
        left = sp.complete(self.support, needs, ex.left_out)
        return RenderResult(self.name, image, timings, stats, sp.used(needs, left), left, std_error=stderr)
