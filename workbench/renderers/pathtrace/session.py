"""Progressive path tracing: :class:`PathTraceSession` keeps each pixel's running sum and sum
of squares, so a caller (the renderer, the UI, a reference cache) asks for more samples and
gets the running image and its noise estimate.

Image definition: a pixel is the box-filtered average of the radiance over its square (uniform
jitter in the pixel; ``pixel_filter="center"``: the radiance through its centre), linear RGB,
nothing clipped.  Noise: the per-pixel standard error of the
mean ``sqrt(s^2 / N)`` with ``s^2`` the unbiased sample variance of the pixel's ``N`` sample
radiances (per channel); ``noise_rmse`` is its root mean square over pixels and channels.
The same ``seed`` gives the same image whatever the thread count; ``add_samples(a)`` then
``add_samples(b)`` gives exactly the image of ``add_samples(a + b)``.
"""
from __future__ import annotations

import time

import numpy as np

from ...core.columns import pack
from ...core.errors import NotApplicable, WorkbenchError
from ...core.tol import tol
from ...scene import model as m
from ...scene.kinds import kind_of
from ...scene.prepared import prepare
from ..raytrace.flatten import flatten, light_rows
from ..kernels.columns import LIGHT_COLS, PATH_COUNTS, TEX_COLS, Mat, PathCount, PathOpt
from ..raytrace.whitted import camera_frame, fused_textures
from .emitters import build_emitters
from .geometry import FRONT_ONLY, triangulated

FRESNEL = {"none": 0, "schlick": 1, "exact": 2}
MIS = {"balance": 1.0, "power": 2.0}
TRANSPORT = {"full": 0, "diffuse": 1, "eye_specular": 2}
"""Light transport the estimator follows (:mod:`.kernels` docstring): all of it; radiosity's
(Lambertian ``kd C``, one-sided surfaces, surface emitters only); the hybrid's (mirror and glass
along the eye path, then radiosity's)."""
PIXEL_FILTER = {"box": 0, "center": 1}
"""``box``: uniform jitter over the pixel's square; ``center``: every sample through its centre."""
_BYTES_PER_PIXEL = 2 * 24 + 4 * 24
"""Running sums and sums of squares (float64), then at most four (H*W, 3) float64 temporaries
while the image and its standard error are made."""
_BYTES_PER_TRIANGLE = 2000
"""A mesh triangle's share of the flattened scene (vertices, normals, uvs, emission: 33 doubles,
the BVH build's temporaries and its packed groups) with a wide margin."""
_BASE_BYTES = 64 << 20
"""Per-thread scratch and the light tables: far below this (the analytic primitives are
counted apart, :func:`..raytrace.flatten.flatten_bytes`)."""


def estimate_bytes(scene: m.Scene, width: int, height: int) -> int:
    """Upper bound of the memory a path-traced render of ``scene`` at ``width x height`` allocates."""
    from ..raytrace.flatten import flatten_bytes
    triangles = sum(len(o.faces) for o in scene.objects if isinstance(o, m.Mesh))
    return (int(width) * int(height) * _BYTES_PER_PIXEL + triangles * _BYTES_PER_TRIANGLE
            + flatten_bytes(scene) + _BASE_BYTES)


def _kernels():
    from . import kernels
    return kernels


MAX_MAJORANT_DEPTH = 1e4
"""Most expected tentative collisions of one crossing of a medium (its majorant times its
bounding sphere's diameter, object space) the path tracer accepts: delta and ratio tracking
cost that many density evaluations per crossing."""


