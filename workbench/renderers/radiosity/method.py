"""The registered ``radiosity`` method: patches -> form factors -> solve -> Gouraud display.

Only what is needed: no emitters, no radiosity (``NotApplicable``); progressive refinement
draws one hemicube per shooting patch (or, ``shot_rows="raycast"``, casts rays from every
receiver to the shooter) and never builds the matrix.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...core.errors import NotApplicable, WorkbenchError
from ...scene import features as ft
from ...scene.kinds import containing, kind_of
from ...scene.model import Scene
from ...scene.prepared import prepare
from .. import support as sp
from ..base import Knob, Option, RenderResult, callback
from . import solvers
from .formfactors import FormFactors, compute
from .patches import PatchSet, patches_from_scene

SUPPORT = sp.declare(
    approximated={**{f: "one flat patch per triangle of its tessellation (patch_size)"
                     for f in (ft.SPHERES, ft.QUADRICS, ft.CSG, ft.BLOBS, ft.ISOSURFACES, ft.LATHES)}},
    left_out={
        ft.POINT_LIGHTS: "radiosity only knows emitting surfaces (area lights, emissive materials)",
        ft.DIRECTIONAL_LIGHTS: "radiosity only knows emitting surfaces (area lights, emissive materials)",
        ft.SPECULAR: "diffuse interreflection only (the hybrid method adds specular effects)",
        ft.REFLECTION: "diffuse interreflection only (use the hybrid method for mirrors)",
        ft.REFRACTION: "diffuse interreflection only (use the hybrid method for glass)",
        ft.ABSORPTION: "no transmission in radiosity",
        ft.TEXTURES: "a patch has one reflectance, the material's kd * color",
        ft.SOLID_TEXTURES: "a patch has one reflectance, the material's kd * color",
        ft.IMAGE_TEXTURES: "a patch has one reflectance, the material's kd * color",
        ft.BUMP: "patches are flat",
        ft.OPACITY: "patches are opaque",
        ft.ENVIRONMENT: "radiosity has no environment light",
        ft.HYPERTEXTURES: "a participating medium has no surface to cut into patches: radiosity "
                          "exchanges light between surfaces only (no absorption, emission or "
                          "scattering in a volume); the medium is not drawn and lets all light through",
        ft.TEXELS: "the fur's base is cut into patches; its strands are a medium, which radiosity does "
                   "not transport (not drawn)",
    })
"""What radiosity builds, approximates and leaves out, with why (:mod:`..support`)."""

def common_options() -> dict[str, Option]:
    """Options shared by ``radiosity`` and ``hybrid``."""
    return {
        "patch_size": Option(float, 0.05, "largest patch edge as a fraction of the scene's "
                             "bounding-box diagonal (the quality knob)"),
        "hemicube_resolution": Option(int, 128, "hemicube pixels across the top face (even)"),
        "hemicube_rotate": Option(bool, False, "random rotation of each hemicube about the "
                                  "normal (against aliasing)"),
        "hemicube_normalize": Option(bool, True, "scale the delta form factors to sum to 1 "
                                     "(their raw sum is 1 + O(1/res^2), errata 6)"),
        "solver": Option(str, "direct", "linear solver", solvers.METHODS),
        "form_factors": Option(str, "hemicube", "form-factor method", ("hemicube", "raycast")),
        "rays": Option(int, 1024, "raycast form factors: rays per patch"),
        "tol": Option(float, 1e-3, "bound on the true relative error of the solution"),
        "max_iterations": Option(int, 0, "iteration / shot cap (0: what the error bound needs)"),
        "ambient": Option(bool, True, "progressive refinement: show Cohen et al.'s ambient term"),
        "row_cache_mb": Option(float, 128.0, "matrix-free progressive refinement: memory for "
                               "rows of patches that shoot again (0: a new row every shot)"),
        "shot_rows": Option(str, "hemicube", "matrix-free progressive refinement: each shot's "
                            "form factors from one hemicube at the shooter (F_ji by reciprocity) "
                            "or by ray casting from every receiver (exact factor x visibility, "
                            "Wallace et al. 1989; no GL)", ("hemicube", "raycast")),
        "relax": Option(float, 1.2, "matrix-free progressive refinement: overshooting factor "
                        "in (0, 2) (1: plain shooting; 1.2 needs ~40 % fewer shots on the "
                        "Cornell box)"),
    }


_BYTES_PER_PATCH = 4096
"""A patch's corners, vertices, triangles, geometry record and outline (about 1.8 kB, measured)."""
_MATRIX_COPIES = {"direct": 6, "jacobi": 6, "gauss_seidel": 10, "progressive": 6}
"""P x P float64 arrays alive at once: F and the reciprocity report's three (all solvers), plus
I - rho F and its LU copy (direct) or the triangular factors of three channels (Gauss-Seidel);
4.4-5.1 and 8.1-8.7 measured on the Cornell box."""
_HEMICUBE_BYTES_PER_PIXEL = 20 * 16 + 48
"""Per top-face pixel (res^2) of the hemicube: up to 16 patches' five faces (3 res^2 each) of
item buffer, depth and read-back, plus the delta form factors."""
_DISPLAY_BYTES_PER_PIXEL = 64
_FIXED_BYTES = 96 * 2 ** 20
"""GL context, shaders, numba kernels' JIT or cache load."""


