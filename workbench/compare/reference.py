"""Which images a method is judged against: the scene's *full* reference (ground truth) and the
method's *matched* reference (the limit of its own physics), by one documented rule.

The ideal image
---------------
Every reference estimates one image: each pixel is the average of the radiance over the pixel's
square (a box filter), linear and unclipped (the metrics clip both images to [0, 1]).  The path
tracer and Mitsuba sample it with uniform jitter; the ray tracers with :data:`CONVERGED_SPP`
stratified samples.  Methods that point-sample the pixel centre (the raster methods, radiosity's
display, the ray tracers at ``spp = 1``) therefore carry a pixel-filtering error at edges: it is
part of their discretisation error, as the course's aliasing is.

Full reference (what the scene *is*)
------------------------------------
1. ``--reference METHOD`` when the user names one: that method at its finest knob value and
   otherwise default options (e.g. ``raytrace`` at depth 12 and one sample per pixel);
2. scenes with emitters (area lights or emissive materials): ``pathtrace``, unbiased path
   tracing (Kajiya 1986) run until the RMS of its per-pixel standard error, on the display
   range, is at most :data:`TARGET_NOISE` or :data:`SAMPLE_BUDGET` samples are spent (a count,
   not a time, so the same scene always gets the same reference); its noise is stated with the
   reference, and errors below it are not resolved;
3. scenes lit by point and directional lights only: ``raytrace`` (Whitted) at its deepest
   recursion, which is exact for the course's model (local model + shadows + ideal reflection and
   refraction), at :data:`CONVERGED_SPP` samples per pixel;
4. otherwise the first method that applies (``raycast``, ``phong``, then the rest).

Matched reference (what the method *would* give at an infinitely fine knob)
---------------------------------------------------------------------------
:data:`MATCHED` maps each method to the renderer and options that compute exactly its physics
(e.g. Phong's limit: the same local model ray-cast analytically without shadows; radiosity's:
path tracing restricted to diffuse transport).  Error against it is the method's
discretisation error; error against the full reference is its total error; the gap is the cost
of the physics it leaves out (and, for methods that sample pixel centres, of the pixel filter).  Outside renderers (pyrender, Mitsuba) have no matched reference.

References are rendered through the disk cache (:mod:`.reference_cache`), so ``compare``,
``study`` and the UI render each one once.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import NotApplicable, OverMemory, WorkbenchError
from ..renderers.base import available, default_methods, get_renderer
from ..scene import features as F
from ..scene.model import Scene
from . import reference_cache
from .runs import MethodRun

IDEAL_IMAGE = ("each pixel is the average radiance over its square (box filter), linear and unclipped; "
               "metrics clip both images to [0, 1]")
SAMPLING_NOTE = ("References estimate the box-filtered pixel (" + IDEAL_IMAGE + "). Methods that sample "
                 "the pixel centre carry a pixel-filtering error at edges: it is part of their "
                 "discretisation error.")
CONVERGED_SPP = 16
"""Stratified samples per pixel (4 x 4) of a deterministic ray tracer's reference."""
TARGET_NOISE = 0.01
"""RMS of the path-traced reference's standard error on the display range that ends its sampling."""
SAMPLE_BUDGET = 1 << 25
"""Path-traced samples (pixels x spp) a reference may take: about a minute on two cores here (the
reference then states the noise it reached)."""
PILOT_SPP = 16
MAX_SPP = 4096
"""Most samples per pixel of a path-traced reference (small images would otherwise spend the
whole sample budget on the few pixels that straddle a light's edge)."""

#: method -> (reference method, options, what that reference computes).  A matched reference is
#: the limit of the method along its knob: methods that sample pixel centres whatever their knob
#: (raster, radiosity's display, the ray tracers at spp = 1) are matched at pixel centres, so
#: their gap to the (box-filtered) full reference holds the pixel filter besides the physics.
_RAYCAST_LOCAL = ("raycast", {"shadows": False, "spp": 1},
                  "the same local model ray-cast on the analytic surfaces, no shadows, pixel centres")
