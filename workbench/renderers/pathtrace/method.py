"""The registered ``pathtrace`` method: a :class:`.session.PathTraceSession` run to ``spp``
samples per pixel, in passes (progress bar, ``on_pass`` callback with the running image).

What the path tracer takes from the one material description (DESIGN.md, "Ground truth and
the error split"): ``kd C`` as a Lambertian lobe, ``ks, n`` as the normalised modified Phong
lobe, ``kr`` as a mirror, ``kt, ior`` (and ``absorption``) as a dielectric with the ray
tracer's Fresnel option, ``emission`` as radiance; the ambient term ``ka`` is off (it stands in
for the indirect light the path tracer computes); the lobes are scaled down together when
``kd max(C) + ks + kr + kt > 1``.  Checker textures are evaluated in the kernel (as the ray
tracer's fused path); other textures, bump, opacity maps and the environment map are left out.

Options ``transport`` (``full``, ``diffuse``: radiosity's physics, ``eye_specular``: the hybrid's)
and ``pixel_filter`` (``box``, ``center``) make it the *matched* reference of other methods
(:mod:`.kernels` docstring).
"""
from __future__ import annotations

import time

from ...core.errors import WorkbenchError
from ...scene import features as F
from ...scene.model import Scene
from .. import support as sp
from ..base import Knob, Option, RenderResult, callback
from ..raytrace.accel import ACCELS
from .session import FRESNEL, MIS, PIXEL_FILTER, TRANSPORT, PathTraceSession, estimate_bytes

_SAMPLES_PER_PASS = 1 << 20
"""Samples (pixels x spp) per kernel call: passes short enough for a progress bar and a UI."""
MAX_SPP = 1 << 20


