"""The two registered ray-tracing methods: ``raycast`` (eye rays + shadow feelers, the course's
"lancer de rayons") and ``raytrace`` (plus recursive reflection and refraction, "suivi de rayons",
Whitted 1980).

One numba kernel (:func:`.kernels.render_pixels`) traces each pixel's whole ray tree depth
first with an explicit stack (the course's ``raytrace``/``shade`` recursion), over bands of
rows ("tiles", delivered to ``on_tile`` as they finish), shading each hit with
:func:`.kernels.shade_hit`: a pixel's colour is the sum of ``weight x local colour`` over the
ray tree.  Texture maps (colour patterns and images, bump, opacity, the environment) are
evaluated in the kernel (:mod:`..kernels.textures`, tables from :mod:`.maps`), as
:mod:`workbench.renderers.texturing` evaluates them for the raster methods; a scene whose maps
are at most planar or solid checkers compiles the checker alone.

Options (see ``Option`` help texts): ``max_depth`` (quality knob of ``raytrace``: the maximum
number of ray generations in a path, primary = 1, as the course's ``recurs_max`` and POV-Ray's
``max_trace_level``), ``threshold`` (the course's perceptual threshold on the accumulated
weight), ``spp`` (samples per pixel, stratified jitter, seeded by ``seed``), ``fresnel``
(``none``: constant k_r, k_t; ``schlick``; ``exact`` dielectric), ``transmissive_shadows``,
``blinn``, ``progress`` (tqdm bar), ``on_tile``, ``accel`` (the acceleration
structure over triangles and bounded analytic primitives: ``bvh``, ``octree`` or ``none``,
:mod:`.accel`) and ``traversal_stats`` (nodes visited
and primitives tested per camera ray, :mod:`.traversal_stats`).

``on_tile(y0, y1, x0, x1, tile)`` is called from the rendering thread after each band with
``tile`` the (y1 - y0, x1 - x0, 3) float32 linear image of rows ``y0:y1`` and columns ``x0:x1``.
"""
from __future__ import annotations

import time

import numpy as np

from ...core.columns import pack
from ...core.errors import WorkbenchError
from ...core.tol import tol
from ...scene import features as F
from ...scene.model import Mesh, Scene
from ...scene.prepared import prepare
from .. import support as sp
from ..base import Knob, Option, RenderResult, callback
from ..kernels.columns import RAY_COUNTS, RayCount, WhittedOpt
from .accel import ACCELS, accel_extra_bytes
from .flatten import SceneData, flatten, flatten_bytes
from .maps import checkers_only, texture_tables

_RAYS_PER_BAND = 1 << 16
"""Primary rays of a band when ``on_tile`` or the progress bar is called once a band."""
_FUSED_RAYS_PER_BAND = 1 << 20
"""Primary rays of a band when nothing is called between bands (no ``on_tile``, no progress
bar): the kernel holds no per-ray arrays, only the band's colours and depths (32 bytes a
pixel), so its bands are larger, and each costs a start of the thread pool, a
scratch set per task and a wait for the slower thread at its end (measured: five bands of 65k
rays instead of one cost the 640 x 480 Whitted scene's trace 11 % more CPU time on one thread,
15 % on two)."""


_BYTES_PER_PRIMARY_RAY = 160
"""Origin, direction, jitter, pixel index and temporaries of one primary ray (all are built
up front by :func:`camera_rays`)."""
_BYTES_PER_STACK_ROW = 136
"""A pending ray of the fused kernel's stack (:func:`.kernels.ray_stack`)."""
_BYTES_PER_TRIANGLE = 768
"""A mesh triangle in the flattened scene and its BVH (458 MB for 1.31 M triangles, bench
bvh_1m, with margin)."""
_BYTES_PER_PIXEL = 64
"""Image, depth and the band's float64 results."""
_FIXED_BYTES = 96 * 2 ** 20
"""Kernels' JIT (or cache load), scene tables, per-task scratch."""


