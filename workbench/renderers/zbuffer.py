"""The course's Z-buffer on the CPU (Catmull 1974; course, "Élimination des parties cachées"):
the readable twin of the GLSL flat / Gouraud / Phong methods.

Pipeline, one step per course slide:

1. Tessellate the scene (the raster methods' triangles, :func:`~workbench.scene.tessellate.
   tessellate_scene`, area lights as emissive polygons); vertex normals by the ``normals``
   rule (``face_mean``: the course's "moyenne des normales aux faces incidentes").
2. Light where the shading mode says (the local model of :mod:`.local_model`, as the GL path):
   ``flat`` (Lambert: one lighting per polygon, at its centroid with its normal), ``gouraud``
   (at the vertices), ``phong`` (per pixel, from the interpolated normal).  The terms are split
   ``I = E + C diffuse + specular`` so that the texture colour ``C`` still varies per pixel.
3. Project the triangles (the GL path's clip matrix and automatic near / far planes), clip them
   against the near plane (Sutherland-Hodgman in clip space), map them to window coordinates.
4. Scan-convert every polygon into a p-bit integer depth buffer initialised to ``2^p - 1``,
   interpolating depth and attributes linearly in screen space along edges and spans (the
   course's formulas, :mod:`.zbuffer_scan`).
5. Shade the pixels each polygon won (``couleurObjet(O, x, y)``): ``E + C diffuse +
   specular`` (+ ``kr`` times the environment in the reflected direction for environment-
   mapped materials), the background (or the environment) where nothing was drawn.
6. March the hypertextures over that image, back to front, each ray's segment ending at the
   depth buffer's surface (:mod:`.zbuffer_volume`, the GL volume pass's twin:
   :mod:`.raster_volume`); then composite the furs' layered shells (:mod:`.zbuffer_fur`, twin of
   :mod:`.raster_fur`; after all the media, where GL interleaves them by distance).

Step 5 runs once per pixel after the scan, on the attributes the winning polygon wrote:
the same image as shading each fragment when it passes the test, for opaque surfaces.

Differences from the GL images drawn with ``interpolation=screen`` (measured by
``tests/renderers/raster/test_zbuffer.py`` and ``bench/zbuffer.py``: at most 0.01 % of the pixels): pixels
whose centre lies on or within float32 rounding of an edge (GL's rasterisation rules and
coverage), depth ties between surfaces that meet or coincide (float32 z and the driver's
fixed-point conversion against float64 here), texture pattern boundaries (float32).
"""
from __future__ import annotations

import time
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..core.errors import WorkbenchError
from ..core.tol import tol
from ..core.transform import normalize
from ..scene import features as ft
from ..scene.model import Camera, Material, Scene
from ..scene.parts import Part
from ..scene.prepared import prepare
from ..scene.tessellate import (DEFAULT_LEVEL, MAX_LEVEL, NORMAL_RULES, area_light_parts, tessellate_scene,
                                with_normal_rule)
from . import raster_fur as rf
from . import raster_volume as rv
from . import support as sp
from . import texturing as tx
from . import zbuffer_fur as zf
from . import zbuffer_volume as zv
from .base import Knob, Option, RenderResult
from .estimates import raster_bytes
from .local_model import shade
from .zbuffer_scan import Frame, Polygons, new_frame, scan_polygons

MODES = ("flat", "gouraud", "phong")
#: Columns of the per-vertex attributes: world point, shading normal, object-space point, uv,
#: diffuse and specular terms (flat, Gouraud; zero for Phong, lit per pixel).
WORLD, NORMAL, OBJ, UV, DIFFUSE, SPECULAR = (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 11),
                                            slice(11, 14), slice(14, 17))
N_ATTRS = 17
MAX_DEPTH_BITS = 32
"""Largest p: Z and 2^p - 1 are held in int64, and z (2^p - 1) stays exact in float64."""
SUPPORT = sp.declare(
    approximated={**{f: "drawn as its tessellation (the tessellation knob)"
                     for f in (ft.SPHERES, ft.QUADRICS, ft.CSG, ft.BLOBS, ft.ISOSURFACES, ft.LATHES)},
                  ft.AREA_LIGHTS: "stand-in point lights (the scene's area-light samples)",
                  ft.EMITTERS: "emission drawn on the surface; it lights others only through area-light stand-ins",
                  ft.HYPERTEXTURES: rv.REASON, ft.TEXELS: rf.REASON},
    left_out={
        ft.BUMP: "the Z-buffer twin interpolates the course's normals only (no perturbation)",
        ft.OPACITY: "the Z-buffer keeps the nearest surface only (drawn opaque, no cut-outs)",
        ft.SHADOWS: "no shadow feelers in a raster local model",
        ft.REFLECTION: "mirror reflection needs ray tracing (environment-mapped materials reflect the environment)",
        ft.REFRACTION: "needs ray tracing (transmissive surfaces drawn with their local model)",
        ft.ABSORPTION: "needs ray tracing",
    })