def estimate_solve_bytes(scene: Scene, opts: dict) -> tuple[int, int]:
    """Upper bound of the peak bytes of :func:`solve_scene` and the patch count, from the
    patch count (:func:`.patches.count_patches`, computed from the surfaces' sizes without
    cutting them): per-patch arrays, the P x P form-factor matrix and the solver's copies of it
    (none for matrix-free progressive refinement: its row cache and a batch of rows), the
    hemicube's item buffers, ray-cast rows' samples."""
    from .patches import count_patches
    if not opts["patch_size"] > 0:
        raise WorkbenchError(f"patch_size must be a positive fraction of the scene's diagonal, got {opts['patch_size']}")
    P = count_patches(scene, opts["patch_size"] * prepare(scene).extent)
    res = int(opts["hemicube_resolution"])
    total = _FIXED_BYTES + P * _BYTES_PER_PATCH
    matrix_free = opts["solver"] == "progressive" and opts["form_factors"] == "hemicube"
    if matrix_free:
        total += int(max(opts["row_cache_mb"], 0.0) * 2 ** 20) + 4 * 16 * P * 8
    else:
        total += _MATRIX_COPIES[opts["solver"]] * 8 * P * P
    if opts["form_factors"] == "raycast":
        total += max(int(opts["rays"]), 1) * P * 8
    elif not (matrix_free and opts["shot_rows"] == "raycast"):
        total += _HEMICUBE_BYTES_PER_PIXEL * res * res
    return int(total), P


@dataclass
class Solution:
    """Radiosity of a scene's patches and the report of how it was obtained."""

    patches: PatchSet
    radiance: np.ndarray         # (P, 3) what each patch shows
    stats: dict
    timings: dict
    left_out: list  # per-scene notes (objects not cut into patches); the table's are the method's


def _row_provider(hc, stats: dict):
    """Hemicube rows for progressive refinement, tracking their row sums."""
    def rows(idx):
        r = hc.rows(idx)
        s = r.sum(1)
        stats["row_sum_min"] = min(stats.get("row_sum_min", np.inf), float(s.min()))
        stats["row_sum_max"] = max(stats.get("row_sum_max", -np.inf), float(s.max()))
        return r
    return rows