class PathTraceSession:
    """The path tracer's state for one scene at one image size.

    Parameters
    ----------
    scene : Scene (its camera is used at ``width x height``).
    seed : int, >= 0.  fresnel : ``none`` | ``schlick`` | ``exact`` (split of kr, kt as the ray
    tracer's option).  rr_start : bounce from which Russian roulette plays (>= 1).
    max_bounces : hard stop of a path (>= 1).  mis : ``power`` (exponent 2) or ``balance``.
    triangulate : trace plain opaque polygons and rectangles, and convex area lights, as
    triangles through the BVH (:mod:`.geometry`; the same surfaces, faster: a scene of triangles
    only casts every ray straight into the BVH and compiles no analytic primitive's code:
    ``kernels.cast``), else as the ray tracer's polygons.
    transport : ``full`` | ``diffuse`` | ``eye_specular`` (:data:`TRANSPORT`; the latter two
    ignore point and directional lights, textures and vertex emission).
    pixel_filter : ``box`` | ``center`` (:data:`PIXEL_FILTER`).
    accel : the ray tracer's acceleration structure (``bvh``, ``octree``, ``none``:
    :mod:`..raytrace.accel`; the same image for a given seed).

    Raises
    ------
    NotApplicable
        Nothing emits light: no emissive surface, no area / point / directional light and a
        black background (``diffuse``, ``eye_specular``: no emissive surface and no area light).
    """

    def __init__(self, scene: m.Scene, width: int, height: int, *, seed: int = 0, fresnel: str = "none",
                 rr_start: int = 3, max_bounces: int = 1000, mis: str = "power", triangulate: bool = True,
                 transport: str = "full", pixel_filter: str = "box", accel: str = "bvh"):
        if seed < 0:
            raise WorkbenchError(f"pathtrace: seed must be >= 0, got {seed}")
        if rr_start < 1 or max_bounces < 1:
            raise WorkbenchError(f"pathtrace: rr_start and max_bounces must be >= 1, got {rr_start}, {max_bounces}")
        if fresnel not in FRESNEL or mis not in MIS:
            raise WorkbenchError(f"pathtrace: fresnel must be one of {', '.join(FRESNEL)} and mis one of "
                                 f"{', '.join(MIS)}, got {fresnel!r}, {mis!r}")
        if transport not in TRANSPORT or pixel_filter not in PIXEL_FILTER:
            raise WorkbenchError(f"pathtrace: transport must be one of {', '.join(TRANSPORT)} and pixel_filter "
                                 f"one of {', '.join(PIXEL_FILTER)}, got {transport!r}, {pixel_filter!r}")
        self.transport, self.pixel_filter = transport, pixel_filter
        t0 = time.perf_counter()
        self.scene = scene.with_camera(scene.camera.with_resolution(width, height))
        self.width, self.height, self.seed = int(width), int(height), int(seed)
        traced = triangulated(self.scene) if triangulate else self.scene
        prepared = prepare(traced)  # the same bounds and media as self.scene's (flat, opaque)
        sd = flatten(traced, accel, prepared=prepared)
        for i, mt in enumerate(sd.materials):  # area lights as triangles: still front-face emitters
            if mt.name.startswith(FRONT_ONLY):
                sd.mat_tab[i, Mat.FRONT_ONLY] = 1.0
        self.sd = sd
        self.emitters = build_emitters(sd)
        full = transport == "full"
        point = [lt for lt in scene.lights if not isinstance(lt, m.AreaLight)] if full else []
        lights = np.ascontiguousarray(light_rows(point).reshape(-1, LIGHT_COLS))
        surfaces_emit = bool((sd.mat_tab[sd.mat, Mat.EMISSION:Mat.EMISSION + 3] > 0).any())
        for o in scene.objects:
            kind = kind_of(o)
            if getattr(kind, "MEDIUM", False):
                depth = o.density * 2.0 * kind.bound_radius(o)
                if depth > MAX_MAJORANT_DEPTH:
                    raise WorkbenchError(
                        f"pathtrace: {o.kind} {o.name or ''!s}{' ' if o.name else ''}has a majorant of {o.density:g} per "
                        f"unit across {2 * kind.bound_radius(o):.4g} units: about {depth:.3g} tentative collisions per "
                        f"crossing for delta tracking, above {MAX_MAJORANT_DEPTH:g} (minutes per image); lower its "
                        f"density, or use raycast or raytrace (the march's cost is its step count)")
        media_emit = any(max(getattr(o, "emission", (0.0,))) > 0 for o in scene.objects
                         if getattr(kind_of(o), "MEDIUM", False))
        emissive = surfaces_emit or media_emit or bool((sd.tri_e > 0).any())
        background = np.asarray(scene.background, dtype=np.float64)
        if full and not (emissive or len(point) or (background > 0).any()):
            raise NotApplicable("pathtrace: nothing emits light (no emissive surface, no light and a "
                                "black background): the image would be black")
        if not full and not surfaces_emit:
            raise NotApplicable(f"pathtrace (transport={transport}): no emitting surface (area light or "
                                "emissive material): diffuse transport has nothing to distribute")
        tex = fused_textures(self.scene, sd) if full else None
        self.textured = tex is not None
        if tex is None:
            tex = np.zeros((len(sd.mat_tab), TEX_COLS))
        names = [mt.name for mt in sd.materials]
        media = ([names.index(mt.name) for mt in prepared.camera_media]
                 + sd.media_holding(traced, traced.camera.position))[-4:]
        if transport == "diffuse":  # every surface opaque: no medium
            media = []
        self.opts = pack(PathOpt, fresnel=FRESNEL[fresnel], ray_offset=tol.ray_offset, t_min=tol.t_min,
                         zero=tol.zero, extent=sd.extent, normal_cancel=tol.normal_cancel, rr_start=rr_start,
                         max_bounces=max_bounces, textured=self.textured, mis_beta=MIS[mis],
                         background=background, n_media=len(media), media=media + [0] * (4 - len(media)),
                         transport=TRANSPORT[transport], pixel_filter=PIXEL_FILTER[pixel_filter],
                         has_media=sd.has_media)
        self.shading = (sd.mat, sd.mat_tab, np.ascontiguousarray(tex), lights)
        self.geo = sd.kernel_args()
        self.cam = camera_frame(self.scene.camera, self.width, self.height)
        npix = self.width * self.height
        self.sums = np.zeros((npix, 3))
        self.sumsq = np.zeros((npix, 3))
        self.counts = np.zeros(PATH_COUNTS, np.int64)
        self.samples = 0
        self.timings = {"build": time.perf_counter() - t0, "bvh_build": sd.bvh_build_time, "trace": 0.0,
                        "trace_cpu": 0.0}
        self.timings["compile"] = self._ensure_compiled()

    def _ensure_compiled(self) -> float:
        """First-call JIT (or numba disk-cache load) of the kernel, on an empty image."""
        k = _kernels()
        t0 = time.perf_counter()
        k.render_samples(self.geo, self.shading, self.emitters.arrays(), self.cam, self.opts, 0, 0, 0,
                         np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(PATH_COUNTS, np.int64))
        return time.perf_counter() - t0

    def add_samples(self, n: int) -> np.ndarray:
        """Trace ``n`` more samples per pixel; returns the running image (H, W, 3) float32."""
        if n < 0:
            raise WorkbenchError(f"pathtrace: the number of samples to add must be >= 0, got {n}")
        if n:
            t0, c0 = time.perf_counter(), time.process_time()
            _kernels().render_samples(self.geo, self.shading, self.emitters.arrays(), self.cam, self.opts,
                                      self.seed, self.samples, int(n), self.sums, self.sumsq, self.counts)
            self.timings["trace"] += time.perf_counter() - t0
            self.timings["trace_cpu"] += time.process_time() - c0  # CPU seconds, all threads
            self.samples += int(n)
        return self.image

    @property
    def image(self) -> np.ndarray:
        """(H, W, 3) float32: the mean of the samples so far (zeros before any)."""
        mean = self.sums / max(self.samples, 1)
        return mean.reshape(self.height, self.width, 3).astype(np.float32)

    @property
    def std_error(self) -> np.ndarray | None:
        """(H, W, 3) float32 per-pixel standard error of the mean, None before two samples."""
        n = self.samples
        if n < 2:
            return None
        mean = self.sums / n
        var = np.maximum(self.sumsq - n * mean * mean, 0.0) / (n - 1)
        return np.sqrt(var / n).reshape(self.height, self.width, 3).astype(np.float32)

    @property
    def noise_rmse(self) -> float | None:
        """RMS over pixels and channels of the per-pixel standard error (None before two samples)."""
        se = self.std_error
        return None if se is None else float(np.sqrt(np.mean(se.astype(np.float64) ** 2)))

    def stats(self) -> dict:
        """Counts and rates of the samples so far."""
        c = self.counts
        n = self.samples * self.width * self.height
        trace = self.timings["trace"]
        return {"samples_per_pixel": self.samples, "samples": n, **{col.name.lower(): int(c[col]) for col in PathCount},
                "mean_path_length": float(c[PathCount.CAMERA_RAYS] + c[PathCount.EXTENSION_RAYS])
                / max(int(c[PathCount.CAMERA_RAYS]), 1),
                "samples_per_s": n / trace if trace > 0 else 0.0,
                "samples_per_cpu_s": n / self.timings["trace_cpu"] if self.timings["trace_cpu"] > 0 else 0.0,
                "noise_rmse": self.noise_rmse, "emitter_triangles": len(self.emitters.cdf),
                "triangles": int(len(np.unique(self.sd.tri_src))),
                "triangle_references": int(len(self.sd.tri_v)), "scene_extent": self.sd.extent}