def generation_bound(scene: Scene, max_depth: int, threshold: float, recursive: bool) -> int:
    """The ``max_depth`` the kernels get: at most ``max_depth``, and one more than the deepest
    generation a ray can reach with a weight above ``threshold`` (so that it changes no image
    and no count).

    A ray of generation g (primary = 1) carries a weight of at most k^(g-1), with k the largest
    ``kr + kt`` of the scene's materials (a child's factor is kr, kt, kr + kt on total internal
    reflection, or kr + kt F, kt (1 - F) with Fresnel), and a child is traced only if its
    weight exceeds ``threshold``.  With k < 1 and a threshold above the smallest normal double
    (below it, products stall in the subnormals), g <= 1 + ceil(ln threshold / ln k'), k' = k
    rounded up by 2^-50 for the products' rounding.  Otherwise the bound is ``max_depth``.
    """
    if not recursive:
        return 1
    k = max((m.kr + m.kt for m in scene.materials.values()), default=0.0)
    if k <= 0.0:
        return 1
    if k < 1.0 and threshold >= np.finfo(np.float64).tiny:
        kk = k * (1.0 + 2.0 ** -50)
        reach = 1 + int(np.ceil(np.log(threshold) / np.log(kk)))
        return int(min(max_depth, reach + 1))
    return int(max_depth)


def estimate_trace_bytes(scene: Scene, width: int, height: int, opts: dict, recursive: bool,
                         extra_triangles: int = 0) -> int:
    """Upper bound of the peak bytes of a ray-traced render (see :meth:`_WhittedBase.estimate_bytes`);
    ``extra_triangles``: triangles the scene will gain before tracing (hybrid's patch meshes)."""
    from ...scene import model as m
    spp = int(opts["spp"])
    tris = extra_triangles + sum(len(o.faces) for o in scene.objects if isinstance(o, m.Mesh))
    total = (_FIXED_BYTES + tris * _BYTES_PER_TRIANGLE + width * height * _BYTES_PER_PIXEL
             + flatten_bytes(scene))
    total += accel_extra_bytes(tris, opts.get("accel", "bvh"))
    total += width * height * spp * _BYTES_PER_PRIMARY_RAY
    G = generation_bound(scene, int(opts.get("max_depth", 1)), float(opts.get("threshold", 0.0)), recursive)
    opacity = any(mt.opacity is not None for mt in scene.materials.values())
    total += texture_bytes(scene)
    return int(total + _kernels().MAX_TASKS * _kernels().stack_rows(G, opacity) * _BYTES_PER_STACK_ROW)


def texture_bytes(scene: Scene) -> int:
    """Bytes of the images the kernels' maps hold (float64 RGBA, :mod:`.maps`), from the files'
    headers (each counted once a use)."""
    paths = [mp.path for mt in scene.materials.values() for mp in (mt.texture, mt.bump, mt.opacity)
             if mp is not None and mp.kind == "image"]
    if scene.environment is not None and scene.environment.kind == "image":
        paths.append(scene.environment.path)
    total = 0
    for path in paths:
        try:
            from PIL import Image
            with Image.open(path) as im:
                total += 32 * im.width * im.height
        except OSError:
            pass  # refused with its reason when the maps are built
    return total


def camera_frame(camera, width: int, height: int) -> np.ndarray:
    """The pinhole camera as the fused kernel reads it: position (3), ``world_from_camera``'s
    rotation (3 x 3, row-major; columns r, u, -f), ``tan(fov_y / 2)``, aspect ratio, width and
    height.  Pixel ``(i, j)``'s centre ray (as :func:`camera_rays` with ``spp = 1``) has the
    direction ``x r + y u - (-f)`` normalised, ``x = ((j + 1/2) / width * 2 - 1) tan aspect``,
    ``y = (1 - (i + 1/2) / height * 2) tan``."""
    R = np.linalg.inv(camera.camera_from_world())[:3, :3]
    return np.array([*np.asarray(camera.position, dtype=np.float64), *R.reshape(-1),
                     np.tan(np.radians(camera.fov_y) / 2.0), width / height, width, height])