"""The Z-buffer's support table (:mod:`.support`)."""
#: Optional features the method evaluates only when the scene has them.
BUILT = (ft.TEXTURES, ft.SOLID_TEXTURES, ft.IMAGE_TEXTURES, ft.ENVIRONMENT)

_BYTES_PER_TRIANGLE = 2048
"""The tessellated part (about 280 B per triangle measured for the GL path), three unshared
vertices of 17 attributes + window and clip coordinates (about 650 B) and their temporaries."""
_BYTES_PER_PIXEL = 900
"""Depth (8 B), id (4 B) and 17 float64 attributes (136 B) per pixel, the shading's (N, 3)
float64 temporaries (about 10 of them) and the float32 image and depth."""
_FIXED_BYTES = 32 * 2 ** 20
"""numba's compiled kernels and the interpreter's share."""


def _vertex_terms(P: np.ndarray, N: np.ndarray, mat: Material, scene: Scene, eye: np.ndarray,
                  blinn: bool) -> tuple[np.ndarray, np.ndarray]:
    """``diffuse = ka Ia + sum_l I_l kd max(N.L_l, 0)`` and ``specular = sum_l I_l ks spec_l``
    at points P (N, 3) with normals N (N, 3) turned towards the eye (the split of
    :func:`.local_model.shade` that lets ``C`` vary per pixel).  Returns two (N, 3) arrays."""
    S = normalize(eye - P)
    lights, amb = scene.point_lights(), scene.ambient
    dark = (0.0, 0.0, 0.0)
    diffuse = shade(P, N, S, np.ones(3), replace(mat, ks=0.0, emission=dark), lights, amb, blinn=blinn)
    specular = shade(P, N, S, np.zeros(3), replace(mat, ka=0.0, kd=0.0, emission=dark), lights, amb,
                     blinn=blinn)
    return diffuse, specular


def corner_attributes(part: Part, mat: Material, mode: str, scene: Scene, eye: np.ndarray,
                      blinn: bool) -> np.ndarray:
    """The attributes of each triangle corner (vertices unshared: flat shading gives each
    triangle its polygon's values).  Returns (F, 3, N_ATTRS) float64 (columns :data:`WORLD`...)."""
    F = part.faces
    V = np.zeros((len(part.positions), N_ATTRS))
    V[:, WORLD], V[:, NORMAL], V[:, OBJ] = part.positions, part.normals, part.obj_positions
    if part.uvs is not None:
        V[:, UV] = part.uvs
    if mode == "gouraud":
        V[:, DIFFUSE], V[:, SPECULAR] = _vertex_terms(part.positions, part.normals, mat, scene, eye, blinn)
    out = V[F]
    if mode == "flat":  # Lambert: one lighting per polygon, at its centroid, with its normal
        d, s = _vertex_terms(part.face_centroids, part.face_normals, mat, scene, eye, blinn)
        out[:, :, NORMAL] = part.face_normals[:, None]
        out[:, :, DIFFUSE], out[:, :, SPECULAR] = d[:, None], s[:, None]
    return out