def _rounds(on_round, E, R, areas, ambient: bool, q: float, tol: float):
    """``progressive_rows``'s ``on_batch`` that reports each round of shots to
    ``on_round(shots, radiance, unshot, progress)``: the radiance shown so far (P, 3) (with
    Cohen et al. 1988's ambient term when ``ambient``, as the final display), the unshot share
    of the emitted power (:func:`.solvers.unshot_fraction`) and the way done to the stopping
    rule (:func:`.solvers.shooting_progress`); None when ``on_round`` is None."""
    if on_round is None:
        return None
    stop = solvers._stop_level(q, tol)

    def on_batch(B, dB, shots):
        shown = B + R * solvers._ambient(dB, R, areas) if ambient else B.copy()
        on_round(shots, shown, solvers.unshot_fraction(dB, E, areas),
                 solvers.shooting_progress(B, dB, stop))
    return on_batch


def _shoot_hemicube(geom, E, R, opts, stats, timings, tol, cap, on_round=None) -> solvers.SolveResult:
    """Matrix-free progressive refinement, one hemicube per shooting patch (rows cached);
    ``on_round``: see :func:`_rounds`."""
    from .hemicube import Hemicube
    t1 = time.perf_counter()
    hc = Hemicube(geom, opts["hemicube_resolution"], rotate=opts["hemicube_rotate"],
                  normalize=opts["hemicube_normalize"])
    timings["compile"] += time.perf_counter() - t1
    try:
        q = float(R.max()) * max(1.0, hc.info()["weight_sum"])
        rows = solvers.RowCache(_row_provider(hc, stats), opts["row_cache_mb"])
        res = solvers.progressive_rows(rows, geom.areas, E, R, tol=tol, max_shots=cap, q=q,
                                       ambient=opts["ambient"], relax=opts["relax"],
                                       on_batch=_rounds(on_round, E, R, geom.areas,
                                                        opts["ambient"], q, tol))
        info = hc.info()
    finally:
        hc.release()
    stats.update({"hemicubes_drawn": info["hemicubes_drawn"], "matrix_stored": False,
                  "shot_rows": "hemicube", "rows_cached": len(rows.rows),
                  "row_cache_hits": rows.hits, "gl_renderer": info["gl_renderer"],
                  "hemicube_weight_sum": info["weight_sum"],
                  "hemicube_weight_sum_raw": info["weight_sum_raw"], "reciprocity_error": None,
                  "note": "shooting takes F_ji = F_ij A_i / A_j from the shooter's hemicube; "
                          "the error bound is for that system, which differs from gathering "
                          "by the hemicube's reciprocity error (proximity, errata 6)"})
    return res


def _shoot_raycast(geom, E, R, opts, stats, timings, tol, cap, on_round=None) -> solvers.SolveResult:
    """Matrix-free progressive refinement with ray-cast rows (receivers' exact factors times
    ray-cast visibility, :class:`.raycast.RayRows`; rows cached); ``on_round``: see
    :func:`_rounds`."""
    from .raycast import RayRows
    t1 = time.perf_counter()
    rr = RayRows(geom)
    rr.rows(np.zeros(0, dtype=np.int64))      # the numba kernel's compile (or cache load), apart
    timings["compile"] += time.perf_counter() - t1
    rows = solvers.RowCache(rr.rows, opts["row_cache_mb"])
    q = float(R.max())
    res = solvers.progressive_rows(rows, geom.areas, E, R, tol=tol, max_shots=cap, q=q,
                                   ambient=opts["ambient"], relax=opts["relax"],
                                   on_batch=_rounds(on_round, E, R, geom.areas, opts["ambient"], q, tol))
    stats.update({"matrix_stored": False, "shot_rows": "raycast", "rows_cached": len(rows.rows),
                  "row_cache_hits": rows.hits, "rows_computed": rows.computed,
                  "visibility_rays": rr.rays_cast, "reciprocity_error": None,
                  "note": "each receiver takes its exact point-to-polygon factor to the shooter "
                          "times ray-cast visibility: the gathering system, without reciprocity"})
    return res


