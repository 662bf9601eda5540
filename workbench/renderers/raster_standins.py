"""The raster family's stand-ins for global effects (issue 15): what the course gives a Z-buffer
renderer in place of the ray tracer's secondary rays.

* **Dynamic environment maps** ("surimpression de scène sur objet: objet réfléchissant"): for
  each object with a reflective (kr > 0) or transmissive (kt > 0) solid material, a cube map
  of the scene seen from the object's centre (the object itself left out), drawn with the same
  shaders and programs as the image whenever the scene changes (at the session's first frame
  and after every live edit, :meth:`.raster.RasterSession.update`; the map does not depend on
  the camera, so a camera move does not redraw it; two rounds give one bounce between mapped
  objects); Phong looks it up per fragment, Gouraud per vertex.  Reflection: ``kr env(R)``, ``R = 2 (N.S) N - S``; refraction (kt
  without blending): ``kt C env(T)`` with ``T`` the direction refracted once at the surface
  (Snell's law, ior).  Known failures, by construction: no self-reflection (the object is not
  in its own map), parallax (the map is seen from the centre, not from the surface point:
  nearby objects appear at the wrong place, the floor under a mirror ball is most wrong;
  ``envmap_iterations`` > 0 corrects it with distance impostors, see standins.glsl, except
  where the corrected ray passes behind a surface the centre does not see), one bounce
  between two mapped objects, and refraction through a solid that is taken as a sphere
  about its centre (two interfaces, no internal reflections).
  Refraction assumes a sphere about the map's centre through the surface point: the ray
  refracts in, crosses the chord and refracts out (exact directions for a sphere, two
  interfaces); solids (:data:`SOLID_KINDS`) with a kt material refract this way when the map is
  built, thin surfaces (planes, polygons, meshes) are blended.
* **Transparency by blending**: a kt material is drawn after the opaque surfaces, sorted back
  to front by object centre (not order-independent), in two passes per object: the colour
  behind is multiplied by ``kt C`` (the material's tint), then the surface's own light is
  added.  It fails where objects interpenetrate or their centres' order is not their depth
  order along a pixel (one order per object, not per fragment), and it shows the background
  straight through (no refraction).
* **Shadow maps** (Williams 1978, "Casting curved shadows on curved surfaces"): for every
  point light (area lights' stand-in point lights included) a cube of six depth maps, for
  every directional light one orthographic map over the scene's bounds, all tiles of one
  depth texture; a fragment is lit by a light when its depth seen from the light, after
  moving it ``shadow_bias`` x scene extent towards the light, is not beyond the stored depth.
  Point sampling: jagged edges at the map's resolution (aliasing); a small bias gives acne.
  Shadow maps depend on the geometry and the lights' positions only: drawn once per session
  and again after a light moves (:meth:`.raster.RasterSession.update`; a colour or intensity
  edit keeps them; a geometry edit builds a new session).

Each is built only when the scene needs it (``reflection``, ``refraction``, ``shadows`` in
:func:`workbench.scene.features.scene_needs`) and the option ``standins`` allows it
(default ``on`` for Gouraud and Phong; ``off``: the bare local model, the image of the
methods without stand-ins).  Their resolutions are options (``envmap_resolution``,
``shadow_resolution``) that ``workbench study --sweep`` can sweep.  Bytes are estimated
(:func:`standin_bytes`) before anything is allocated.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core import transform as tf
from ..core.errors import WorkbenchError
from ..core.tol import tol
from ..scene import features as ft
from ..scene import model as m
from ..scene.model import Camera, DirectionalLight, Scene

KINDS = ("envmap", "blend", "shadows")
#: The options of the stand-ins (the CLI's ``--set`` names, the window's stand-in controls).
OPTIONS = ("standins", "envmap_resolution", "shadow_resolution", "shadow_bias", "envmap_iterations")
ENV_RESOLUTIONS = (8, 2048)
SHADOW_RESOLUTIONS = (16, 8192)
DEFAULT_ENV_RESOLUTION = 128
DEFAULT_SHADOW_RESOLUTION = 512
DEFAULT_ENV_ITERATIONS = 3
"""Parallax-correction steps of an environment-map lookup (distance impostors; 0: the classic
map seen from the object's centre)."""
MAX_ENV_ITERATIONS = 16
DEFAULT_SHADOW_BIAS = 0.001
"""Shadow-map bias as a fraction of the scene's extent (the diagonal of its bounds)."""

#: Cube faces: viewing direction and up vector, in the order of ``cube_face`` in standins.glsl.
FACES = (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)), ((-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
         ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
         ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)), ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0)))