def clip_near(clip: np.ndarray, attrs: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray], np.ndarray]:
    """Clip triangles against the near plane ``z_c >= -w_c`` (Sutherland-Hodgman in clip
    space).  A new vertex at clip-space parameter ``t`` along edge [a, b] gets the attributes
    at the screen-space parameter ``s = t w_b / ((1 - t) w_a + t w_b)`` (the point of the
    projected edge it projects to), so that they stay linear in screen space over the whole
    triangle, as the course's scanline formulas define them; when a corner is behind the eye
    (``w <= 0``: no screen position) there is no such interpolation, and ``t`` is used.

    Parameters
    ----------
    clip : (T, 3, 4) clip coordinates of each triangle's corners; attrs : (T, 3, K).

    Returns
    -------
    clip_polys, attr_polys : lists of (n_i, 4) and (n_i, K) arrays, the convex polygons
        (3 or 4 vertices) of the triangles that cross the plane.
    keep : (T,) bool, the triangles entirely in front of it (kept as they are).
    """
    d = clip[:, :, 2] + clip[:, :, 3]                     # signed: >= 0 in front of the near plane
    inside = d >= 0.0
    keep = inside.all(1)
    clip_polys, attr_polys = [], []
    for t in np.flatnonzero(inside.any(1) & ~keep):
        cp, ap = [], []
        for c in range(3):
            n = (c + 1) % 3
            if inside[t, c]:
                cp.append(clip[t, c])
                ap.append(attrs[t, c])
            if inside[t, c] != inside[t, n]:
                s = d[t, c] / (d[t, c] - d[t, n])
                cp.append(clip[t, c] + s * (clip[t, n] - clip[t, c]))
                wa, wb = clip[t, c, 3], clip[t, n, 3]
                if wa > 0.0 and wb > 0.0:
                    s = s * wb / ((1.0 - s) * wa + s * wb)
                ap.append(attrs[t, c] + s * (attrs[t, n] - attrs[t, c]))
        clip_polys.append(np.array(cp))
        attr_polys.append(np.array(ap))
    return clip_polys, attr_polys, keep


def to_window(clip: np.ndarray, width: int, height: int) -> np.ndarray:
    """Clip coordinates (M, 4) (w > 0) to window coordinates (M, 3): x column and y row from
    the top-left corner in pixels (as :meth:`Camera.project`), z = (z_ndc + 1) / 2 (GL's
    default depth range)."""
    ndc = clip[:, :3] / clip[:, 3:4]
    return np.stack([(ndc[:, 0] + 1.0) * 0.5 * width, (1.0 - ndc[:, 1]) * 0.5 * height,
                     (ndc[:, 2] + 1.0) * 0.5], -1)


def _polygons(P: np.ndarray, A: np.ndarray, clip_from_world: np.ndarray, width: int, height: int):
    """Triangles ``P`` (T, 3, 3) world corners with attributes ``A`` (T, 3, K) as window-space
    polygons (:class:`~.zbuffer_scan.Polygons`), the id of each polygon being its triangle's
    index.  Returns ``(polys, clipped)``, ``clipped`` (T,) bool: the triangles the near plane
    cuts."""
    clip = np.concatenate([P, np.ones(P.shape[:2] + (1,))], -1) @ clip_from_world.T
    cp, ap, keep = clip_near(clip, A)
    tri = np.flatnonzero(keep)
    xyz = [to_window(clip[keep].reshape(-1, 4), width, height)] + [to_window(c, width, height) for c in cp]
    attrs = [A[keep].reshape(-1, A.shape[-1])] + ap
    count = np.concatenate([np.full(len(tri), 3), [len(c) for c in cp]]).astype(np.int64)
    crossing = np.flatnonzero((clip[:, :, 2] + clip[:, :, 3] >= 0.0).any(1) & ~keep)
    ident = np.concatenate([tri, crossing]).astype(np.int32)
    xyz, attrs = np.concatenate(xyz), np.concatenate(attrs)
    start = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int64)
    finite = np.add.reduceat(~np.isfinite(xyz).all(1), start) == 0 if len(start) else np.zeros(0, bool)
    polys = Polygons(xyz, attrs, start[finite], count[finite], ident[finite])
    clipped = np.zeros(len(clip), dtype=bool)
    clipped[crossing] = True
    return polys, clipped


class Raster(NamedTuple):
    """What :func:`rasterise` leaves for shading: the (part, material) pairs, the filled
    :class:`~.zbuffer_scan.Frame`, the clip planes, and per triangle (over all parts, the ids
    in ``frame.ident``) whether the near plane cuts it."""

    pairs: list
    frame: Frame
    near: float
    far: float
    clipped: np.ndarray


