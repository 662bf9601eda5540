"""The registered ``hybrid`` method: radiosity for diffuse interreflection, ray tracing from the
eye for mirrors and glass (the two-pass method; Wallace, Cohen & Greenberg 1987, in the
simple form the course sketches: view-independent diffuse pass, view-dependent specular pass).

Pass 1 solves radiosity on every surface (a specular surface takes part with its diffuse
reflectance kd * color: it occludes and reflects diffusely, but light it mirrors onto diffuse
surfaces is not transported, no caustics).  Pass 2 builds a derived scene in which each
diffuse object (kr == kt == 0) is a Mesh of its patches whose ``vertex_emission`` is the
radiosity interpolated to vertices and whose material has ka = kd = 0 and no emission (the
solution already holds both; ks is kept for highlights), keeps specular objects as they are,
and renders it with the registered ``raytrace`` method: a primary ray that hits a diffuse
surface returns its radiosity, one that hits a mirror or glass follows the ray tracer's
recursion until it lands on a diffuse surface (or the light, or the background).

Progress (the window's, :mod:`workbench.app.ui.jobs`): ``on_progress(phase, done, total,
unit)`` hears the radiosity pass's phases (:func:`.method.solve_scene`: the form factors'
rows, then the solve, which reports no amount done) and the ray-trace pass's rows
(``"ray trace"``); ``on_tile`` gets the ray-trace pass's bands of the final image.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...scene import features as ft
from ...scene import model as m
from ...scene.kinds import kind_of
from ..base import Knob, Option, RenderResult, callback
from ..base import render as render_method
from .. import support as sp
from .method import SUPPORT as RADIOSITY_SUPPORT
from .method import check_camera_outside, common_options, estimate_solve_bytes, solve_scene

_RAY_PASS = {ft.SPECULAR, ft.REFLECTION, ft.REFRACTION, ft.ABSORPTION}
SUPPORT = sp.declare(
    approximated={**{f: c.reason for f, c in RADIOSITY_SUPPORT.items()
                     if c.status is sp.Status.APPROXIMATED},
                  ft.REFLECTION: "ray-traced from the eye; caustics are not transported by the radiosity pass",
                  ft.REFRACTION: "ray-traced from the eye; caustics are not transported by the radiosity pass"},
    left_out={**{f: c.reason for f, c in RADIOSITY_SUPPORT.items()
                 if c.status is sp.Status.LEFT_OUT and f not in _RAY_PASS},
              ft.HYPERTEXTURES: "the radiosity pass has no patches in a participating medium (no volume "
                                "transport), so the eye-ray pass drops it too rather than draw a medium that "
                                "neither lights nor shadows the surfaces around it",
              ft.TEXELS: "the fur's base takes its radiosity patches; its strands, a medium without "
                         "patches, are dropped from both passes"})
"""Radiosity's table, with the specular effects the eye-ray pass adds (:mod:`..support`)."""

RAYTRACE_OPTIONS = ("max_depth", "threshold", "spp", "fresnel")


def is_diffuse(mat: m.Material) -> bool:
    return mat.kr == 0 and mat.kt == 0


def derived_scene(scene: m.Scene, patches, radiance: np.ndarray) -> tuple[m.Scene, int]:
    """The scene with every diffuse object replaced by its radiosity-emitting patch mesh (a fur
    by its base's), and without the participating media that have no surface (hypertextures,
    left out: :data:`SUPPORT`).

    Returns the scene and the number of objects replaced."""
    vrad = patches.vertex_values(radiance)
    by_object: dict[int, list[int]] = {}
    for s, obj in enumerate(patches.surface_objects):
        by_object.setdefault(id(obj), []).append(s)
    objects, materials, replaced = [], dict(scene.materials), 0
    for obj in scene.objects:
        mat = scene.material_of(obj)
        surfaces = by_object.get(id(obj))
        if getattr(kind_of(obj), "MEDIUM", False) and not surfaces:
            continue  # a medium without a surface (hypertexture): left out (SUPPORT), no volume transport
        if not is_diffuse(mat) or not surfaces:
            objects.append(obj)
            continue
        sel = np.isin(patches.surface, surfaces)
        ids = patches.vertex_ids[sel]
        tris = np.concatenate([ids[:, [0, 1, 2]], ids[:, [0, 2, 3]]])
        tris = tris[(tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])]
        used, faces = np.unique(tris, return_inverse=True)
        name = f"{mat.name}__radiosity"
        materials[name] = replace(mat, name=name, ka=0.0, kd=0.0, emission=(0.0, 0.0, 0.0),
                                  texture=None, bump=None)
        objects.append(m.Mesh(material=name, name=obj.name, vertices=m._ro(patches.vertices[used]),
                              faces=faces.reshape(-1, 3).astype(np.int64), source="radiosity patches",
                              vertex_emission=m._ro(vrad[used])))
        replaced += 1
    return replace(scene, objects=tuple(objects), materials=materials, ambient=(0.0, 0.0, 0.0)), replaced