#: Bytes per texel: the environment map's RGBA float32 colour and its depth; a shadow map's depth.
ENV_TEXEL_BYTES = 16 + 4
SHADOW_TEXEL_BYTES = 4


def parse_standins(text) -> str:
    """The ``standins`` option: ``on`` (every stand-in the scene needs), ``off`` (none), or a
    comma-separated subset of ``envmap``, ``blend``, ``shadows``.  Returns the canonical form
    (``off`` or the chosen kinds in :data:`KINDS` order); raises ValueError otherwise."""
    words = [w.strip() for w in str(text).lower().split(",") if w.strip()]
    if words == ["on"]:
        return ",".join(KINDS)
    if words in (["off"], ["none"]):
        return "off"
    bad = [w for w in words if w not in KINDS]
    if bad or not words:
        raise ValueError(f"expected on, off or a comma-separated subset of {', '.join(KINDS)}, got {text!r}")
    return ",".join(k for k in KINDS if k in words)


@dataclass(frozen=True)
class StandinOptions:
    """The stand-ins asked for (``kinds``: a subset of :data:`KINDS`) and their knobs."""

    kinds: frozenset = frozenset(KINDS)
    envmap_resolution: int = DEFAULT_ENV_RESOLUTION
    shadow_resolution: int = DEFAULT_SHADOW_RESOLUTION
    shadow_bias: float = DEFAULT_SHADOW_BIAS
    envmap_iterations: int = DEFAULT_ENV_ITERATIONS

    @classmethod
    def parse(cls, standins: str = "on", envmap_resolution: int = DEFAULT_ENV_RESOLUTION,
              shadow_resolution: int = DEFAULT_SHADOW_RESOLUTION, shadow_bias: float = DEFAULT_SHADOW_BIAS,
              envmap_iterations: int = DEFAULT_ENV_ITERATIONS) -> "StandinOptions":
        """Checked options (one-line WorkbenchError naming the bad value)."""
        try:
            canon = parse_standins(standins)
        except ValueError as e:
            raise WorkbenchError(f"standins: {e}") from None
        lo, hi = ENV_RESOLUTIONS
        if not lo <= envmap_resolution <= hi:
            raise WorkbenchError(f"envmap_resolution must be within {lo}..{hi}, got {envmap_resolution}")
        lo, hi = SHADOW_RESOLUTIONS
        if not lo <= shadow_resolution <= hi:
            raise WorkbenchError(f"shadow_resolution must be within {lo}..{hi}, got {shadow_resolution}")
        if not (math.isfinite(shadow_bias) and 0.0 <= shadow_bias < 1.0):
            raise WorkbenchError(f"shadow_bias must be within [0, 1) (a fraction of the scene's extent), "
                                 f"got {shadow_bias}")
        if not 0 <= envmap_iterations <= MAX_ENV_ITERATIONS:
            raise WorkbenchError(f"envmap_iterations must be within 0..{MAX_ENV_ITERATIONS}, got {envmap_iterations}")
        kinds = frozenset() if canon == "off" else frozenset(canon.split(","))
        return cls(kinds, int(envmap_resolution), int(shadow_resolution), float(shadow_bias),
                   int(envmap_iterations))


@dataclass(frozen=True)
class Plan:
    """Which stand-ins a session builds: ``envmap``, ``blend``, ``shadows``; ``covered`` maps
    each scene feature a stand-in draws to how; ``off_reason`` says why the others are not
    drawn."""

    envmap: bool
    blend: bool
    shadows: bool
    covered: dict
    off_reason: str

    @property
    def any(self) -> bool:
        return self.envmap or self.blend or self.shadows


