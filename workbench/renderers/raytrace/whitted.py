"""The two registered ray-tracing methods: ``raycast`` (eye rays + shadow feelers, the course's
"lancer de rayons") and ``raytrace`` (plus recursive reflection and refraction, "suivi de rayons",
Whitted 1980).

Two organisations of the same algorithm, both over bands of rows ("tiles", delivered to
``on_tile`` as they finish):

* fused (:func:`.kernels.render_pixels`), when every surface colour is plain or a ``checker``
  (planar or solid) and nothing needs numpy (no image texture, bump, opacity map or
  environment): one numba kernel traces each pixel's whole ray tree depth first with an
  explicit stack (the course's ``raytrace``/``shade`` recursion), checkers evaluated in the
  kernel;
* wavefront, otherwise: each generation of rays is intersected by a numba kernel, coloured
  (textures through :mod:`workbench.renderers.texturing` in numpy, so that they match the
  raster methods exactly), shaded with shadow feelers by a second kernel, which also spawns
  the reflected and refracted children that form the next generation.

Both shade with :func:`.kernels.shade_hit`; a pixel's colour is the sum of ``weight x local
colour`` over the ray tree, and the two paths give the same images and ray counts (tested).

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
from ..kernels.columns import CHECKER_PLANAR, CHECKER_SOLID, RAY_COUNTS, TEX_COLS, Mat, RayCount, Tex, WhittedOpt
from .accel import ACCELS, accel_extra_bytes
from .flatten import MAX_CUTOUTS, OPACITY_CUT, SHADOW_CROSSINGS, SceneData, flatten, flatten_bytes

_RAYS_PER_BAND = 1 << 16
"""Primary rays of a band: the wavefront's per-generation arrays are a band's, and a UI's
``on_tile`` and the progress bar are called once a band."""
_FUSED_RAYS_PER_BAND = 1 << 20
"""Primary rays of a band of the fused path when nothing is called between bands (no
``on_tile``, no progress bar): it holds no per-ray arrays, only the band's colours and depths
(32 bytes a pixel), so its bands are larger, and each costs a start of the thread pool, a
scratch set per task and a wait for the slower thread at its end (measured: five bands of 65k
rays instead of one cost the 640 x 480 Whitted scene's trace 11 % more CPU time on one thread,
15 % on two)."""


_BYTES_PER_PRIMARY_RAY = 160
"""Origin, direction, jitter, pixel index and temporaries of one primary ray (all are built
up front by :func:`camera_rays`)."""
_BYTES_PER_WAVEFRONT_RAY = 1536
"""Arrays of one ray in a wavefront iteration: its state, hit record, shading outputs, two
child slots, compaction output and texturing temporaries (about 1 kB, measured)."""
_BYTES_PER_FEELER = 160
"""A shadow feeler of the wavefront's opacity visibility pass (per ray and light)."""
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


def _growth(scene: Scene, G: int, threshold: float, branches: int) -> float:
    """Upper bound of (rays of one wavefront iteration) / (primary rays of the band): each
    iteration at most multiplies the rays by ``branches``, and, where every material has
    kr + kt <= 1, the rays of generation g above ``threshold`` number at most
    k^(g-1) / threshold per primary ray (their weights sum to at most k^(g-1))."""
    if branches <= 1 or G <= 1:
        return 1.0
    g = np.arange(1, min(G, 4096) + 1, dtype=np.float64)
    by_branching = np.exp(np.minimum((g - 1) * np.log(branches), 700.0))
    k = max((m.kr + m.kt for m in scene.materials.values()), default=0.0)
    if k <= 1.0 and threshold > 0.0:
        by_weight = np.exp(np.minimum((g - 1) * np.log(max(k, 1e-300)) - np.log(threshold), 700.0))
        by_branching = np.minimum(by_branching, np.maximum(by_weight, 1.0))
    elif G > 4096:
        return float(np.exp(700.0))
    return float(by_branching.max())


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
    if fusable(scene, scene.materials.values()):  # MAX_TASKS stacks of 2 G + 2 pending rays
        return int(total + 64 * (2 * G + 2) * _BYTES_PER_STACK_ROW)
    # the wavefront: the largest iteration of a band (capped by _Tracer.ray_cap)
    cap = wavefront_cap(scene, width, height, spp, G, float(opts.get("threshold", 0.0)), recursive)
    total += _BYTES_PER_WAVEFRONT_RAY * cap
    if F.OPACITY in F.scene_needs(scene):
        total += _BYTES_PER_FEELER * len(scene.lights) * cap
    return int(total)