def camera_rays(camera, width: int, height: int, spp: int, seed: int):
    """Primary rays, ``spp`` per pixel, stratified jitter on an ``m x ceil(spp/m)`` grid
    (``m = ceil(sqrt(spp))``); one sample per pixel goes through the pixel centre (same rays as
    :meth:`Camera.rays`).

    Returns origins (H*W*spp, 3), unit directions (H*W*spp, 3) and pixel indices, pixel-major.
    """
    th = np.tan(np.radians(camera.fov_y) / 2.0)
    aspect = width / height
    if spp == 1:
        ox = np.full((1, 1, 1), 0.5)
        oy = ox
    else:
        m = int(np.ceil(np.sqrt(spp)))
        m2 = int(np.ceil(spp / m))
        s = np.arange(spp)
        jit = np.random.default_rng(seed).random((height, width, spp, 2))
        ox = ((s % m)[None, None, :] + jit[..., 0]) / m
        oy = ((s // m)[None, None, :] + jit[..., 1]) / m2
    x = ((np.arange(width)[None, :, None] + ox) / width * 2.0 - 1.0) * th * aspect
    y = (1.0 - (np.arange(height)[:, None, None] + oy) / height * 2.0) * th
    R = camera_frame(camera, width, height)[3:12].reshape(3, 3)  # world_from_camera: columns r, u, -f
    d = np.empty((height, width, spp, 3))
    for c in range(3):
        d[..., c] = x * R[c, 0] + y * R[c, 1] - R[c, 2]
    d = d.reshape(-1, 3)
    d /= np.sqrt(np.einsum("ij,ij->i", d, d))[:, None]
    o = np.empty_like(d)
    o[:] = camera.position
    pix = np.repeat(np.arange(height * width), spp)
    return o, d, pix


def _kernels():
    from . import kernels
    return kernels


def ensure_compiled(sd: SceneData, maps) -> float:
    """Run :func:`.kernels.render_pixels` once on one ray (first-call JIT, or a load from the
    numba disk cache), with the scene's texture maps ``maps`` (:func:`.maps.texture_tables`).
    Returns the seconds spent (a fraction of a millisecond once compiled for this scene's kinds
    and maps in this process: the kernels are specialised to them, see
    :mod:`..kernels.specialise` and :mod:`..kernels.textures`)."""
    k = _kernels()
    t0 = time.perf_counter()
    O = np.zeros((1, 3))
    D = np.array([[0.0, 0.0, 1.0]])
    shading = k.Shading(sd.mat, sd.mat_tab, maps, sd.lights, np.zeros(3), np.zeros(3),
                        kernel_options(1, extent=sd.extent))
    k.render_pixels(sd.kernel_args(), shading, k.Pixels(O, D, np.array([0.0, 0.0, 1.0]), np.zeros(16),
                                                         np.zeros((1, 3), np.float32), np.zeros(1, np.float32)),
                    1, 0, tol.normal_cancel, np.zeros(RAY_COUNTS, np.int64))
    return time.perf_counter() - t0


def kernel_options(generations: int, *, threshold: float = 0.0, fresnel: int = 0,
                   transmissive_shadows: bool = False, blinn: bool = False, shadows: bool = False,
                   reflection: bool = False, refraction: bool = False, extent: float = 1.0,
                   background: bool = True, media=(), step_scale: float = 0.0) -> np.ndarray:
    """The Whitted kernels' options (columns :class:`..kernels.columns.WhittedOpt`): the
    tolerances from ``tol``, the media around the camera (material rows, innermost last, at
    most four), the factor of the heterogeneous media's march steps (0: the scene has none)."""
    media = list(media)[-4:]
    return pack(WhittedOpt, generations=generations, threshold=threshold, fresnel=fresnel,
                transmissive_shadows=transmissive_shadows, blinn=blinn, shadows=shadows,
                reflection=reflection, refraction=refraction, ray_offset=tol.ray_offset, t_min=tol.t_min,
                zero=tol.zero, extent=extent, background=background, n_media=len(media),
                media=media + [0] * (4 - len(media)), step_scale=step_scale)


def fused_textures(scene: Scene, sd: SceneData):
    """The path tracer's (M, TEX_COLS) colour texture table (:func:`..kernels.textures.checker_color`)
    when the scene's maps are at most planar or solid checkers (:func:`.maps.checkers_only`),
    else None (the path tracer then leaves the textures out)."""
    if not checkers_only(scene, sd.materials):
        return None
    return texture_tables(scene, sd).color


def _alloc(n, surface: bool = True):
    """Hit records of n rays (rows of missed rays are left unset); without ``surface``, the
    distance, primitive and geometric normal only (the other records have no rows:
    :func:`.kernels.trace_batch` then computes the geometric normal alone)."""
    m = n if surface else 0
    return dict(t=np.empty(n), prim=np.empty(n, np.int64), ng=np.empty((n, 3)),
                ns=np.empty((m, 3)), uv=np.empty((m, 2)), po=np.empty((m, 3)), ev=np.empty((m, 3)))


_COUNTS = tuple(c.name.lower() for c in RayCount)
"""The ``stats`` keys of the kernels' ray counts, in column order."""


class _Tracer:
    """State of one render: scene arrays, texture maps, options, counters."""

    def __init__(self, scene: Scene, sd: SceneData, opts: dict, recursive: bool, media: tuple):
        self.scene, self.sd = scene, sd
        self.do_shadow = bool(len(sd.lights)) and opts["shadows"]
        refl = recursive and any(m.kr > 0 for m in sd.materials)
        refr = recursive and any(m.kt > 0 for m in sd.materials)
        self.do_refl, self.do_refr = refl, refr
        fres = {"none": 0, "schlick": 1, "exact": 2}[opts["fresnel"]]
        self.G = generation_bound(scene, opts["max_depth"], opts.get("threshold", 0.0), recursive)
        names = [mt.name for mt in sd.materials]
        self.media = ([names.index(mt.name) for mt in media] + sd.media_holding(scene, scene.camera.position))[-4:]
        self.kopts = kernel_options(self.G, threshold=opts.get("threshold", 0.0), fresnel=fres,
                                    transmissive_shadows=opts["transmissive_shadows"], blinn=opts["blinn"],
                                    shadows=self.do_shadow, reflection=refl, refraction=refr,
                                    extent=sd.extent, background=True, media=self.media,
                                    step_scale=opts["step_scale"] if sd.has_media else 0.0)
        self.ambient = np.asarray(scene.ambient, dtype=np.float64)
        self.background = np.asarray(scene.background, dtype=np.float64)
        self.geo = sd.kernel_args()
        self.maps = texture_tables(scene, sd)
        self.stats = dict(primary_rays=0, shadow_rays=0, reflected_rays=0, refracted_rays=0,
                          ended_by_depth=0, ended_by_threshold=0, escaped_rays=0,
                          total_internal_reflections=0)

    def trace(self, O, D, n_pixels, spp, fwd, cam, first, out):
        """Trace a band's primary rays and their trees (one :func:`.kernels.render_pixels`
        call) into ``out = (image, depth)``, the band's (n_pixels, 3) and (n_pixels,) float32
        rows of the picture (no float64 band to allocate, fault in and copy: 3 to 4 ms of a 640
        x 480 trace phase, measured).  The band's pixels are ``first ... first + n_pixels - 1``
        of the image; the kernel makes their centre rays from ``cam`` (:func:`camera_frame`)
        when ``O`` is empty."""
        sd = self.sd
        image, depth_map = out
        counts = np.zeros(RAY_COUNTS, np.int64)
        k = _kernels()
        shading = k.Shading(sd.mat, sd.mat_tab, self.maps, sd.lights, self.ambient, self.background, self.kopts)
        k.render_pixels(self.geo, shading, k.Pixels(O, D, fwd, cam, image, depth_map), spp, first,
                        tol.normal_cancel, counts)
        self.stats["primary_rays"] += n_pixels * spp
        for key, v in zip(_COUNTS, counts):
            self.stats[key] += int(v)


_COUNTS = tuple(c.name.lower() for c in RayCount)
"""The ``stats`` keys of the kernels' ray counts, in column order."""


class _WhittedBase:
    recursive = True

    def render(self, scene: Scene, width: int, height: int, **o) -> RenderResult:
        if not 1 <= o["spp"] <= 4096:
            raise WorkbenchError(f"method {self.name!r}: option 'spp' must be within 1..4096, got {o['spp']}")
        if not 1.0 / 64 <= o["step_scale"] <= 64.0:
            raise WorkbenchError(f"method {self.name!r}: option 'step_scale' must be within 1/64..64, got {o['step_scale']}")
        timings = {}
        t0 = time.perf_counter()
        prepared = prepare(scene)
        sd = flatten(scene, o["accel"], prepared)
        timings["build"] = time.perf_counter() - t0
        timings["bvh_build"] = sd.bvh_build_time
        opts = dict(o)
        opts.setdefault("max_depth", 1)
        tr = _Tracer(scene, sd, opts, self.recursive, prepared.camera_media)
        timings["compile"] = ensure_compiled(sd, tr.maps)
        spp = opts["spp"]
        cam = scene.camera
        fwd = np.asarray(cam.look_at, float) - np.asarray(cam.position, float)
        fwd /= np.linalg.norm(fwd)
        bar = None
        if opts["progress"]:
            from tqdm import tqdm
            bar = tqdm(total=height, unit="row", desc=self.name)
        t1, c1 = time.perf_counter(), time.process_time()  # the trace phase includes the camera rays
        frame = camera_frame(cam, width, height)
        if spp == 1:  # the kernel makes the pixel-centre rays itself
            O = D = np.empty((0, 3))
        else:
            O, D, _ = camera_rays(cam, width, height, spp, opts["seed"])
        image = np.zeros((height * width, 3), np.float32)
        depth = np.full(height * width, np.inf, np.float32)
        quiet = opts["on_tile"] is None and bar is None
        rows = max(1, (_FUSED_RAYS_PER_BAND if quiet else _RAYS_PER_BAND) // (width * spp))
        bands = list(range(0, height, rows))
        for y0 in bands:
            y1 = min(height, y0 + rows)
            a, b = y0 * width * spp, y1 * width * spp
            tr.trace(O[a:b], D[a:b], (y1 - y0) * width, spp, fwd, frame, y0 * width,
                     (image[y0 * width:y1 * width], depth[y0 * width:y1 * width]))
            if opts["on_tile"] is not None:
                opts["on_tile"](y0, y1, 0, width, image[y0 * width:y1 * width].reshape(y1 - y0, width, 3))
            if bar is not None:
                bar.update(y1 - y0)
        if bar is not None:
            bar.close()
        timings["trace"] = time.perf_counter() - t1
        timings["trace_cpu"] = time.process_time() - c1  # CPU seconds, all threads
        st = tr.stats
        total = st["primary_rays"] + st["shadow_rays"] + st["reflected_rays"] + st["refracted_rays"]
        st["total_rays"] = total
        st["mrays_per_s"] = total / max(timings["trace"], 1e-9) / 1e6
        st["primitives"] = int(sd.top.sum())
        st["triangles"] = int(sum(len(ob.faces) for ob in scene.objects if isinstance(ob, Mesh)))
        st["accel"] = opts["accel"]
        st["triangle_references"] = int(len(sd.tri_v))
        if opts["traversal_stats"]:
            from .traversal_stats import primary_ray_counts
            t2 = time.perf_counter()
            st.update(primary_ray_counts(sd, *camera_rays(cam, width, height, 1, 0)[:2]))
            timings["traversal_stats"] = time.perf_counter() - t2
        st["scene_extent"] = sd.extent
        if o["march_error"] and sd.has_media and o["step_scale"] / 2 >= 1.0 / 64:
            # the march's step error, estimated by the same render at half the step
            t3 = time.perf_counter()
            half = self.render(scene, width, height, **{**o, "step_scale": o["step_scale"] / 2, "march_error": False,
                                                        "on_tile": None, "progress": False})
            diff = image.reshape(height, width, 3) - half.image
            st["march_error_rmse"] = float(np.sqrt(np.mean(diff.astype(np.float64) ** 2)))
            st["march_error_max"] = float(np.abs(diff).max())
            timings["march_error"] = time.perf_counter() - t3
        used, left = self._features(scene, tr)
        return RenderResult(self.name, image.reshape(height, width, 3), timings, st, used, left,
                            depth=depth.reshape(height, width))

    def estimate_bytes(self, scene: Scene, width: int, height: int, **o) -> int:
        """Upper bound of the render's peak bytes: primary rays (w h spp), image, mesh
        triangles and BVH, the kernel's ray stacks (:func:`.kernels.stack_rows` per task, G
        from :func:`generation_bound`) and the maps' images (:func:`texture_bytes`)."""
        if not 1 <= o["spp"] <= 4096:
            raise WorkbenchError(f"method {self.name!r}: option 'spp' must be within 1..4096, got {o['spp']}")
        return estimate_trace_bytes(scene, width, height, o, self.recursive)

    def _features(self, scene, tr):
        """(features used, ``left_out`` notes): the class's :attr:`support` table for the scene's
        needs, then the paths this render skipped (no lights, option off, no such material)."""
        needs = F.scene_needs(scene)
        left = sp.notes(self.support, needs)
        declared = {n.feature for n in left}

        def skipped(f, reason):
            if f not in declared:
                left.append(sp.Note(f, reason, sp.Status.LEFT_OUT if f in needs else sp.Status.NOT_NEEDED))
        if not tr.do_shadow:
            skipped(F.SHADOWS, "no lights (no shadow rays traced)" if not len(tr.sd.lights)
                    else "disabled by option (no shadow rays traced)")
        if not tr.do_refr:
            skipped(F.REFRACTION, "no transmissive material (no refraction rays traced)")
        if not tr.do_refl:
            skipped(F.REFLECTION, "no reflective material (no reflection rays traced)")
        if F.MESHES not in needs:
            left.append(sp.Note(F.MESHES, "no meshes (no BVH built or traversed)", sp.Status.NOT_NEEDED))
        return sp.used(needs, left), left


_APPROXIMATED = {
    F.AREA_LIGHTS: "stand-in point lights (the scene's area-light samples), hard shadows per sample",
    F.EMITTERS: "emission seen directly; emitting surfaces light others only through area-light stand-ins",
    F.HYPERTEXTURES: "emission-absorption march (step: the object's step times step_scale) with the ambient "
                     "light as the only in-scattered light; the medium shadows surfaces",
    F.TEXELS: "the texel shell marched with the Kajiya-Kay lobes and feelers against the surfaces "
              "(the fur does not shadow itself)",
}
"""What both Whitted methods stand in for (their ``support`` tables, :mod:`..support`)."""

_COMMON = {
    "spp": Option(int, 1, "samples per pixel (stratified jitter; 1 = pixel centres)"),
    "seed": Option(int, 0, "seed of the sample jitter"),
    "shadows": Option(bool, True, "trace shadow feelers"),
    "transmissive_shadows": Option(bool, False, "transmissive occluders attenuate shadow feelers by kt instead of blocking"),
    "blinn": Option(bool, False, "Blinn's half-vector specular instead of Phong's"),
    "fresnel": Option(str, "none", "reflection/transmission split: none (constant kr, kt), schlick or exact dielectric", ("none", "schlick", "exact")),
    "progress": Option(bool, False, "show a tqdm progress bar (CLI)"),
    "on_tile": Option(callback, None, "callback on_tile(y0, y1, x0, x1, tile) after each band of rows"),
    "accel": Option(str, "bvh", "acceleration structure over the triangles and the bounded analytic "
                    "primitives: bvh (4-wide binned SAH), octree (the course's arbre octal) or none (every "
                    "triangle and primitive tested); same images", ACCELS),
    "step_scale": Option(float, 1.0, "multiplies every hypertexture's march step (its 'step' key): the "
                         "knob of the emission-absorption march, 1/64..64", low=1.0 / 64),
    "march_error": Option(bool, False, "estimate the hypertextures' march error: render again at half the "
                          "step and report the difference (stats march_error_rmse, march_error_max; timed apart)"),
    "traversal_stats": Option(bool, False, "count nodes visited and primitives tested per pixel-centre "
                              "camera ray (stats accel_*; a pass of its own, timed apart)"),
}


class RaycastRenderer(_WhittedBase):
    """Eye rays and shadow feelers with the shared local model (no secondary rays)."""

    name = "raycast"
    ui_kind = "cpu"
    recursive = False
    support = sp.declare(approximated=_APPROXIMATED, left_out={
        F.REFLECTION: "raycast traces no secondary rays", F.REFRACTION: "raycast traces no secondary rays",
        F.ABSORPTION: "raycast traces no secondary rays (no path through a medium)"})
    knob = Knob("spp", (1, 2, 4, 8, 16), 1, "samples per pixel")
    options = dict(_COMMON)
    memory_options = ("spp",)


class RaytraceRenderer(_WhittedBase):
    """Whitted ray tracer: raycast plus recursive reflection and refraction."""

    name = "raytrace"
    ui_kind = "cpu"
    support = sp.declare(approximated=_APPROXIMATED)
    knob = Knob("max_depth", (1, 2, 3, 4, 5, 6, 8, 12), 5,
                "maximum number of ray generations in a path (primary = 1)")
    options = {**_COMMON,
               "max_depth": Option(int, 5, "maximum ray generations per path (primary = 1), >= 1"),
               "threshold": Option(float, 1e-3, "perceptual threshold: a child ray whose accumulated weight (max RGB) is at most this is not traced", low=0.0)}
    memory_options = ("max_depth", "threshold", "spp")

    def estimate_bytes(self, scene, width, height, **o):
        if o["max_depth"] < 1:
            raise WorkbenchError(f"method 'raytrace': option 'max_depth' must be >= 1, got {o['max_depth']}")
        return super().estimate_bytes(scene, width, height, **o)

    def render(self, scene, width, height, **o):
        if o["max_depth"] < 1:
            raise WorkbenchError(f"method 'raytrace': option 'max_depth' must be >= 1, got {o['max_depth']}")
        return super().render(scene, width, height, **o)