def plan(needs: frozenset, options: StandinOptions | None, mode: str, *, user_model: bool,
         n_lights: int) -> Plan:
    """The stand-ins of a session: those the scene needs (``needs``), the options allow and
    the mode can draw (Gouraud and Phong; flat shading and a user's shading model draw the bare
    local model)."""
    kinds = options.kinds if options is not None else frozenset()
    if mode == "flat":
        off = "flat shading draws the bare local model; stand-ins are for gouraud and phong"
    elif user_model:
        off = "a user's shading model draws the bare local model, without stand-ins"
    else:
        off = "stand-in off: option standins"
    ok = mode in ("gouraud", "phong") and not user_model
    envmap = ok and "envmap" in kinds and (ft.REFLECTION in needs or ft.REFRACTION in needs)
    blend = ok and "blend" in kinds and ft.REFRACTION in needs
    shadows = ok and "shadows" in kinds and ft.SHADOWS in needs and n_lights > 0
    covered = {}
    if ft.REFLECTION in needs and envmap:
        covered[ft.REFLECTION] = "dynamic environment map per reflective object"
    if ft.REFRACTION in needs and (blend or envmap):
        covered[ft.REFRACTION] = " and ".join(
            (["refraction of solids through their environment map"] if envmap else [])
            + (["transparency by blending with the material's tint" + (" (thin surfaces)" if envmap else "")]
               if blend else []))
    if ft.SHADOWS in needs and shadows:
        covered[ft.SHADOWS] = "shadow maps (Williams 1978)"
    return Plan(envmap, blend, shadows, covered, off)


#: Object kinds that are solids (a kt material refracts through them like a lens: through the
#: environment map when there is one); other kinds are thin surfaces (blended when kt > 0).
SOLID_KINDS = ("sphere", "box", "csg", "quadric")


def refracts_through_map(mat: m.Material, kind: str, p: Plan) -> bool:
    """Whether a part of ``kind`` with ``mat`` refracts through its environment map: kt > 0
    and the map is built, on a solid (:data:`SOLID_KINDS`) or when blending is off."""
    return p.envmap and mat.kt > 0 and (kind in SOLID_KINDS or not p.blend)


def mapped_material(mat: m.Material, kind: str, p: Plan) -> bool:
    """Whether a part of ``kind`` with ``mat`` gets an environment map under plan ``p``: kr > 0
    (unless the material reflects the scene's environment, the course's environment mapping,
    which stays exact for it), or refraction through the map."""
    return p.envmap and ((mat.kr > 0 and not mat.environment) or refracts_through_map(mat, kind, p))


def blended_material(mat: m.Material, kind: str, p: Plan) -> bool:
    """Whether a part of ``kind`` with ``mat`` is drawn by blending: kt > 0, no opacity map of
    its own, and not refracting through an environment map."""
    return p.blend and mat.kt > 0 and mat.opacity is None and not refracts_through_map(mat, kind, p)


def _leaves(obj: m.SceneObject):
    if isinstance(obj, m.CSG):
        for child in (obj.left, obj.right):
            yield from _leaves(child)
    else:
        yield obj


def shadow_tiles(lights) -> int:
    """Tiles of the shadow atlas: six per point light, one per directional light."""
    return sum(1 if isinstance(x, DirectionalLight) else 6 for x in lights)


def atlas_grid(tiles: int) -> tuple[int, int]:
    """(columns, rows) of a near-square grid of ``tiles`` tiles."""
    cols = max(1, math.ceil(math.sqrt(tiles)))
    return cols, max(1, math.ceil(tiles / cols))


def standin_bytes(scene: Scene, options: StandinOptions | None, mode: str, *, user_model: bool = False) -> int:
    """Bytes of the stand-ins' textures: per environment-mapped object (an upper bound: every
    leaf of an object with such a material) ``6 R^2 (16 + 4)`` (colour and depth), and the
    shadow atlas's ``cols x rows x S^2 x 4``."""
    lights = scene.point_lights()
    p = plan(ft.scene_needs(scene), options, mode, user_model=user_model, n_lights=len(lights))
    total = 0
    if p.envmap:
        n = sum(1 for o in scene.objects for leaf in _leaves(o)
                if mapped_material(scene.materials[leaf.material], o.kind, p))
        total += n * 6 * options.envmap_resolution ** 2 * ENV_TEXEL_BYTES
    if p.shadows:
        cols, rows = atlas_grid(shadow_tiles(lights))
        total += cols * rows * options.shadow_resolution ** 2 * SHADOW_TEXEL_BYTES
    return total


# --------------------------------------------------------------------------- geometry
def scene_extent(boxes: np.ndarray) -> float:
    """Diagonal of the union of (K, 2, 3) boxes."""
    return float(np.linalg.norm(boxes[:, 1].max(0) - boxes[:, 0].min(0)))