MATCHED: dict[str, tuple[str, dict, str]] = {
    "flat": _RAYCAST_LOCAL, "gouraud": _RAYCAST_LOCAL, "phong": _RAYCAST_LOCAL, "zbuffer": _RAYCAST_LOCAL,
    "raycast": ("raycast", {"spp": CONVERGED_SPP}, "the ray caster itself, box-filtered (its knob is spp)"),
    "raytrace": ("raytrace", {"max_depth": 12}, "the Whitted ray tracer at depth 12, pixel centres"),
    "povray": ("raytrace", {"max_depth": 12, "transmissive_shadows": True},
               "the Whitted ray tracer (POV-Ray's model) at depth 12, pixel centres"),
    "radiosity": ("pathtrace", {"transport": "diffuse", "pixel_filter": "center"},
                  "path tracing of diffuse transport only (Lambertian kd * colour, emitters only), "
                  "pixel centres"),
    "hybrid": ("pathtrace", {"transport": "eye_specular", "pixel_filter": "center"},
               "path tracing: mirror and glass from the eye, diffuse transport after (no caustics), "
               "pixel centres"),
    "pathtrace": ("pathtrace", {}, "the path tracer itself, converged (box-filtered)"),
}
OUTSIDE = {"pyrender": "an outside renderer with its own PBR model: no matched reference in the workbench",
           "mitsuba": "an outside renderer: judged against the full reference only"}


@dataclass
class Reference:
    """A rendered reference: ``run`` holds the image; ``noise`` the RMS of its own error estimate
    on the display range (0 when not estimated); ``what`` says which physics it contains."""

    method: str
    options: dict
    reason: str
    run: MethodRun
    noise: float = 0.0
    noise_note: str = ""
    what: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def image(self) -> np.ndarray:
        return self.run.image

    def describe(self) -> dict:
        """JSON-ready facts of the reference (for reports)."""
        res = self.run.result
        return {"method": self.method, "options": self.options, "reason": self.reason,
                "what": self.what, "noise_rmse": self.noise, "noise_note": self.noise_note,
                "image_definition": IDEAL_IMAGE, "time_s": self.run.time, "cold_s": self.run.cold,
                "compile_s": self.run.compile, "cache": res.stats.get("cache", "") if res else "",
                "features_used": list(res.features_used) if res else [],
                "left_out": list(res.left_out) if res else []}


def candidates(scene: Scene) -> list[tuple[str, str]]:
    """Full-reference candidates in rule order, each with the reason it would be chosen."""
    out = []
    if F.EMITTERS in F.scene_needs(scene):
        out.append(("pathtrace", "scene has emitters: unbiased path tracing (Kajiya 1986), converged"))
    out.append(("raytrace", "point-lit scene: the Whitted ray tracer is exact for the course's model "
                            "(local model, shadows, ideal reflection and refraction)"))
    out.append(("raycast", "analytic primitives under the same local model (no secondary rays)"))
    out.append(("phong", "per-pixel local model at the finest tessellation (no ray tracer registered)"))
    rest = [m for m in default_methods() if m not in {c for c, _ in out}]
    out.extend((m, "first registered method that applies, at its finest setting") for m in rest)
    return [(m, why) for m, why in out if m in available()]


MEDIUM_KNOBS = (("volume_resolution", (16, 32, 64, 128)), ("step_scale", (4.0, 2.0, 1.0, 0.5, 0.25)))
"""Options on which a participating medium's discretisation error depends, with the values a
study sweeps (cheapest first): the raster's 3D texture resolution (``volume_resolution``) and
the ray marchers' step multiplier (``step_scale``, times every hypertexture's ``step``).  On a
scene with hypertextures a method is swept along the first of them it declares (the raster,
which has both, along its texture's resolution) and its references take the last (finest)
value of each it declares; a method with neither (the path tracer) keeps its knob."""