class HybridRenderer:
    """Radiosity (diffuse) + ray tracing from the eye (specular), two passes."""

    name = "hybrid"
    ui_kind = "cpu"
    support = SUPPORT
    knob = Knob("patch_size", (0.2, 0.1, 0.05, 0.035, 0.025), 0.05,
                "largest patch edge / scene diagonal")
    options = {**common_options(),
               "max_depth": Option(int, 5, "ray tracer: maximum ray generations per path"),
               "threshold": Option(float, 1e-3, "ray tracer: weight below which a child ray is not traced", low=0.0),
               "spp": Option(int, 1, "ray tracer: samples per pixel"),
               "fresnel": Option(str, "none", "ray tracer: reflection/transmission split",
                                 ("none", "schlick", "exact")),
               "on_tile": Option(callback, None, "ray-trace pass: callback on_tile(y0, y1, x0, x1, "
                                 "tile) with each band of the final image as it is traced"),
               "on_progress": Option(callback, None, "callback on_progress(phase, done, total, unit) "
                                     "at each step of both passes (total None: the step reports "
                                     "no amount done)")}
    memory_options = ("patch_size", "hemicube_resolution", "solver", "row_cache_mb",
                      "max_depth", "threshold", "spp")

    def estimate_bytes(self, scene: m.Scene, width: int, height: int, **opts) -> int:
        """The radiosity pass (:func:`.method.estimate_solve_bytes`), whose patches stay alive,
        plus the ray tracer on the derived scene (two triangles per patch,
        :func:`..raytrace.whitted.estimate_trace_bytes`)."""
        from ..raytrace.whitted import estimate_trace_bytes
        check_camera_outside(scene, self.name)  # refused before any estimate
        solve, P = estimate_solve_bytes(scene, opts)
        return solve + estimate_trace_bytes(scene, width, height, opts, True, extra_triangles=2 * P)

    def render(self, scene: m.Scene, width: int, height: int, **opts) -> RenderResult:
        on_progress, on_tile = opts["on_progress"], opts["on_tile"]
        sol = solve_scene(scene, opts, self.name, on_progress=on_progress)
        derived, replaced = derived_scene(scene, sol.patches, sol.radiance)
        traced = {"rows": 0}

        def band(y0, y1, x0, x1, tile):
            if on_tile is not None:
                on_tile(y0, y1, x0, x1, tile)
            traced["rows"] = max(traced["rows"], y1)
            on_progress("ray trace", traced["rows"], height, "rows")
        if on_progress is not None:
            on_progress("ray trace", 0, height, "rows")
        rt = render_method(derived, "raytrace", width=width, height=height,
                           on_tile=band if on_progress is not None else on_tile,
                           **{k: opts[k] for k in RAYTRACE_OPTIONS})
        timings = dict(sol.timings)
        timings["compile"] += rt.timings.get("compile", 0.0)
        timings["raytrace"] = rt.timings["total"]
        stats = dict(sol.stats)
        stats["objects_as_radiosity_meshes"] = replaced
        stats.update({f"raytrace_{k}": v for k, v in rt.stats.items()})
        needs = ft.scene_needs(scene)
        left_out = sp.notes(self.support, needs) + sol.left_out
        if needs & {ft.REFLECTION, ft.REFRACTION}:
            left_out.append(sp.Note("caustics", "light mirrored or refracted onto diffuse surfaces is not "
                                    "transported by the radiosity pass"))
        used = sp.used(needs | {ft.EMITTERS}, left_out)
        return RenderResult(self.name, rt.image, timings, stats, used, left_out, depth=rt.depth)