class PathTraceRenderer:
    """Unbiased path tracing with next-event estimation and MIS (Kajiya 1986; Veach 1997)."""

    name = "pathtrace"
    ui_kind = "progressive"
    support = sp.declare(
        approximated={F.TEXTURES: "plain colours and planar or solid checkers only (others: plain colour)",
                      F.TEXELS: "the strands as a medium of albedo kd C with the isotropic phase function "
                                "(no Kajiya-Kay highlight)"},
        left_out={f: "not evaluated by the path tracer's kernel (plain colour, unbumped, opaque, "
                  "background colour)" for f in (F.IMAGE_TEXTURES, F.BUMP, F.OPACITY, F.ENVIRONMENT)})
    knob = Knob("spp", (2, 4, 16, 64, 256), 16, "samples per pixel")
    options = {
        "spp": Option(int, 16, "samples per pixel (uniform jitter: the box-filtered pixel; >= 2 for a noise estimate)"),
        "seed": Option(int, 0, "seed of the random numbers (>= 0; same seed, same image)"),
        "fresnel": Option(str, "none", "reflection/transmission split: none (constant kr, kt), schlick or exact dielectric", tuple(FRESNEL)),
        "mis": Option(str, "power", "multiple importance sampling heuristic", tuple(MIS)),
        "transport": Option(str, "full", "light transport: full; diffuse (radiosity's physics: every surface "
                            "Lambertian kd*color and one-sided, ks/kr/kt ignored, only area lights and emissive "
                            "materials emit); eye_specular (the hybrid's: mirror and glass followed along the eye "
                            "path, ks ignored, then diffuse transport, no caustics)", tuple(TRANSPORT)),
        "pixel_filter": Option(str, "box", "box: uniform jitter over the pixel (the ideal image); center: every "
                               "sample through the pixel centre (the point-sampled image of raster and radiosity)",
                               tuple(PIXEL_FILTER)),
        "rr_start": Option(int, 3, "bounce from which Russian roulette plays (survival min(0.95, max throughput))"),
        "max_bounces": Option(int, 1000, "hard stop of a path (a guard: roulette ends paths long before)"),
        "accel": Option(str, "bvh", "acceleration structure over the triangles and the bounded analytic "
                        "primitives: bvh, octree or none (every one tested); same image", ACCELS),
        "progress": Option(bool, False, "show a tqdm progress bar (CLI)"),
        "on_pass": Option(callback, None, "callback on_pass(spp_so_far, image, std_error) after each pass"),
    }

    memory_options = ()  # memory grows with the image size only (sums per pixel), not with spp

    def estimate_bytes(self, scene: Scene, width: int, height: int, **options) -> int:
        """Upper bound of the bytes a render allocates (:func:`.session.estimate_bytes`)."""
        return estimate_bytes(scene, width, height)

    def progressive_session(self, scene: Scene, width: int, height: int, **o) -> PathTraceSession:
        """A session the interactive window refines pass by pass (``ui_kind``
        ``"progressive"``), with the converted options ``o`` but ``spp`` (the target), ``progress``
        and ``on_pass``."""
        return PathTraceSession(scene, width, height, seed=o["seed"], fresnel=o["fresnel"],
                                rr_start=o["rr_start"], max_bounces=o["max_bounces"], mis=o["mis"],
                                transport=o["transport"], pixel_filter=o["pixel_filter"], accel=o["accel"])

    def render(self, scene: Scene, width: int, height: int, **o) -> RenderResult:
        if not 1 <= o["spp"] <= MAX_SPP:
            raise WorkbenchError(f"method 'pathtrace': option 'spp' must be within 1..{MAX_SPP}, got {o['spp']}")
        t0 = time.perf_counter()
        ses = self.progressive_session(scene, width, height, **o)
        per_pass = max(1, _SAMPLES_PER_PASS // (width * height))
        bar = None
        if o["progress"]:
            from tqdm import tqdm
            bar = tqdm(total=o["spp"], unit="spp", desc=self.name)
        while ses.samples < o["spp"]:
            n = min(per_pass, o["spp"] - ses.samples)
            ses.add_samples(n)
            if bar is not None:
                bar.update(n)
            if o["on_pass"] is not None:
                o["on_pass"](ses.samples, ses.image, ses.std_error)
        if bar is not None:
            bar.close()
        timings = dict(ses.timings)
        timings["setup"] = time.perf_counter() - t0 - timings["trace"]
        stats = ses.stats()
        se = ses.std_error
        if se is not None:  # kept with the stats' arrays by the reference cache
            stats["stderr"], stats["stderr_rms"] = se, stats["noise_rmse"]
        return RenderResult(self.name, ses.image, timings, stats, *self._features(scene, ses), std_error=se)

    def _features(self, scene: Scene, ses: PathTraceSession):
        """(features used, ``left_out`` notes): the :attr:`support` table for the scene's needs,
        then what this render's options skip (``transport``), textures the kernel did not
        evaluate, emitters it could not sample."""
        needs = F.scene_needs(scene)
        left = [sp.Note("ambient", "off (the path tracer computes the indirect light it stands in for)")]
        left += sp.notes(self.support, needs)
        noted = {n.feature for n in left}

        def add(f, reason):
            if f in needs and f not in noted:
                left.append(sp.Note(f, reason))
                noted.add(f)
        if ses.transport != "full":
            why = f"transport={ses.transport}: "
            for f, what in ((F.POINT_LIGHTS, "only emitting surfaces light the scene"),
                            (F.DIRECTIONAL_LIGHTS, "only emitting surfaces light the scene"),
                            (F.SPECULAR, "no Phong lobe (ks ignored)")):
                add(f, why + what)
            for f in (F.REFLECTION, F.REFRACTION, F.ABSORPTION):
                add(f, why + ("Lambertian kd*color, opaque" if ses.transport == "diffuse"
                              else "followed along the eye path only (no caustics)"))
        if not ses.textured:
            why = ("not evaluated by the path tracer's kernel" if ses.transport == "full"
                   else f"transport={ses.transport}: as radiosity")
            for f in (F.TEXTURES, F.BUMP, F.OPACITY, F.ENVIRONMENT):
                add(f, f"{why} (plain colour, unbumped, opaque, background colour)")
        left += [sp.Note("emitter sampling", u) for u in ses.emitters.unsampled]
        return sp.used(needs, left), left