def run_to_noise(session: PathTraceSession, target: float, *, max_spp: int = 1 << 16,
                 time_limit: float | None = None, first: int = 8, on_pass=None) -> PathTraceSession:
    """Add samples to ``session`` until its ``noise_rmse`` is at most ``target`` (or ``max_spp``
    samples per pixel, or ``time_limit`` seconds of tracing in this call), and return it.

    The noise of a mean falls as ``1 / sqrt(N)``: after ``first`` samples, each pass asks for
    the ``N (noise / target)^2`` samples the target needs (at most doubling ``N`` per pass, so
    a poor early estimate cannot overshoot far, and so the time limit is checked often).
    ``on_pass(session)`` is called after each pass (progress).
    """
    if not target > 0.0:
        raise WorkbenchError(f"pathtrace: the target noise must be > 0, got {target}")
    t0 = time.perf_counter()
    while session.samples < max_spp:
        n = session.samples
        if n < 2:
            want = max(first, 2) - n
        else:
            noise = session.noise_rmse
            if noise <= target:
                break
            want = min(n, max(1, int(np.ceil(n * (noise / target) ** 2)) - n))
        if time_limit is not None and n >= 2:
            spent = time.perf_counter() - t0
            rate = session.timings["trace"] / n  # seconds per sample per pixel
            if spent + want * rate > time_limit:
                want = int((time_limit - spent) / rate)
                if want < 1:
                    break
        session.add_samples(min(want, max_spp - n))
        if on_pass is not None:
            on_pass(session)
    return session