def _box_distance(p: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """(K,) distance from point ``p`` to each (K, 2, 3) box (0 inside)."""
    gap = np.maximum(np.maximum(boxes[:, 0] - p, p - boxes[:, 1]), 0.0)
    return np.linalg.norm(gap, axis=1)


def _corner_distance(p: np.ndarray, boxes: np.ndarray) -> float:
    corners = np.stack([np.where(np.array([i & 1, i & 2, i & 4], bool), boxes[:, 1], boxes[:, 0])
                        for i in range(8)], 1)
    return float(np.linalg.norm(corners - p, axis=-1).max())


def cube_cameras(centre, boxes: np.ndarray, resolution: int) -> tuple[list[Camera], float, float]:
    """The six 90-degree cameras of a cube map at ``centre`` (:data:`FACES` order) seeing the
    (K, 2, 3) ``boxes``, and their (near, far): near half the distance to the nearest box (at
    least ``tol.hemicube_near`` extents), far beyond the farthest corner."""
    c = np.asarray(centre, dtype=np.float64)
    extent = scene_extent(boxes)
    d = _box_distance(c, boxes)
    near = max(0.5 * float(d.min()) if len(d) else 0.0, tol.hemicube_near * extent)
    far = max(1.01 * _corner_distance(c, boxes), 2.0 * near)
    cams = [Camera(tuple(c), tuple(c + np.asarray(f)), up, 90.0, resolution, resolution) for f, up in FACES]
    return cams, near, far


def clip_of(camera: Camera, near: float, far: float) -> np.ndarray:
    """(4, 4) ``clip_from_world`` of a camera."""
    return camera.clip_from_camera(near, far) @ camera.camera_from_world()


def _ortho(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """OpenGL orthographic ``clip_from_camera`` of the camera-space box [lo, hi] (the camera
    looks down -z: near = -hi_z, far = -lo_z)."""
    M = np.eye(4)
    M[0, 0], M[1, 1], M[2, 2] = 2.0 / (hi[0] - lo[0]), 2.0 / (hi[1] - lo[1]), -2.0 / (hi[2] - lo[2])
    M[0, 3] = -(hi[0] + lo[0]) / (hi[0] - lo[0])
    M[1, 3] = -(hi[1] + lo[1]) / (hi[1] - lo[1])
    M[2, 3] = (hi[2] + lo[2]) / (hi[2] - lo[2])
    return M


def directional_clip(towards_light, boxes: np.ndarray) -> np.ndarray:
    """(4, 4) orthographic ``clip_from_world`` of a directional light (``towards_light``: unit
    direction to it) covering the (K, 2, 3) boxes, with a margin of 1 % of the extent."""
    w = tf.normalize(np.asarray(towards_light, dtype=np.float64))
    lo, hi = boxes[:, 0].min(0), boxes[:, 1].max(0)
    centre, extent = 0.5 * (lo + hi), max(scene_extent(boxes), tol.zero)
    up = (0.0, 1.0, 0.0) if abs(w[1]) < 0.9 else (1.0, 0.0, 0.0)
    V = tf.look_at(centre + w * extent, centre, up)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    q = tf.transform_points(V, corners)
    margin = 0.01 * extent
    return _ortho(q.min(0) - margin, q.max(0) + margin) @ V


@dataclass(frozen=True)
class ShadowLayout:
    """The shadow atlas: ``tiles`` tiles of ``resolution``^2 on a ``cols`` x ``rows`` grid;
    per light its first tile ``base``, whether it is a cube (point light) ``cube`` and its
    position (or direction towards it) ``pos``, a point light's faces' (near, far) ``ranges``
    ((0, 0) for a directional light); ``bias_world`` the bias in world units;
    ``clips`` (tiles, 4, 4) the tiles' ``clip_from_world``."""

    resolution: int
    cols: int
    rows: int
    tiles: int
    base: tuple
    cube: tuple
    pos: tuple
    ranges: tuple
    bias_world: float
    clips: np.ndarray


def shadow_layout(lights, boxes: np.ndarray, resolution: int, bias: float) -> ShadowLayout:
    """The atlas of the (point and directional) ``lights`` over the scene's (K, 2, 3) boxes."""
    from .raster_shaders import light_values
    base, cube, pos, ranges, clips = [], [], [], [], []
    for light in lights:
        p, _ = light_values(light)
        base.append(len(clips))
        pos.append(tuple(float(x) for x in p))
        if isinstance(light, DirectionalLight):
            cube.append(False)
            ranges.append((0.0, 0.0))
            clips.append(directional_clip(p, boxes))
        else:
            cube.append(True)
            cams, near, far = cube_cameras(p, boxes, resolution)
            ranges.append((near, far))
            clips.extend(clip_of(cam, near, far) for cam in cams)
    cols, rows = atlas_grid(len(clips))
    return ShadowLayout(resolution, cols, rows, len(clips), tuple(base), tuple(cube), tuple(pos),
                        tuple(ranges), bias * scene_extent(boxes), np.array(clips))


@dataclass(frozen=True)
class DrawStandins:
    """What stand-ins one draw's program compiles (:func:`.raster_shaders.standin_defines`):
    ``env_res`` > 0 its object's environment map at that resolution, looked up with
    ``env_iterations`` parallax-correction steps, ``env_kt`` refraction through it, ``tint_pass`` the multiplicative pass of blended transparency, ``shadows`` the
    shadow atlas (or None)."""

    env_res: int = 0
    env_iterations: int = 0
    env_kt: bool = False
    tint_pass: bool = False
    shadows: ShadowLayout | None = None


# --------------------------------------------------------------------------- GL objects
def _tile_viewport(tile: int, cols: int, res: int) -> tuple[int, int, int, int]:
    return (res * (tile % cols), res * (tile // cols), res, res)


class EnvironmentMap:
    """One object's dynamic cube map: six tiles (3 x 2) of ``resolution``^2 RGBA float32 with
    their depth, seen from ``centre`` by ``cameras`` (:func:`cube_cameras`) between ``near``
    and ``far``."""

    def __init__(self, ctx, key, centre: np.ndarray, boxes: np.ndarray, resolution: int):
        import moderngl
        self.key, self.centre, self.resolution = key, np.asarray(centre, dtype=np.float64), resolution
        self.cameras, self.near, self.far = cube_cameras(self.centre, boxes, resolution)
        size = (3 * resolution, 2 * resolution)
        self.color = ctx.texture(size, 4, dtype="f4")
        self.color.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.color.repeat_x = self.color.repeat_y = False
        self.depth = ctx.depth_texture(size)
        self.depth.compare_func = ""  # read as distances (standins.glsl env_distance)
        self.depth.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.depth.repeat_x = self.depth.repeat_y = False
        self.fbo = ctx.framebuffer([self.color], self.depth)

    def faces(self):
        """(viewport, camera) of each face."""
        for f in range(6):
            yield _tile_viewport(f, 3, self.resolution), self.cameras[f]

    def release(self) -> None:
        from . import gl
        gl.release_framebuffer(self.fbo)
        self.color.release()
        self.depth.release()


class ShadowAtlas:
    """The shadow maps of a :class:`ShadowLayout` in one depth texture, read raw by
    ``texelFetch`` (no comparison sampler, no filtering)."""

    def __init__(self, ctx, layout: ShadowLayout):
        self.layout = layout
        size = (layout.cols * layout.resolution, layout.rows * layout.resolution)
        limit = int(ctx.info.get("GL_MAX_TEXTURE_SIZE", 8192))
        if max(size) > limit:
            raise WorkbenchError(f"shadow_resolution {layout.resolution}: the shadow atlas of {layout.tiles} "
                                 f"maps would be {size[0]} x {size[1]} texels, above GL_MAX_TEXTURE_SIZE "
                                 f"{limit}; lower shadow_resolution")
        self.depth = ctx.depth_texture(size)
        self.depth.compare_func = ""
        import moderngl
        self.depth.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.fbo = ctx.framebuffer(depth_attachment=self.depth)

    def tiles(self):
        """(viewport, clip_from_world) of each tile."""
        L = self.layout
        for t in range(L.tiles):
            yield _tile_viewport(t, L.cols, L.resolution), L.clips[t]

    def release(self) -> None:
        from . import gl
        gl.release_framebuffer(self.fbo)
        self.depth.release()


def mat4_array(clips: np.ndarray) -> np.ndarray:
    """(K, 4, 4) row-major matrices as the column-major float32 data of a GLSL ``mat4[K]``."""
    return np.ascontiguousarray(np.transpose(np.asarray(clips), (0, 2, 1)), dtype="f4")