def check_camera_outside(scene: Scene, method: str) -> None:
    """Refuse (:class:`NotApplicable`) a camera inside a closed object: patches are lit on their
    outer side only, so the image would be their unlit backs, all black."""
    eye = np.asarray(scene.camera.position, dtype=np.float64)
    for obj in scene.objects:
        if containing(obj, np.eye(4), eye) is not None:
            raise NotApplicable(f"{method}: the camera is inside the closed object "
                                f"{obj.name or kind_of(obj).TYPE!r} ({kind_of(obj).TYPE}): radiosity lights "
                                "the outer side of its patches only and would show their unlit backs "
                                "(move the camera out, or use pathtrace)")


def solve_scene(scene: Scene, opts: dict, method: str, on_round=None,
                on_progress=None) -> Solution:
    """Patches, form factors and solution of ``scene`` with the ``common_options``
    (:func:`check_camera_outside` first).  ``on_round(patches, shots, radiance, unshot,
    progress)`` is called after each round of shots of matrix-free progressive refinement
    (``solver="progressive"`` with hemicube form factors; :func:`_rounds`), never by the other
    solvers.  ``on_progress(phase, done, total, unit)`` (the hybrid method's, see
    :mod:`workbench.app.ui.jobs`) hears the phases: the hemicube matrix's rows (``"radiosity
    form factors"``, patches done of all), then the solve, which reports no amount done
    (``total`` None), as do ray-cast form factors and shooting (its shots counted)."""
    def phase(name, done=0, total=None, unit=""):
        if on_progress is not None:
            on_progress(name, done, total, unit)

    check_camera_outside(scene, method)
    if opts["max_iterations"] < 0:
        raise WorkbenchError(f"{method}: max_iterations must be >= 0 (0: automatic), got {opts['max_iterations']}")
    if opts["row_cache_mb"] < 0:
        raise WorkbenchError(f"{method}: row_cache_mb must be >= 0, got {opts['row_cache_mb']}")
    timings: dict = {"compile": 0.0}
    t0 = time.perf_counter()
    extent = prepare(scene).extent  # patch sizes are fractions of the scene's diagonal
    patches, left_out = patches_from_scene(scene, opts["patch_size"] * extent)
    timings["patches"] = time.perf_counter() - t0
    if len(patches) == 0 or not (patches.emission > 0).any():
        raise NotApplicable(f"{method}: the scene has no emitters (no area light and no emissive "
                            "material): radiosity has nothing to distribute")
    stats = {"patches": len(patches), "solver": opts["solver"], "form_factor_method": opts["form_factors"],
             "patch_size_world": opts["patch_size"] * extent}
    geom = patches.geometry()
    E, R = patches.emission, patches.reflectance
    tol = opts["tol"]
    cap = opts["max_iterations"] or None
    if opts["solver"] == "progressive" and opts["form_factors"] == "hemicube":
        shoot = _shoot_raycast if opts["shot_rows"] == "raycast" else _shoot_hemicube

        def shot(shots, radiance, unshot, progress):
            phase("radiosity shooting", shots, None, "shots")
            if on_round is not None:
                on_round(patches, shots, radiance, unshot, progress)
        phase("radiosity shooting", 0, None, "shots")
        res = shoot(geom, E, R, opts, stats, timings, tol, cap,
                    None if on_round is None and on_progress is None else shot)
        timings["form_factors"] = res.seconds   # rows and shots interleave
        timings["solve"] = 0.0
    else:
        hemicube = opts["form_factors"] == "hemicube"
        phase("radiosity form factors" if hemicube else
              f"radiosity form factors ({opts['form_factors']}: no progress reported)",
              0, len(patches) if hemicube else None, "patches" if hemicube else "")
        ff: FormFactors = compute(geom, opts["form_factors"], opts["hemicube_resolution"],
                                  rotate=opts["hemicube_rotate"], rays=opts["rays"],
                                  normalize=opts["hemicube_normalize"],
                                  on_rows=lambda done, total: phase("radiosity form factors",
                                                                    done, total, "patches"))
        phase(f"radiosity solve ({opts['solver']}: no progress reported)")
        timings["form_factors"] = ff.seconds
        rep = ff.report()
        stats.update({"row_sum_min": rep["row_sum_min"], "row_sum_max": rep["row_sum_max"],
                      "reciprocity_error": rep["reciprocity_error"],
                      "reciprocity_max": rep["reciprocity_max"], "matrix_stored": True})
        if "gl_renderer" in rep:
            stats.update({"gl_renderer": rep["gl_renderer"], "hemicube_weight_sum": rep["weight_sum"],
                          "hemicube_weight_sum_raw": rep["weight_sum_raw"]})
        res = solvers.solve(ff.F, E, R, opts["solver"], tol=tol, max_iterations=cap,
                            ambient=opts["ambient"], areas=geom.areas)
        timings["solve"] = res.seconds
    stats.update({"iterations": res.iterations, "converged": res.converged,
                  "solver_message": res.message, "error_bound": res.error_bound,
                  "residual_history": [float(x) for x in res.residuals[-50:]]})
    return Solution(patches, np.asarray(res.display), stats, timings, left_out)