def wavefront_cap(scene: Scene, width: int, height: int, spp: int, G: int, threshold: float,
                  recursive: bool) -> int:
    """Most rays one wavefront iteration may hold: the band's primary rays times
    :func:`_growth` (reflection, refraction and, with opacity maps, the ray continuing
    through a partly transparent surface).  :class:`_Tracer` refuses to go beyond it."""
    n0 = min(height, max(1, _RAYS_PER_BAND // (width * spp))) * width * spp
    mats = scene.materials.values()
    branches = (int(recursive and any(m.kr > 0 for m in mats)) + int(recursive and any(m.kt > 0 for m in mats))
                + int(F.OPACITY in F.scene_needs(scene)))
    grow = _growth(scene, G, threshold, max(branches, 1))
    if F.OPACITY in F.scene_needs(scene):
        grow *= 2.0  # continuations are not threshold-tested: at most one per ray and iteration
    return int(min(n0 * grow, 2.0 ** 62))


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


class _Colorizer:
    """Surface colour ``C`` (material colour times texture), bumped normals and background
    radiance, through :mod:`workbench.renderers.texturing` when the scene needs it."""

    def __init__(self, scene: Scene, sd: SceneData):
        self.scene, self.sd = scene, sd
        self.base = sd.mat_tab[:, Mat.COLOR:Mat.COLOR + 3]
        needs = F.scene_needs(scene)
        self.tex = None
        self.missing: list[str] = []  # features wanted but not evaluated
        wanted = [f for f in (F.TEXTURES, F.BUMP, F.OPACITY, F.ENVIRONMENT) if f in needs]
        if wanted:
            try:
                from .. import texturing
                self.tex = texturing
            except ImportError:
                self.missing = wanted
        self.bg = np.asarray(scene.background, dtype=np.float64)

    def _groups(self, prim, attr):
        """(material, selection, uv or None, world_from_object) for hits whose material has
        ``attr`` (texture, bump, opacity), split by primitive (each has its own transform)."""
        sd = self.sd
        for k in np.flatnonzero(np.bincount(prim[prim >= 0], minlength=len(sd.mat))):
            m = sd.materials[sd.mat[k]]
            if getattr(m, attr) is None:
                continue
            yield m, prim == k, bool(sd.has_uv[k]), sd.wfo[k]

    def colors(self, prim, P_obj, Ns, uv):
        """(n, 3) colours ``C`` (set for textured materials only: shade_batch reads the others
        from the material table) and (n, 3) shading normals (bumped where a material asks)."""
        if self.tex is None:
            return self.base[self.sd.mat[np.maximum(prim, 0)]], Ns
        C = np.empty((len(prim), 3))
        for m, sel, has_uv, W in self._groups(prim, "texture"):
            n_obj = Ns[sel] @ W[:3, :3]
            C[sel] = self.tex.surface_color(m, P_obj[sel], n_obj, uv[sel] if has_uv else None)
        for m, sel, has_uv, W in self._groups(prim, "bump"):
            n_obj = Ns[sel] @ W[:3, :3]
            Ns[sel] = self.tex.bump_normal(m, P_obj[sel], n_obj, Ns[sel], W, uv[sel] if has_uv else None)
        return C, Ns

    def alpha(self, prim, P_obj, Ns, uv):
        """(n,) opacity of the hit surfaces (1 where no opacity map)."""
        a = np.ones(len(prim))
        if self.tex is None:
            return a
        for m, sel, has_uv, W in self._groups(prim, "opacity"):
            a[sel] = self.tex.alpha(m, P_obj[sel], Ns[sel] @ W[:3, :3], uv[sel] if has_uv else None)
        return a

    def background(self, D):
        if self.scene.environment is not None and self.tex is not None:
            return np.asarray(self.tex.environment(self.scene.environment, D), dtype=np.float64)
        return np.broadcast_to(self.bg, D.shape)


def _kernels():
    from . import kernels
    return kernels


def _feelers():
    from . import feelers
    return feelers


def ensure_compiled(sd: SceneData, fused: bool = False) -> float:
    """Run the kernels a render needs once on one ray (first-call JIT, or a load from the numba
    disk cache): :func:`.kernels.render_pixels` for the fused path, the wavefront kernels
    otherwise.  Returns the seconds spent (a fraction of a millisecond once compiled for this
    scene's kinds in this process: the kernels are specialised to them, see
    :mod:`..kernels.specialise`)."""
    k = _kernels()
    t0 = time.perf_counter()
    O = np.zeros((1, 3))
    D = np.array([[0.0, 0.0, 1.0]])
    geo = sd.kernel_args()
    kopts = kernel_options(1, extent=sd.extent)
    if fused:
        shading = k.Shading(sd.mat, sd.mat_tab, np.zeros((len(sd.mat_tab), TEX_COLS)), sd.lights,
                            np.zeros(3), np.zeros(3), kopts)
        k.render_pixels(geo, shading, k.Pixels(O, D, np.array([0.0, 0.0, 1.0]), np.zeros(16), np.zeros((1, 3)),
                                               np.zeros(1)), 1, 0, tol.normal_cancel, np.zeros(RAY_COUNTS, np.int64))
        return time.perf_counter() - t0
    arr = _alloc(1)
    k.trace_batch(geo, O, D, np.zeros(1), np.full(1, np.inf), tol.zero, tol.ray_offset, 1.0,
                  tol.normal_cancel, False, arr["t"], arr["prim"], arr["ng"], arr["ns"], arr["uv"],
                  arr["po"], arr["ev"])
    ch = _alloc_children(1)
    nl = len(sd.lights)
    _feelers().feeler_batch(sd.lights, O, D, np.ones(1), np.zeros(1, np.int64), D.copy(), D.copy(), kopts,
                            np.empty((nl, 3)), np.empty((nl, 3)), np.empty(nl), np.empty(nl), np.empty(nl, np.bool_))
    k.shade_batch(geo, sd.mat, sd.mat_tab, sd.lights, np.zeros(3), np.zeros(3), O, D, np.ones(1),
                  np.zeros(1, np.int64), D.copy(), D.copy(), np.ones((1, 3)), np.zeros((1, 3)),
                  np.empty((0, nl)), np.ones((1, 3)), np.zeros(1, np.int64), np.zeros((1, 4), np.int64),
                  np.zeros(1, np.int64), np.zeros(1, np.int64), kopts, np.zeros((1, 3)),
                  ch["o"], ch["d"], ch["w"], ch["stk"], ch["nstk"], ch["kind"], ch["tmin"], ch["pix"],
                  ch["gen"], np.zeros((1, RAY_COUNTS), np.int64))
    k.accumulate(np.zeros((1, 3)), np.zeros(1, np.int64), np.zeros((1, 3)))
    k.compact(ch["kind"], ch["o"], ch["d"], ch["w"], ch["stk"], ch["nstk"], ch["tmin"], ch["pix"],
              ch["gen"])
    k.column_sums(np.zeros((1, RAY_COUNTS), np.int64))
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


def fusable(scene: Scene, materials) -> bool:
    """Whether the fused kernel can shade ``materials``: no environment, bump or opacity map,
    and surface colours plain or ``checker`` with the ``planar`` or ``solid`` projection."""
    return scene.environment is None and all(
        m.bump is None and m.opacity is None
        and (m.texture is None or (m.texture.kind == "checker" and m.texture.projection in ("planar", "solid")))
        for m in materials)


def fused_textures(scene: Scene, sd: SceneData):
    """The (M, TEX_COLS) texture table of :func:`.kernels.render_pixels` when every material's
    surface colour is one the fused kernel evaluates itself (plain, or a ``checker`` with the
    ``planar`` or ``solid`` projection) and nothing else needs numpy (bump, opacity, an
    environment); else None (the wavefront path)."""
    if not fusable(scene, sd.materials):
        return None
    tab = np.zeros((len(sd.materials), TEX_COLS))
    for i, m in enumerate(sd.materials):
        tx = m.texture
        if tx is None:
            continue
        from ..texturing import frame
        _, se, w = frame(tx.pole, tx.equator)
        tab[i] = pack(Tex, kind=CHECKER_PLANAR if tx.projection == "planar" else CHECKER_SOLID,
                      scale=tx.scale, center=tx.center, se=se, w=w, color0=tx.colors[0], color1=tx.colors[1])
    return tab


def _alloc(n, surface: bool = True):
    """Hit records of n rays (rows of missed rays are left unset); without ``surface``, the
    distance, primitive and geometric normal only (the other records have no rows:
    :func:`.kernels.trace_batch` then computes the geometric normal alone)."""
    m = n if surface else 0
    return dict(t=np.empty(n), prim=np.empty(n, np.int64), ng=np.empty((n, 3)),
                ns=np.empty((m, 3)), uv=np.empty((m, 2)), po=np.empty((m, 3)), ev=np.empty((m, 3)))


def _alloc_children(n):
    """Child ray slots (2 per parent: reflection, refraction), written by shade_batch."""
    return dict(o=np.empty((2 * n, 3)), d=np.empty((2 * n, 3)), w=np.empty((2 * n, 3)),
                stk=np.empty((2 * n, 4), np.int64), nstk=np.empty(2 * n, np.int64),
                kind=np.empty(2 * n, np.int64), tmin=np.empty(2 * n), pix=np.empty(2 * n, np.int64),
                gen=np.empty(2 * n, np.int64))


# the columns of shade_batch's counts
_COUNTS = tuple(c.name.lower() for c in RayCount)
"""The ``stats`` keys of the kernels' ray counts, in column order."""


class _Tracer:
    """State of one render: scene arrays, options, counters."""

    def __init__(self, scene: Scene, sd: SceneData, opts: dict, recursive: bool, media: tuple):
        self.scene, self.sd = scene, sd
        self.col = _Colorizer(scene, sd)
        needs = F.scene_needs(scene)
        self.do_shadow = bool(len(sd.lights)) and opts["shadows"]
        refl = recursive and any(m.kr > 0 for m in sd.materials)
        refr = recursive and any(m.kt > 0 for m in sd.materials)
        self.do_refl, self.do_refr = refl, refr
        fres = {"none": 0, "schlick": 1, "exact": 2}[opts["fresnel"]]
        self.env = scene.environment is not None and self.col.tex is not None
        self.G = generation_bound(scene, opts["max_depth"], opts.get("threshold", 0.0), recursive)
        self.ray_cap = wavefront_cap(scene, scene.camera.width, scene.camera.height, opts["spp"], self.G,
                                     opts.get("threshold", 0.0), recursive)
        names = [mt.name for mt in sd.materials]
        self.media = ([names.index(mt.name) for mt in media] + sd.media_holding(scene, scene.camera.position))[-4:]
        self.kopts = kernel_options(self.G, threshold=opts.get("threshold", 0.0), fresnel=fres,
                                    transmissive_shadows=opts["transmissive_shadows"], blinn=opts["blinn"],
                                    shadows=self.do_shadow, reflection=refl, refraction=refr,
                                    extent=sd.extent, background=not self.env, media=self.media,
                                    step_scale=opts["step_scale"] if sd.has_media else 0.0)
        self.ambient = np.asarray(scene.ambient, dtype=np.float64)
        self.geo = sd.kernel_args()
        self.stats = dict(primary_rays=0, shadow_rays=0, reflected_rays=0, refracted_rays=0,
                          ended_by_depth=0, ended_by_threshold=0, escaped_rays=0,
                          total_internal_reflections=0)
        self.has_opacity = F.OPACITY in needs and self.col.tex is not None
        self.tex_tab = None if self.col.missing else fused_textures(scene, sd)
        self.fused = self.tex_tab is not None

    def trace(self, O, D, pix, n_pixels, spp, fwd, cam, first):
        """Trace a band's primary rays and their trees; returns (image (n_pixels, 3), depth).
        The band's pixels are ``first ... first + n_pixels - 1`` of the image; the fused path
        makes their centre rays from ``cam`` (:func:`camera_frame`) when ``O`` is empty."""
        if self.fused:
            return self._trace_fused(O, D, n_pixels, spp, fwd, cam, first)
        return self._trace_wavefront(O, D, pix, n_pixels, spp, fwd)

    def _trace_fused(self, O, D, n_pixels, spp, fwd, cam, first):
        """One :func:`.kernels.render_pixels` call: whole ray trees, pixel by pixel."""
        sd = self.sd
        image = np.empty((n_pixels, 3))
        depth_map = np.empty(n_pixels)
        counts = np.zeros(RAY_COUNTS, np.int64)
        k = _kernels()
        shading = k.Shading(sd.mat, sd.mat_tab, self.tex_tab, sd.lights, self.ambient, self.col.bg, self.kopts)
        k.render_pixels(self.geo, shading, k.Pixels(O, D, fwd, cam, image, depth_map), spp, first,
                        tol.normal_cancel, counts)
        self.stats["primary_rays"] += n_pixels * spp
        for key, v in zip(_COUNTS, counts):
            self.stats[key] += int(v)
        return image, depth_map

    def _trace_wavefront(self, O, D, pix, n_pixels, spp, fwd):
        """Generation by generation: intersect all rays, colour the hits in numpy, shade."""
        k = _kernels()
        sd = self.sd
        acc = np.zeros((n_pixels, 3))
        depth_map = np.full(n_pixels, np.inf)
        n = len(O)
        self.stats["primary_rays"] += n
        w = np.ones((n, 3))
        gen = np.zeros(n, np.int64)
        stk = np.zeros((n, 4), np.int64)
        stk[:, :len(self.media)] = self.media
        nstk = np.full(n, len(self.media), np.int64)
        tmin = np.zeros(n)
        first = True
        while n > 0:
            h = self._hits(O, D, tmin)
            prim = h["prim"]
            if first:
                sel = np.flatnonzero((prim >= 0) & (np.arange(n) % spp == 0))
                depth_map[pix[sel]] = h["t"][sel] * (D[sel] @ fwd)
                first = False
            if self.env:
                miss = np.flatnonzero(prim < 0)
                _accumulate(acc, pix[miss], w[miss] * self.col.background(D[miss]))
            C, ns = self.col.colors(prim, h["po"], h["ns"], h["uv"])
            cont = None
            if self.has_opacity:  # alpha blends the surface with the ray's straight continuation
                alpha = h["alpha"]
                part = np.flatnonzero((prim >= 0) & (alpha < 1.0))
                cont = (O[part], D[part], w[part] * (1.0 - alpha[part, None]), stk[part], nstk[part],
                        self._past(O[part], D[part], h["t"][part]), pix[part], gen[part])
                w = w * alpha[:, None]
            contrib = np.empty((n, 3))
            ch = _alloc_children(n)
            counts = np.empty((n, RAY_COUNTS), np.int64)
            vis = (self._visibility(O, D, h, ns) if self.has_opacity and self.do_shadow
                   else np.empty((0, len(sd.lights))))
            k.shade_batch(self.geo, sd.mat, sd.mat_tab, sd.lights, self.ambient, self.col.bg, O, D,
                          h["t"], prim, h["ng"], ns, C, h["ev"], vis, w, gen, stk, nstk, pix, self.kopts,
                          contrib, ch["o"], ch["d"], ch["w"], ch["stk"], ch["nstk"], ch["kind"],
                          ch["tmin"], ch["pix"], ch["gen"], counts)
            _accumulate(acc, pix, contrib)
            for key, v in zip(_COUNTS, k.column_sums(counts)):
                self.stats[key] += int(v)
            O, D, w, stk, nstk, tmin, pix, gen = k.compact(*(ch[x] for x in (
                "kind", "o", "d", "w", "stk", "nstk", "tmin", "pix", "gen")))
            if cont is not None and len(cont[0]):
                O, D, w, stk, nstk, tmin, pix, gen = (np.concatenate([x, y]) for x, y in
                                                      zip((O, D, w, stk, nstk, tmin, pix, gen), cont))
            n = len(O)
            if n > self.ray_cap:  # the bound estimate_bytes counted on
                raise WorkbenchError(f"raytrace: a ray generation grew beyond {self.ray_cap} rays (the "
                                     "memory estimate's bound): lower max_depth or raise threshold")
        return acc / spp, depth_map

    def _visibility(self, O, D, h, ns):
        """(n, L) visibility of each light from each hit through its shadow feeler
        (:func:`.feelers.feeler_batch`: the feelers :func:`.kernels.shade_hit` would trace),
        with opacity maps: a surface lets ``1 - alpha`` through (all of it where cut out, as
        for the rays it cuts), and with ``transmissive_shadows`` also ``alpha kt`` (as
        :func:`.reference.shadow_feeler`)."""
        sd = self.sd
        n, nl = len(O), len(sd.lights)
        fo, fd = np.empty((n * nl, 3)), np.empty((n * nl, 3))
        tmin, tmax, want = np.empty(n * nl), np.empty(n * nl), np.empty(n * nl, np.bool_)
        _feelers().feeler_batch(sd.lights, O, D, h["t"], h["prim"], h["ng"], ns, self.kopts, fo, fd, tmin, tmax,
                                want)
        vis = np.ones(n * nl)
        kt = sd.mat_tab[sd.mat, Mat.KT] if self.kopts[WhittedOpt.TRANSMISSIVE_SHADOWS] > 0.5 else np.zeros(len(sd.mat))
        todo = np.flatnonzero(want)
        for _ in range(SHADOW_CROSSINGS):
            if not len(todo):
                break
            s = self._trace(fo[todo], fd[todo], tmin[todo], tmax[todo], shadow_only=True)
            hit = s["prim"] >= 0
            todo, prim = todo[hit], s["prim"][hit]
            a = self.col.alpha(prim, s["po"][hit], s["ns"][hit], s["uv"][hit])
            a[a < OPACITY_CUT] = 0.0
            vis[todo] *= 1.0 - a + a * kt[prim]
            go = vis[todo] > 0.0
            todo = todo[go]
            tmin[todo] = self._past(fo[todo], fd[todo], s["t"][hit][go])
        return vis.reshape(n, nl)

    def _past(self, O, D, t):
        """``tmin`` that restarts rays just beyond their hit at ``t`` (offset scaled with the
        hit point, :func:`workbench.core.tol.offset_scale`)."""
        P = O + t[:, None] * D
        return t + tol.ray_offset * np.maximum(np.abs(P).max(1), self.sd.extent)

    def _trace(self, O, D, tmin, tmax, shadow_only=False):
        """Closest hits of rays and their surface data (:func:`.kernels.trace_batch`)."""
        h = _alloc(len(O))
        _kernels().trace_batch(self.geo, O, D, tmin, tmax, tol.zero, tol.ray_offset, self.sd.extent,
                               tol.normal_cancel, shadow_only, h["t"], h["prim"], h["ng"], h["ns"],
                               h["uv"], h["po"], h["ev"])
        return h

    def _hits(self, O, D, tmin):
        """Closest hits; surfaces cut out by an opacity map (alpha < 0.5) are passed through."""
        n = len(O)
        h = self._trace(O, D, tmin, np.full(n, np.inf))
        h["alpha"] = np.ones(n)
        if not self.has_opacity:
            return h
        todo = np.arange(n)
        for _ in range(MAX_CUTOUTS):
            sel = todo[h["prim"][todo] >= 0]
            a = self.col.alpha(h["prim"][sel], h["po"][sel], h["ns"][sel], h["uv"][sel])
            h["alpha"][sel] = a
            todo = sel[a < OPACITY_CUT]
            if not len(todo):
                break
            sub = self._trace(O[todo], D[todo], self._past(O[todo], D[todo], h["t"][todo]),
                              np.full(len(todo), np.inf))
            for key, v in sub.items():
                h[key][todo] = v
        h["alpha"][h["alpha"] < OPACITY_CUT] = 0.0
        return h


def _accumulate(acc, pix, values):
    _kernels().accumulate(acc, pix, np.ascontiguousarray(values))


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
        timings["compile"] = ensure_compiled(sd, tr.fused)
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
        if tr.fused and spp == 1:  # the kernel makes the pixel-centre rays itself
            O = D = np.empty((0, 3))
            pix = np.empty(0, np.int64)
        else:
            O, D, pix = camera_rays(cam, width, height, spp, opts["seed"])
        image = np.zeros((height * width, 3), np.float32)
        depth = np.full(height * width, np.inf, np.float32)
        quiet = tr.fused and opts["on_tile"] is None and bar is None
        rows = max(1, (_FUSED_RAYS_PER_BAND if quiet else _RAYS_PER_BAND) // (width * spp))
        bands = list(range(0, height, rows))
        for y0 in bands:
            y1 = min(height, y0 + rows)
            a, b = y0 * width * spp, y1 * width * spp
            img, dep = tr.trace(O[a:b], D[a:b], pix[a:b] - y0 * width, (y1 - y0) * width, spp, fwd,
                                frame, y0 * width)
            image[y0 * width:y1 * width] = img
            depth[y0 * width:y1 * width] = dep
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
        triangles and BVH, the fused kernel's ray stacks (2 G + 2 rows per task, G from
        :func:`generation_bound`) and the wavefront's largest iteration
        (:func:`wavefront_cap`, enforced while tracing)."""
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
        left += [sp.Note(f, "texturing module not available (untextured colour used)") for f in tr.col.missing]
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