def rasterise(scene: Scene, camera: Camera, *, tessellation: int, normals: str, shading: str, blinn: bool,
              depth_bits: int, near: float, far: float, timings: dict) -> Raster:
    """Steps 1 to 4 of the module docstring (tessellate, light per vertex or polygon, project and
    clip, scan-convert); phases timed into ``timings``."""
    t0 = time.perf_counter()
    pairs = [(with_normal_rule(p, normals), scene.materials[p.material])
             for p in tessellate_scene(scene, tessellation)]
    prepared = prepare(scene.with_camera(camera))
    pairs += area_light_parts(prepared.area_lights)
    timings["tessellate"] = time.perf_counter() - t0
    near, far = near or prepared.near, far or prepared.far
    if not 0.0 < near < far:
        raise WorkbenchError(f"clip planes need 0 < near < far, got near {near:.6g} and far {far:.6g}")
    eye = np.asarray(camera.position, dtype=np.float64)
    clip_from_world = camera.clip_from_camera(near, far) @ camera.camera_from_world()
    t0 = time.perf_counter()
    frame = new_frame(camera.width, camera.height, N_ATTRS, depth_bits)
    parts = [p for p, _ in pairs]
    polys, clipped = None, np.zeros(0, dtype=bool)
    if sum(p.n_triangles for p in parts):
        corner = [corner_attributes(p, m, shading, scene, eye, blinn) for p, m in pairs]
        polys, clipped = _polygons(np.concatenate([p.positions[p.faces] for p in parts]), np.concatenate(corner),
                                   clip_from_world, camera.width, camera.height)
    timings["vertices"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    compiled = bool(scan_polygons.signatures)
    if polys is not None and len(polys.start):
        scan_polygons(polys, frame)
    timings["scan"] = time.perf_counter() - t0
    timings["compile"] = 0.0 if compiled or polys is None else timings["scan"]
    return Raster(pairs, frame, near, far, clipped)


def near_clipped_pixels(raster: Raster) -> np.ndarray:
    """(H, W) bool: pixels whose visible triangle the near plane cuts (where the new corners'
    values decide the image: :func:`clip_near`; GLSL ``noperspective`` varyings got NaN there
    on llvmpipe, hence ``shaders/include/screen_space.glsl``)."""
    ident = raster.frame.ident
    if not len(raster.clipped):
        return np.zeros(ident.shape, dtype=bool)
    return (ident >= 0) & raster.clipped[np.maximum(ident, 0)]


def near_clipped_mask(scene: Scene, width: int, height: int, tessellation: int = DEFAULT_LEVEL,
                      normals: str = "smooth") -> np.ndarray:
    """:func:`near_clipped_pixels` of ``scene`` seen by its camera at ``width x height`` (what
    the tests and ``bench/zbuffer.py`` set apart when comparing with GL)."""
    raster = rasterise(scene, scene.camera.with_resolution(width, height), tessellation=tessellation,
                       normals=normals, shading="flat", blinn=False, depth_bits=24, near=0.0, far=0.0,
                       timings={})
    return near_clipped_pixels(raster)


def _shade_pixels(A: np.ndarray, Ng: np.ndarray, mat: Material, mode: str, scene: Scene,
                  eye: np.ndarray, blinn: bool, has_uv: bool, needs) -> np.ndarray:
    """``couleurObjet(O, x, y)`` at the pixels one part won: attributes A (N, K) and the
    geometric normals Ng (N, 3) of their triangles.  Returns (N, 3) linear RGB."""
    P = A[:, WORLD]
    S = normalize(eye - P)
    N = np.where((np.linalg.norm(A[:, NORMAL], axis=-1) < tol.normal_cancel)[:, None], Ng, A[:, NORMAL])
    N = normalize(N)
    N = np.where((np.sum(N * S, -1) < 0.0)[:, None], -N, N)  # faces the viewer (two-sided)
    uv = A[:, UV] if has_uv else None
    C = tx.surface_color(mat, A[:, OBJ], N, uv) if ft.TEXTURES in needs else np.asarray(mat.color, float)
    if mode == "phong":
        color = shade(P, N, S, C, mat, scene.point_lights(), scene.ambient, blinn=blinn)
    else:
        color = np.asarray(mat.emission, float) + C * A[:, DIFFUSE] + A[:, SPECULAR]
    if mat.environment and mat.kr > 0.0:
        R = 2.0 * np.sum(N * S, -1, keepdims=True) * N - S
        color = color + mat.kr * tx.environment(scene.environment, R)
    return color


class ZBufferRenderer:
    """The registered ``zbuffer`` method (see the module docstring)."""

    name = "zbuffer"
    ui_kind = "cpu"
    support = SUPPORT
    knob = Knob("tessellation", (1, 2, 3, 4, 6, 8, 12, 16, 24, 32), DEFAULT_LEVEL,
                "tessellation level of analytic primitives (sphere: 4L x 8L, see tessellate)")
    options = {
        "tessellation": Option(int, DEFAULT_LEVEL, "tessellation level >= 1 (the quality knob)"),
        "shading": Option(str, "gouraud", "flat (Lambert per polygon), gouraud (colours interpolated) "
                          "or phong (normals interpolated)", MODES),
        "depth_bits": Option(int, 24, f"p: the integer depth buffer's bits, 1..{MAX_DEPTH_BITS} "
                             "(initialised to 2^p - 1)"),
        "blinn": Option(bool, False, "Blinn-Phong (N.H)^n instead of Phong (R.S)^n"),
        "normals": Option(str, "smooth", "vertex normals: the tessellation's (analytic, area-weighted) "
                          "or face_mean (the course's plain mean of the incident faces' normals)",
                          NORMAL_RULES),
        "view": Option(str, "color", "color image or depth view (white near, black far)", ("color", "depth")),
        "near": Option(float, 0.0, "near clip plane (0: the camera's, or from the scene bounds)"),
        "far": Option(float, 0.0, "far clip plane (0: the camera's, or from the scene bounds)"),
        "volume_resolution": Option(int, rv.DEFAULT_RESOLUTION,
                                    "cells per side of a hypertexture's density grid (its own grid when set)",
                                    low=2),
        "step_scale": Option(float, 1.0, "factor of the hypertextures' ray-march step (their 'step')"),
        "shells": Option(int, rf.DEFAULT_SHELLS, f"layered shells drawn for each fur (1..{rf.MAX_SHELLS})",
                         low=1),
    }
    memory_options = ("tessellation", "volume_resolution", "shells")

    def _check(self, tessellation: int, depth_bits: int, near: float = 0.0, far: float = 0.0,
               shells: int = rf.DEFAULT_SHELLS) -> None:
        if not 1 <= tessellation <= MAX_LEVEL:
            raise WorkbenchError(f"method {self.name!r}: tessellation must be within 1..{MAX_LEVEL}, "
                                 f"got {tessellation}")
        if not 1 <= depth_bits <= MAX_DEPTH_BITS:
            raise WorkbenchError(f"method {self.name!r}: depth_bits must be within 1..{MAX_DEPTH_BITS}, "
                                 f"got {depth_bits}")
        if near < 0 or far < 0 or (near and far and far <= near):
            raise WorkbenchError(f"method {self.name!r}: need 0 < near < far, got near={near}, far={far}")
        try:
            rf.check_shells(shells)
        except WorkbenchError as e:
            raise WorkbenchError(f"method {self.name!r}: {e}") from None

    def estimate_bytes(self, scene: Scene, width: int, height: int, *, tessellation: int = DEFAULT_LEVEL,
                       depth_bits: int = 24, near: float = 0.0, far: float = 0.0,
                       volume_resolution: int = rv.DEFAULT_RESOLUTION, step_scale: float = 1.0,
                       shells: int = rf.DEFAULT_SHELLS, **_) -> int:
        """Triangles (:func:`.estimates.triangle_bound` at ``tessellation``), pixels, the
        media's march: the float32 grid and its float64 trilinear temporaries (about 3x), and
        :data:`.zbuffer_volume.BYTES_PER_PIXEL` (refused above the grids' own limit,
        :func:`.raster_volume.volume_bytes`), and the furs' shells, one at a time
        (:func:`.zbuffer_fur.shell_bytes`)."""
        self._check(tessellation, depth_bits, near, far, shells)
        grids = self._volume_bytes(scene, volume_resolution, step_scale)
        march = zv.BYTES_PER_PIXEL * width * height if grids else 0
        return raster_bytes(scene, width, height, tessellation, _BYTES_PER_TRIANGLE, _BYTES_PER_PIXEL,
                            _FIXED_BYTES) + 4 * grids + march + zf.shell_bytes(scene, tessellation, shells,
                                                                                width, height)

    def _volume_bytes(self, scene: Scene, volume_resolution: int, step_scale: float) -> int:
        try:
            return rv.volume_bytes(scene, volume_resolution, step_scale)
        except WorkbenchError as e:
            raise WorkbenchError(f"method {self.name!r}: {e}") from None

    def render(self, scene: Scene, width: int, height: int, *, tessellation: int = DEFAULT_LEVEL,
               shading: str = "gouraud", depth_bits: int = 24, blinn: bool = False, normals: str = "smooth",
               view: str = "color", near: float = 0.0, far: float = 0.0,
               volume_resolution: int = rv.DEFAULT_RESOLUTION, step_scale: float = 1.0,
               shells: int = rf.DEFAULT_SHELLS) -> RenderResult:
        self._check(tessellation, depth_bits, near, far, shells)
        self._volume_bytes(scene, volume_resolution, step_scale)
        timings: dict[str, float] = {}
        camera = scene.camera.with_resolution(width, height)
        needs = ft.scene_needs(scene)
        raster = rasterise(scene, camera, tessellation=tessellation, normals=normals, shading=shading,
                           blinn=blinn, depth_bits=depth_bits, near=near, far=far, timings=timings)
        frame, pairs, near, far = raster.frame, raster.pairs, raster.near, raster.far
        eye = np.asarray(camera.position, dtype=np.float64)
        t0 = time.perf_counter()
        image = self._shade(frame, pairs, shading, scene, camera, eye, blinn, needs)
        timings["shade"] = time.perf_counter() - t0
        depth = self._depth(frame, depth_bits, near, far)
        if view != "depth" and rv.media(scene):
            t0 = time.perf_counter()
            image, timings["volume_bake"] = zv.composite(image, scene, camera, depth, volume_resolution, step_scale)
            timings["volume_march"] = time.perf_counter() - t0 - timings["volume_bake"]
        if view != "depth" and rf.furs(scene):
            t0 = time.perf_counter()
            clip_from_world = camera.clip_from_camera(near, far) @ camera.camera_from_world()
            image = zf.composite(image, scene, camera, depth, tessellation, shells,
                                 lambda P: _polygons(P, np.zeros(P.shape[:2] + (1,)), clip_from_world,
                                                     width, height)[0])
            timings["shells"] = time.perf_counter() - t0
        if view == "depth":
            g = np.where(np.isfinite(depth), 1.0 - (depth - near) / (far - near), 0.0)
            image = np.repeat(np.clip(g, 0.0, 1.0)[..., None], 3, -1)
        left = [sp.Note(f, "not needed by the scene (not built)", sp.Status.NOT_NEEDED)
                for f in BUILT if f not in needs]
        left += sp.notes(SUPPORT, needs)
        used = sp.used(needs, left)
        stats = {"triangles": sum(p.n_triangles for p, _ in pairs), "near_clipped": int(raster.clipped.sum()),
                 "near_clipped_pixels": int(near_clipped_pixels(raster).sum()), "near": near, "far": far,
                 "depth_bits": depth_bits, "fragments": int(frame.counts[0]),
                 "depth_passes": int(frame.counts[1]), "shading": shading, "normals": normals}
        if rf.furs(scene):
            stats["shells"] = shells
        return RenderResult(self.name, image.astype(np.float32), timings, stats, used, left,
                            depth=depth.astype(np.float32))

    @staticmethod
    def _shade(frame, pairs, mode, scene, camera: Camera, eye, blinn, needs) -> np.ndarray:
        """The image: each pixel shaded from the attributes its polygon wrote, the background
        (or the environment seen along the pixel's ray) where nothing was drawn."""
        H, W = frame.ident.shape
        image = np.empty((H, W, 3))
        ident = frame.ident
        empty = ident < 0
        if scene.environment is not None:
            image[empty] = tx.environment(scene.environment, camera.rays()[1][empty])
        else:
            image[empty] = np.asarray(scene.background, dtype=np.float64)
        if not len(pairs) or empty.all():
            return image
        part_of = np.concatenate([np.full(p.n_triangles, k) for k, (p, _) in enumerate(pairs)])
        Ng = np.concatenate([np.cross(p.positions[p.faces[:, 1]] - p.positions[p.faces[:, 0]],
                                      p.positions[p.faces[:, 2]] - p.positions[p.faces[:, 0]])
                             for p, _ in pairs])
        seen = np.flatnonzero(~empty.ravel())
        tri = ident.ravel()[seen]
        owner = part_of[tri]
        attrs = frame.attrs.reshape(-1, N_ATTRS)
        flat_image = image.reshape(-1, 3)
        for k in np.unique(owner):
            part, mat = pairs[k]
            pix = seen[owner == k]
            flat_image[pix] = _shade_pixels(attrs[pix], normalize(Ng[tri[owner == k]]), mat, mode, scene,
                                            eye, blinn, part.uvs is not None, needs)
        return image

    @staticmethod
    def _depth(frame, depth_bits: int, near: float, far: float) -> np.ndarray:
        """Camera-space depth recovered from the integer buffer (its quantisation shows):
        window depth d = Z / (2^p - 1), depth = n f / (f - d (f - n)); inf where nothing."""
        zmax = (1 << depth_bits) - 1
        d = frame.depth.astype(np.float64) / zmax
        depth = (near * far) / (far - d * (far - near))
        return np.where(frame.ident >= 0, depth, np.inf)