def medium_finest(method: str, scene: Scene | None) -> dict:
    """The finest value of each :data:`MEDIUM_KNOBS` option ``method`` declares, on a scene with
    hypertextures (else nothing)."""
    if scene is None or F.HYPERTEXTURES not in F.scene_needs(scene):
        return {}
    accepted = get_renderer(method).options
    return {name: values[-1] for name, values in MEDIUM_KNOBS if name in accepted}


def finest_options(method: str, scene: Scene | None = None) -> dict:
    """Options putting ``method``'s quality knob at its most accurate value, and on a scene with
    hypertextures its march step or texture resolution too (:func:`medium_finest`)."""
    knob = get_renderer(method).knob
    return {**({knob.name: knob.values[-1]} if knob.values else {}), **medium_finest(method, scene)}


def display_noise(std_error: np.ndarray | None, image: np.ndarray) -> float:
    """RMS over pixels and channels of the standard error of the *display-range* value
    ``clip(x, 0, 1)``: a channel whose mean lies more than 3 standard errors above 1 is clipped
    whatever the noise (0); elsewhere the clipped value's standard error is at most
    ``min(se, 1)`` (clipping is 1-Lipschitz).  None (no estimate) gives 0."""
    if std_error is None:
        return 0.0
    se = np.minimum(np.asarray(std_error, dtype=np.float64), 1.0)
    se = np.where(np.asarray(image, dtype=np.float64) - 3.0 * se > 1.0, 0.0, se)
    return float(np.sqrt(np.mean(se ** 2)))


def _cached_run(scene: Scene, method: str, width: int, height: int, options: dict) -> MethodRun:
    """A :class:`MethodRun` of ``method`` through the reference cache (never raises for a
    method's failure; ``NotApplicable`` gives ``status = "not_applicable"``)."""
    run = MethodRun(method, dict(options))
    try:
        res = reference_cache.cached_render(scene, method, width, height, **options)
    except NotApplicable as e:
        run.status, run.reason = "not_applicable", str(e)
        return run
    except OverMemory as e:
        run.status, run.reason = "over_memory", str(e)
        return run
    except WorkbenchError as e:
        run.status, run.reason = "failed", str(e)
        return run
    run.result = res
    run.cold, run.compile = res.timings["total"], float(res.timings.get("compile", 0.0))
    return run


def _converged_pathtrace(scene: Scene, width: int, height: int, options: dict,
                         target: float, budget: int) -> tuple[MethodRun, float]:
    """The path tracer run to a display-range noise ``target`` within ``budget`` samples: a
    pilot of :data:`PILOT_SPP` samples per pixel measures the noise, and the final count is the
    power of two that ``noise ~ 1 / sqrt(spp)`` needs, cut to the budget (both renders cached
    and the choice deterministic, so a rerun costs nothing)."""
    pilot = _cached_run(scene, "pathtrace", width, height, {**options, "spp": PILOT_SPP})
    if pilot.status != "ok":
        return pilot, 0.0
    noise = display_noise(pilot.result.std_error, pilot.image)
    need = PILOT_SPP * max(1.0, (noise / target) ** 2)
    spp = 1 << math.ceil(math.log2(need))
    while spp > PILOT_SPP and (spp * width * height > budget or spp > MAX_SPP):
        spp //= 2
    if spp == PILOT_SPP:
        return pilot, noise
    run = _cached_run(scene, "pathtrace", width, height, {**options, "spp": spp})
    if run.status != "ok":
        return run, 0.0
    return run, display_noise(run.result.std_error, run.image)