class RadiosityRenderer:
    """Radiosity with hemicube (or ray-cast) form factors, shown with Gouraud shading."""

    name = "radiosity"
    ui_kind = "cpu"
    support = SUPPORT
    ui_options = {"solver": "progressive"}
    """The window's radiosity shoots (Cohen et al. 1988) and shows each round as it lands
    (``on_pass``)."""
    knob = Knob("patch_size", (0.2, 0.1, 0.05, 0.035, 0.025), 0.05,
                "largest patch edge / scene diagonal")
    options = {**common_options(),
               "on_pass": Option(callback, None, "progressive refinement: callback on_pass(shots, "
                                 "image, unshot, progress) after each round of shots: the image so "
                                 "far, the unshot share of the emitted power and the way done to the "
                                 "stopping rule in [0, 1]"),
               "pass_seconds": Option(float, 0.25, "on_pass: least time between two reported rounds "
                                      "(each draws its image; the last round is always reported)",
                                      low=0.0)}
    memory_options = ("patch_size", "hemicube_resolution", "solver", "row_cache_mb")

    def estimate_bytes(self, scene: Scene, width: int, height: int, **opts) -> int:
        """:func:`estimate_solve_bytes` plus the Gouraud display's image and buffers (a camera
        inside a closed object is refused first: :func:`check_camera_outside`)."""
        check_camera_outside(scene, self.name)
        return estimate_solve_bytes(scene, opts)[0] + _DISPLAY_BYTES_PER_PIXEL * width * height

    def render(self, scene: Scene, width: int, height: int, **opts) -> RenderResult:
        from .display import draw
        from .. import gl
        on_pass = opts["on_pass"]
        last = {"at": -np.inf, "round": None, "shown": None}

        def on_round(patches, shots, radiance, unshot, progress):
            last["round"] = (shots, unshot, progress)
            if time.perf_counter() - last["at"] >= opts["pass_seconds"]:
                on_pass(shots, draw(patches, radiance, scene.camera, scene.background)[0],
                        unshot, progress)
                last["at"], last["shown"] = time.perf_counter(), last["round"]
        sol = solve_scene(scene, opts, self.name, None if on_pass is None else on_round)
        img, t = draw(sol.patches, sol.radiance, scene.camera, scene.background)
        if last["round"] is not None and last["shown"] is not last["round"]:
            shots, unshot, progress = last["round"]  # the last round, skipped for time: shown
            on_pass(shots, img, unshot, progress)
        sol.timings["compile"] += t["compile"]
        sol.timings["display"] = t["display"]
        sol.stats.setdefault("gl_renderer", gl.renderer_name())
        needs = ft.scene_needs(scene)
        left = sp.notes(self.support, needs) + sol.left_out
        return RenderResult(self.name, img, sol.timings, sol.stats, sp.used(needs | {ft.EMITTERS}, left), left)