def _stratified_noise(scene: Scene, method: str, width: int, height: int, options: dict,
                      image: np.ndarray) -> float:
    """RMSE (display range) between the reference and the same render at a quarter of its
    samples: a measured bound of the sampling error a stratified reference still has (its own
    error is smaller than its coarser version's)."""
    coarse = _cached_run(scene, method, width, height, {**options, "spp": max(1, options["spp"] // 4)})
    if coarse.status != "ok":
        return 0.0
    return float(np.sqrt(np.mean((np.clip(coarse.image, 0, 1) - np.clip(image, 0, 1)) ** 2)))


def render_reference(scene: Scene, width: int, height: int, method: str, options: dict, reason: str,
                     what: str = "", *, target: float = TARGET_NOISE, budget: int = SAMPLE_BUDGET) -> Reference:
    """Render one reference (cached) and measure its own noise; ``options`` of ``pathtrace``
    without ``spp`` mean 'converged' (see :func:`_converged_pathtrace`)."""
    t0 = time.perf_counter()
    if method == "pathtrace" and "spp" not in options:
        run, noise = _converged_pathtrace(scene, width, height, options, target, budget)
        note = (f"RMS of the per-pixel standard error on the display range ({run.options.get('spp', '?')} "
                f"samples per pixel; target {target}, budget {budget} samples)")
    else:
        run = _cached_run(scene, method, width, height, options)
        noise, note = 0.0, "deterministic"
        if run.status == "ok" and run.result.std_error is not None:
            noise = display_noise(run.result.std_error, run.image)
            note = "RMS of the per-pixel standard error on the display range"
        elif run.status == "ok" and options.get("spp", 1) >= 4:
            noise = _stratified_noise(scene, method, width, height, options, run.image)
            note = (f"RMSE against the same render at {max(1, options['spp'] // 4)} samples per pixel "
                    "(an upper estimate of its own sampling error)")
    if run.status == "ok" and not run.warm:
        run.warm = [time.perf_counter() - t0] if run.result.stats.get("cache") == "hit" else []
    return Reference(method, dict(run.options), reason, run, noise, note, what)


def _full_options(method: str, scene: Scene) -> dict:
    if method == "pathtrace":
        return {}
    opts = finest_options(method, scene)
    if method in ("raytrace", "raycast") and "spp" not in opts:
        opts["spp"] = CONVERGED_SPP
    return opts


def choose_reference(scene: Scene, width: int, height: int, method: str | None = None,
                     repeat: int = 0) -> Reference:
    """Render the full reference by the rule above (or with ``method``, if given).
    ``repeat`` is accepted for compatibility and ignored (references are not timed)."""
    if method is not None:
        get_renderer(method)  # unknown name -> WorkbenchError
        cands = [(method, "chosen by the user (--reference)")]
    else:
        cands = candidates(scene)
    tried = []
    for m, why in cands:
        try:
            opts = _full_options(m, scene)
        except ImportError as e:  # registered but its module is broken
            tried.append(f"{m}: cannot be loaded ({e})")
            continue
        if method is not None and m != "pathtrace":
            opts = finest_options(m, scene)    # the user's method as it is, at its finest knob
        ref = render_reference(scene, width, height, m, opts, why, what=_what(m, scene))
        if ref.run.status == "ok":
            return ref
        tried.append(f"{m}: {ref.run.reason}")
    raise WorkbenchError("no reference image: no registered method renders this scene ("
                         + "; ".join(tried or ["no method registered"]) + ")")


def _what(method: str, scene: Scene) -> str:
    if method == "pathtrace":
        return "all light transport the scene describes (unbiased; noise stated)"
    if method == "raytrace":
        return "local model, shadows, ideal reflection and refraction (no diffuse interreflection)"
    return MATCHED.get(method, (None, None, "the method at its finest setting"))[2]


#: Gouraud and Phong draw stand-ins for global effects by default where the scene needs them
#: (:mod:`workbench.renderers.raster_standins`): their physics is then the ray tracer's, approximated.
_STANDIN_SHADOWS = ("raycast", {"shadows": True, "spp": 1},
                    "the same local model ray-cast with shadow feelers (the limit of the shadow-map "
                    "stand-in), pixel centres")
_STANDIN_WHITTED = ("raytrace", {"max_depth": 12},
                    "the Whitted ray tracer at pixel centres: the physics the stand-ins (environment maps, "
                    "blending, shadow maps) approximate; their approximation error counts here")


def _standins_drawn(options: dict | None) -> frozenset[str]:
    """The stand-ins a Gouraud/Phong run draws, from its ``standins`` option (default on)."""
    value = str((options or {}).get("standins", "on")).strip().lower()
    if value == "on":
        return frozenset({"envmap", "blend", "shadows"})
    return frozenset() if value == "off" else frozenset(x.strip() for x in value.split(","))


def matched_spec(method: str, scene: Scene | None = None,
                 options: dict | None = None) -> tuple[str, dict, str] | None:
    """``(reference method, options, what it computes)`` matching ``method``'s physics, or None
    for outside renderers and methods without one (a user's GLSL model has no ray-cast twin).
    ``scene`` and the run's ``options``: Gouraud and Phong with stand-ins (on by default) match
    the Whitted ray tracer on a scene that needs reflection or refraction when they draw an
    environment map or blending, the ray caster with shadows on one that needs shadows when they
    draw shadow maps; else (``standins=off`` too) the table :data:`MATCHED`: the bare local model."""
    spec = MATCHED.get(method)
    if spec is not None and scene is not None and method in ("gouraud", "phong"):
        needs, drawn = F.scene_needs(scene), _standins_drawn(options)
        if (F.REFLECTION in needs or F.REFRACTION in needs) and drawn & {"envmap", "blend"}:
            spec = _STANDIN_WHITTED
        elif F.SHADOWS in needs and scene.lights and "shadows" in drawn:
            spec = _STANDIN_SHADOWS
    if spec is None:
        return None
    m, opts, what = spec
    if m not in available():
        return None
    accepted = get_renderer(m).options
    if any(k not in accepted for k in opts):  # the reference method lacks that mode here
        return None
    return m, dict(opts), what


def matched_reason(method: str) -> str:
    """Why ``method`` has no matched reference (for reports)."""
    if method.startswith("glsl:"):
        return "a user's shading model: the ray caster does not evaluate it, no matched reference"
    return OUTSIDE.get(method, "no matched reference for this method")


class References:
    """The full reference of a scene and, on demand, each method's matched reference, rendered
    once per (method, options) at one size."""

    def __init__(self, scene: Scene, width: int, height: int, method: str | None = None):
        self.scene, self.width, self.height = scene, width, height
        self.full = choose_reference(scene, width, height, method)
        self._matched: dict[tuple, Reference | None] = {}

    def matched(self, method: str, options: dict | None = None) -> Reference | None:
        """``method``'s matched reference for a run with ``options``, or None (none exists, or
        it does not apply)."""
        spec = matched_spec(method, self.scene, options)
        if spec is None:
            return None
        m, opts, what = spec
        opts = {**opts, **medium_finest(m, self.scene)}  # the medium's limit too (MEDIUM_KNOBS)
        key = (m, tuple(sorted(opts.items())))
        if key not in self._matched:
            if m == self.full.method and opts == _full_options(m, self.scene) and m == "pathtrace":
                ref = self.full
            else:
                ref = render_reference(self.scene, self.width, self.height, m, opts,
                                       f"matched reference of {method}", what)
            self._matched[key] = ref if ref.run.status == "ok" else None
        return self._matched[key]


def physical_differences(result_left_out: list, reference_features: list[str]) -> list[str]:
    """Features the reference builds that a method leaves out (its ``left_out`` notes,
    :class:`workbench.renderers.support.Note`).

    A method with any such feature differs from the reference physically, not only by
    discretisation; its error measures the missing effect too.
    """
    left = {note.feature for note in result_left_out}
    return sorted(left & set(reference_features))


__all__ = ["CONVERGED_SPP", "IDEAL_IMAGE", "MATCHED", "Reference", "References", "SAMPLING_NOTE",
           "MEDIUM_KNOBS", "candidates", "choose_reference", "display_noise", "finest_options", "matched_spec",
           "physical_differences", "render_reference"]
