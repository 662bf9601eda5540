"""Flat, Gouraud and Phong shading in GLSL (moderngl on EGL, into an FBO): the course's
"lissage" chapter.

* ``flat``: one lighting per polygon, at its centroid with its normal (Lambert's model as the
  course draws it; the texture colour still varies per fragment).
* ``gouraud``: lighting at the vertices with normals averaged from the incident faces
  (analytic for spheres and quadrics), the diffuse and specular terms interpolated.
* ``phong``: normals interpolated and lighting per fragment (bump mapping needs this).

All three use the local model of :mod:`.local_model` (GLSL mirror in
``shaders/include/lighting.glsl``) and the textures of :mod:`.texturing` (mirror in
``shaders/include/texturing.glsl``).

Gouraud and Phong also draw stand-ins for the global effects the scene needs (environment
maps, blending, shadow maps: :mod:`.raster_standins`, option ``standins``, on by default in
:func:`render`; a :class:`RasterSession` builds them when given ``standins``).

Hypertextures (participating media) are ray-marched in a fragment shader through a 3D
texture of their density (:mod:`.raster_volume`, options ``volume_resolution`` and
``step_scale``), composited over the opaque pass with the blended surfaces, back to front.
Furs (Kajiya-Kay texels) are drawn over their base as layered shells (:mod:`.raster_fur`,
option ``shells``), in the same back-to-front pass.

Interactive use (the UI calls this every frame)::

    session = RasterSession(scene, "phong", tessellation=6)   # tessellate + upload once
    image = session.draw(camera)                # (H, W, 3) float32, linear, row 0 on top
    session.draw_to(fbo, camera)                # into the caller's moderngl framebuffer

A session keeps its programs, vertex buffers and FBOs; ``render()`` reuses sessions for the
same scene content (objects, materials, lights), so repeated renders neither re-tessellate nor
re-upload.  A UI that owns a window context calls ``gl.use_context(ui_ctx)`` before creating
the session; ``draw_to`` needs an FBO with a depth attachment.  ``session.release()`` frees
the GL objects.

Live edits: material and light constants are compiled into the programs as literals (llvmpipe
reads a uniform per fragment).  A UI slider that edits them calls ``session.update(scene)``
instead of building a new session: the edited materials' draws (every lit draw for a light)
switch to *live* program variants that read those values from uniforms (``LIVE_MATERIAL``,
``LIVE_LIGHTS`` in :func:`.raster_shaders.material_defines`), compiled once and then only fed
new uniforms, on the same vertex buffers; ``session.settle()`` compiles the values back in
once the edit rests.  Both variants give the same image within float32 rounding.

Vertex work: every mode draws indexed, shared vertices; flat gives each triangle its own
provoking vertex carrying the polygon's normal and centroid
(:func:`~workbench.scene.tessellate_topology.provoking_layout`).  Objects whose parts are
closed and outward-wound (and opaque, without cut-outs) have their back faces culled while
the camera is outside their bounding box: the image is the same, half the triangles are
rasterised.  Measured overdraw of the opaque pass (opaque draws front to back) is at most
1.2 on the bundled scenes, so there is no depth pre-pass (it would double the vertex work).

Z-buffer: ``depth_bits`` 24 is moderngl's fixed-point depth texture; 32 a float
``GL_DEPTH_COMPONENT32F`` attachment (:mod:`.raster_depth`); 16 is emulated by quantising
``gl_FragDepth`` to 2^16 - 1 levels (exactly the comparisons of a 16-bit buffer; it disables
early depth rejection).  ``RenderResult.depth`` is the camera-space depth recovered from the
buffer, so its quantisation shows; ``view = "depth"`` shows it as grey levels.
"""
from __future__ import annotations

import time
from collections import OrderedDict
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..core.errors import WorkbenchError
from ..scene import features as ft
from ..scene.model import AREA_LIGHT_PREFIX, AreaLight, Camera, Environment, Material, Scene
from ..scene.kinds import KINDS
from ..scene.parts import Part
from ..scene.prepared import prepare
from ..scene.tessellate import (DEFAULT_LEVEL, MAX_LEVEL, NORMAL_RULES, area_light_parts, tessellate_scene,
                                with_normal_rule)
from .estimates import raster_bytes
from ..scene.tessellate_topology import closed_outward, provoking_layout
from . import gl
from . import support as sp
from . import texturing as tx
from .base import Knob, Option, RenderResult, check_memory, convert_options
from .raster_shaders import (LIVE_MATERIAL_FIELDS, ProgramCache, base_defines, light_kind,
                             light_uniforms, light_values, material_defines, material_uniforms)
from . import raster_standins as sti
from . import raster_fur as rf
from . import raster_volume as rv

DEPTH_CHOICES = (16, 24, 32)
#: Varying interpolation: GL's perspective-correct one, or the course's screen-space scanline.
INTERPOLATIONS = ("perspective", "screen")
#: Texture units of the image samplers.
UNITS = {"u_tex_image": 0, "u_bump_image": 1, "u_op_image": 2, "u_env_image": 3, "u_env_cube": 4,
         "u_shadow_atlas": 5, "u_env_depth": 6}
#: Shader features and why they may be left out.
SHADER_FEATURES = (ft.TEXTURES, ft.SOLID_TEXTURES, ft.IMAGE_TEXTURES, ft.BUMP, ft.OPACITY, ft.ENVIRONMENT)
NOT_RASTER = {
    ft.SHADOWS: "no shadow feelers in a raster local model",
    ft.REFLECTION: "mirror reflection needs ray tracing (environment-mapped materials reflect the environment map)",
    ft.REFRACTION: "refraction needs ray tracing (transmissive surfaces drawn with their local model)",
    ft.ABSORPTION: "absorption needs ray tracing",
}
_TESSELLATED = "drawn as its tessellation (the tessellation knob)"
_STANDINS = {
    ft.SHADOWS: "shadow-map stand-in (option standins)",
    ft.REFLECTION: "environment-map stand-in (option standins)",
    ft.REFRACTION: "environment-map or blended stand-in (option standins)",
}
_COMMON_APPROX = {**{f: _TESSELLATED for f in (ft.SPHERES, ft.QUADRICS, ft.CSG, ft.BLOBS, ft.ISOSURFACES,
                                               ft.LATHES)},
                  ft.AREA_LIGHTS: "stand-in point lights (the scene's area-light samples)",
                  ft.EMITTERS: "emission drawn on the surface; it lights others only through area-light stand-ins",
                  ft.HYPERTEXTURES: rv.REASON, ft.TEXELS: rf.REASON}
#: The raster modes' support tables (:mod:`.support`): flat draws no stand-ins, and only Phong
#: has a per-fragment normal for bump mapping.
SUPPORT = {
    "flat": sp.declare(_COMMON_APPROX, {**{f: f"{why} (flat draws no stand-ins)" for f, why in NOT_RASTER.items()},
                                        ft.BUMP: "flat shading has no per-fragment normal to perturb"}),
    "gouraud": sp.declare({**_COMMON_APPROX, **_STANDINS},
                          {ft.ABSORPTION: NOT_RASTER[ft.ABSORPTION],
                           ft.BUMP: "gouraud shading has no per-fragment normal to perturb"}),
    "phong": sp.declare({**_COMMON_APPROX, **_STANDINS}, {ft.ABSORPTION: NOT_RASTER[ft.ABSORPTION]}),
}


def _closed(kind: str) -> bool:
    """Whether a part of this kind is a closed, outward-wound surface (the kind's
    ``CLOSED_TESSELLATION``; False for parts that are no object kind, e.g. an area light's)."""
    k = KINDS.get(kind)
    return k is not None and k.CLOSED_TESSELLATION


def _set(prog, name: str, value) -> None:
    """Set a uniform if the compiler kept it."""
    if name in prog:
        prog[name].value = value


def _box_corners(P: np.ndarray) -> list:
    """The 8 corners of the axis-aligned bounding box of points ``P`` (N, 3)."""
    lo, hi = P.min(0), P.max(0)
    return [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


def _beyond_near(camera: Camera, boxes, near: float) -> np.ndarray:
    """Per box (G, 8, 3 corners): True when the whole box lies beyond the near plane, so the
    camera is outside the solid within it and no front face is clipped open."""
    boxes = np.asarray(boxes, dtype=np.float64)
    if len(boxes) == 0:
        return np.zeros(0, dtype=bool)
    depth = camera.project(boxes.reshape(-1, 3))[1].reshape(-1, 8)
    return (depth > near).all(1)


def _write(prog, name: str, array: np.ndarray) -> None:
    if name in prog:
        prog[name].write(np.ascontiguousarray(array, dtype="f4").tobytes())


class _Uniforms:
    """The uniforms of one draw, recorded once and written when the draw's program last
    served another draw (programs are shared between draws with the same defines)."""

    def __init__(self, prog):
        self.prog, self.items = prog, []

    def set(self, name: str, value) -> None:
        """Record ``value`` for the uniform ``name`` (an int, or floats written as raw bytes).
        An array uniform whose tail the compiler dropped (it keeps an array up to its last
        element read, e.g. one light's shadow range of two when only the first is used) takes
        the leading elements it kept."""
        if name in self.prog:
            u = self.prog[name]
            if isinstance(value, int):
                self.items.append((u, value, False))
            else:
                data = np.ascontiguousarray(value, dtype="f4").tobytes()
                self.items.append((u, data[:4 * u.dimension * u.array_length], True))

    def apply(self) -> None:
        for u, v, raw in self.items:
            if raw:
                u.write(v)
            else:
                u.value = v


@dataclass
class _Draw:
    """One part on the GPU: program, vertex array, material and what to bind (part and
    material are None for the background pass)."""

    part: Part | None
    material: Material | None
    prog: object
    vao: object
    blended: bool
    centre: np.ndarray
    images: dict
    uniforms: _Uniforms
    #: index into RasterSession.cull_boxes when the part belongs to a closed, outward-wound
    #: opaque object (its back faces are culled while the camera is outside its box), else -1
    cull: int = -1
    #: the scene material's name (None: an area light's polygon or the background)
    name: str | None = None
    has_uv: bool = False
    #: (vertex buffer, format, attribute names, index buffer) of the part
    buffers: tuple = ()
    #: vertex array of each program variant the part was drawn with (by id of the program)
    vaos: dict = field(default_factory=dict)
    #: the object the part belongs to (its name, else the draw's id): what an environment map
    #: of that object leaves out
    group: object = None
    #: the stand-ins its program compiles (raster_standins.DrawStandins, None: none) and the
    #: multiplicative first pass of blended transparency (a _Draw on the same buffers, or None)
    standins: object = None
    tint: "_Draw | None" = None
    #: (live material, live lights) of ``prog``, its uniforms other than live values, and
    #: whether it reads the lights from uniforms
    variant: tuple | None = None
    fixed: _Uniforms | None = None
    light_uniforms: bool = False


#: Material fields :meth:`RasterSession.update` takes without a new session.
_VALUE_FIELDS = LIVE_MATERIAL_FIELDS + ("kt", "ior", "absorption")


def _same(a, b) -> bool:
    """Equal values (identity, ``==``, or field by field for dataclasses holding arrays)."""
    if a is b:
        return True
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        return a.shape == b.shape and bool(np.array_equal(a, b))
    if hasattr(a, "__dataclass_fields__"):
        return all(_same(getattr(a, f.name), getattr(b, f.name)) for f in fields(a))
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    try:
        return bool(a == b)
    except (ValueError, TypeError):
        return False


_PARTS: OrderedDict = OrderedDict()


def _parts(scene: Scene, level: int) -> tuple[list[Part], list]:
    """Tessellated parts and the objects that gave none, cached by the scene's
    objects (identity) and level: flat, Gouraud and Phong sessions of the same scene share one
    tessellation."""
    key = (id(scene.objects), level)
    hit = _PARTS.get(key)
    if hit is None or hit[0] is not scene.objects:
        empty: list = []
        hit = (scene.objects, tessellate_scene(scene, level, empty), empty)
        _PARTS[key] = hit
        if len(_PARTS) > 8:
            _PARTS.popitem(last=False)
    return hit[1], hit[2]


class RasterSession:
    """A scene tessellated and uploaded for one shading mode (see the module docstring).

    Parameters
    ----------
    scene : the scene (its camera is only the default for :meth:`draw`).
    mode : ``"flat"``, ``"gouraud"`` or ``"phong"``.
    tessellation : level of :func:`workbench.scene.tessellate.tessellate_scene`.
    blinn : Blinn-Phong specular instead of Phong.
    depth_bits : 16 (emulated fixed point), 24 (fixed point) or 32 (float) depth buffer.
    backface_culling : cull the back faces of closed opaque objects while the camera is
        outside them (:meth:`_cull_groups`; the image is the same, the triangle work halves).
    shading : a user's shading model in place of the local model (Phong only; a
        :class:`~.user_shading.ShadingProgram`, see :mod:`.user_shading`).
    interpolation : ``"perspective"`` (GL's default, perspective-correct varyings) or
        ``"screen"``: the course's scanline formulas, linear in screen space along edges and
        spans (as GLSL ``noperspective``; the ``SCREEN_SPACE`` define,
        ``shaders/include/screen_space.glsl``).
    normals : vertex normals, ``"smooth"`` (the tessellation's) or ``"face_mean"`` (the
        course's plain mean of the incident faces' normals,
        :func:`~workbench.scene.tessellate.with_normal_rule`).
    standins : the stand-ins for global effects asked for (:class:`.raster_standins.
        StandinOptions`; None: none, the bare local model); those the scene needs and the
        mode draws are built (:func:`.raster_standins.plan`).
    volume_resolution, step_scale : texels per side of the hypertextures' 3D textures (their
        own ``grid`` when set) and the factor of their march step (:mod:`.raster_volume`).
    shells : layered shells per fur (:mod:`.raster_fur`).
    """

    def __init__(self, scene: Scene, mode: str, *, tessellation: int = DEFAULT_LEVEL,
                 blinn: bool = False, depth_bits: int = 24, ctx=None, backface_culling: bool = True,
                 shading=None, interpolation: str = "perspective", normals: str = "smooth",
                 standins: sti.StandinOptions | None = None,
                 volume_resolution: int = rv.DEFAULT_RESOLUTION, step_scale: float = 1.0,
                 shells: int = rf.DEFAULT_SHELLS):
        if mode not in ("flat", "gouraud", "phong"):
            raise WorkbenchError(f"unknown raster mode {mode!r}")
        if shading is not None and mode != "phong":
            raise WorkbenchError(f"a user's shading model needs Phong shading, not {mode!r}")
        self.shading = shading
        if depth_bits not in DEPTH_CHOICES:
            raise WorkbenchError(f"depth_bits must be one of {DEPTH_CHOICES}, got {depth_bits}")
        if interpolation not in INTERPOLATIONS:
            raise WorkbenchError(f"interpolation must be one of {', '.join(INTERPOLATIONS)}, got {interpolation!r}")
        rv.volume_bytes(scene, volume_resolution, step_scale)  # refuses before anything is built
        self.shells = rf.check_shells(shells)
        self.scene, self.mode, self.depth_bits, self.blinn = scene, mode, depth_bits, blinn
        self.interpolation = interpolation
        #: materials (names) and whether the lights are drawn by live programs
        #: (:meth:`update`; :meth:`settle` compiles their values back in)
        self.live_materials: set[str] = set()
        self.live_lights = False
        #: area lights' polygon materials ("area light N") whose radiance is live
        self.live_areas: set[str] = set()
        self.ctx = ctx or gl.context()
        self.programs = ProgramCache(self.ctx)
        self.timings: dict[str, float] = {}
        t0 = time.perf_counter()
        parts, empty = _parts(scene, tessellation)
        empty = [o for o in empty if not any(o is v for v in rv.media(scene))]  # marched, not tessellated
        #: objects whose surface tessellates to nothing (a blob's threshold above its field's
        #: maximum): not drawn, as the ray methods find no surface there; said in left_out
        self.empty_objects = [o.name or o.kind for o in empty]
        pairs = [(with_normal_rule(p, normals), scene.materials[p.material], p.material)
                 for p in parts]
        #: bounds, clip planes and area lights (.scene.prepared) of what is drawn (an empty
        #: object's declared bounds would widen the depth range and the stand-ins' maps), built
        #: once per session
        drawn = [o for o in scene.objects if not any(o is e for e in empty)]
        self.prepared = prepare(replace(scene, objects=type(scene.objects)(drawn)) if empty else scene)
        pairs += [(p, m, None) for p, m in area_light_parts(self.prepared.area_lights)]
        self.timings["tessellate"] = time.perf_counter() - t0
        self.n_triangles = sum(p.n_triangles for p, _, _ in pairs)
        #: (K, 2, 3) world box of every part: what the stand-ins' maps cover
        self.part_boxes = np.array([[p.positions.min(0), p.positions.max(0)] for p, _, _ in pairs]).reshape(-1, 2, 3)
        self.lights = scene.point_lights()
        self._light_values = light_uniforms(self.lights)
        self._needs = ft.scene_needs(scene)  # its texture entry does not change with update()
        self._gl_images: dict[tuple, object] = {}
        self._gl_objects: list = []  # vertex arrays and buffers, freed by release()
        self._fbos: OrderedDict = OrderedDict()
        self._depth_of: dict[int, tuple] = {}  # id of an own FBO -> (colour, depth) textures
        self._uniforms_of: dict[int, _Draw] = {}  # program -> draw whose uniforms it holds
        self._camera_of: dict[int, bytes] = {}    # program -> clip matrix it holds
        t0 = time.perf_counter()
        self._build_standins(pairs, standins)
        self.draws = [self._upload(p, m, name) for p, m, name in pairs]
        self.cull_boxes = self._cull_groups() if backface_culling else np.zeros((0, 8, 3))
        self.volume_resolution, self.step_scale = int(volume_resolution), float(step_scale)
        #: the hypertextures' ray marches (:mod:`.raster_volume`), drawn in the camera's pass
        self.volumes, self.timings["volume_bake"] = rv.build(self.ctx, self.programs, scene,
                                                             self.volume_resolution, self.step_scale)
        self._volume_targets: OrderedDict = OrderedDict()  # colour texture id -> colour-only FBO
        #: the furs' shells (:mod:`.raster_fur`), drawn in the camera's pass
        self.furs = rf.build(self.ctx, self.programs, scene, tessellation, self.shells, self.lights)
        self.background = None
        if scene.environment is not None:
            self.background = self._background(scene.environment)
        self.timings["upload"] = (time.perf_counter() - t0 - self.programs.compile_seconds
                                  - self.timings["volume_bake"])
        # llvmpipe compiles a program's machine code at its first draw: do it now, counted as
        # compile time (a 1 x 1 frame)
        t0 = time.perf_counter()
        self.draw(scene.camera.with_resolution(1, 1))
        self.timings["compile"] = (self.programs.compile_seconds + time.perf_counter() - t0
                                   - self.timings.get("standin_maps", 0.0))

    @property
    def left_out(self) -> list[sp.Note]:
        """Features of the scene this session does not draw, and why."""
        return self._reported()[0]

    @property
    def features_used(self) -> list[str]:
        """Features of the scene this session draws."""
        return self._reported()[1]

    def _reported(self) -> tuple[list[str], list[str]]:
        """:meth:`_report` of the current scene (computed once per scene)."""
        held = getattr(self, "_report_of", None)
        if held is None or held[0] is not self.scene:
            held = self._report_of = (self.scene, self._report())
        return held[1]

    # ------------------------------------------------------------------ building
    def _image_texture(self, path: str, repeat_v: bool = True, data: bool = False):
        """The GL texture of an image file (``data``: bump/opacity values, not sRGB colours)."""
        key = (path, repeat_v, data)
        if key not in self._gl_images:
            img = tx.image(path, data=data)
            tex = self.ctx.texture((img.shape[1], img.shape[0]), 4,
                                   np.ascontiguousarray(img[::-1], dtype="f4").tobytes(), dtype="f4")
            import moderngl
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.repeat_x, tex.repeat_y = True, repeat_v
            self._gl_images[key] = tex
        return self._gl_images[key]

    def _background(self, env: Environment) -> _Draw:
        """Full-screen pass showing the environment behind everything."""
        d = base_defines()
        d["ENV_KIND"] = {"sky": 1, "image": 2}[env.kind]
        prog = self.programs.get("background", d)
        u = _Uniforms(prog)
        images = {}
        if env.kind == "image":
            images["u_env_image"] = self._image_texture(env.path, repeat_v=False)
            u.set("u_env_image", UNITS["u_env_image"])
        else:
            u.set("u_env_zenith", env.zenith)
            u.set("u_env_horizon", env.horizon)
            u.set("u_env_ground", env.ground)
        vao = self.ctx.vertex_array(prog, [])
        self._gl_objects.append(vao)
        return _Draw(None, None, prog, vao, False, np.zeros(3), images, u)

    def _build_standins(self, pairs, options: sti.StandinOptions | None) -> None:
        """The plan of stand-ins (:func:`.raster_standins.plan`) and their maps: the shadow
        atlas, and one environment map per object (parts grouped by object name) whose material
        is mapped, seen from the centre of the object's bounds, the object left out."""
        self.standin_options = options
        self.plan = sti.plan(self._needs, options, self.mode, user_model=self.shading is not None,
                             n_lights=len(self.lights))
        self.shadow_layout = self.shadow_atlas = None
        self._shadows_drawn = self._env_drawn = False
        #: how many times each kind of map was drawn (a camera move draws none; tests read it)
        self.maps_drawn = {"shadow": 0, "environment": 0}
        self.env_maps: dict = {}
        if self.plan.shadows:
            self.shadow_layout = sti.shadow_layout(self.lights, self.part_boxes, options.shadow_resolution,
                                                   options.shadow_bias)
            self.shadow_atlas = sti.ShadowAtlas(self.ctx, self.shadow_layout)
        if self.plan.envmap:
            keys = [p.name or id(p) for p, _, _ in pairs]
            mapped = {k for k, (p, m, name) in zip(keys, pairs)
                      if name is not None and sti.mapped_material(m, p.kind, self.plan)}
            for key in mapped:
                mine = np.array([k == key for k in keys])
                box = self.part_boxes[mine]
                centre = 0.5 * (box[:, 0].min(0) + box[:, 1].max(0))
                self.env_maps[key] = sti.EnvironmentMap(self.ctx, key, centre, self.part_boxes[~mine],
                                                        options.envmap_resolution)

    def _draw_standins(self, part: Part, mat: Material, group, name: str | None):
        """The :class:`.raster_standins.DrawStandins` of a draw (None: an area light's
        polygon, or no stand-in in the session)."""
        if name is None or not self.plan.any:
            return None
        env = self.env_maps.get(group) if sti.mapped_material(mat, part.kind, self.plan) else None
        return sti.DrawStandins(env_res=env.resolution if env else 0,
                                env_iterations=self.standin_options.envmap_iterations if env else 0,
                                env_kt=env is not None and sti.refracts_through_map(mat, part.kind, self.plan),
                                shadows=self.shadow_layout)

    def _upload(self, part: Part, mat: Material, name: str | None) -> _Draw:
        ctx = self.ctx
        has_uv = part.uvs is not None
        F = part.faces
        if self.mode == "flat":
            # indexed, each triangle with its own provoking (last) vertex carrying the polygon's
            # normal and centroid (flat varyings take the provoking vertex's values)
            src, owner, F = provoking_layout(len(part.positions), F)
            has_owner = (owner >= 0)[:, None]
            cols = [part.positions[src], np.where(has_owner, part.face_normals[owner], 0.0),
                    part.obj_positions[src]] + ([part.uvs[src]] if has_uv else [])
            cols.append(np.where(has_owner, part.face_centroids[owner], 0.0))
        else:
            cols = [part.positions, part.normals, part.obj_positions] + ([part.uvs] if has_uv else [])
        data = np.concatenate(cols, 1)
        index = ctx.buffer(np.ascontiguousarray(F, dtype="i4").tobytes())
        fmt = "3f 3f 3f" + (" 2f" if has_uv else "") + (" 3f" if self.mode == "flat" else "")
        names = ["in_position", "in_normal", "in_obj_position"] + (["in_uv"] if has_uv else []) \
            + (["in_centroid"] if self.mode == "flat" else [])
        vbo = ctx.buffer(np.ascontiguousarray(data, dtype="f4").tobytes())
        self._gl_objects += [vbo, index]
        images = {}
        if mat.texture is not None and mat.texture.kind == "image":
            images["u_tex_image"] = self._image_texture(mat.texture.path)
        if mat.bump is not None and mat.bump.kind == "image" and self.mode == "phong":
            images["u_bump_image"] = self._image_texture(mat.bump.path, data=True)
        if mat.opacity is not None and mat.opacity.kind == "image":
            images["u_op_image"] = self._image_texture(mat.opacity.path, data=True)
        env = self.scene.environment
        # bound whenever a variant may read it (the literal one with kr > 0, the live one)
        if mat.environment and env is not None and env.kind == "image":
            images["u_env_image"] = self._image_texture(env.path, repeat_v=False)
        op = mat.opacity
        blended = op is not None and (op.kind == "image" or (op.kind == "constant" and op.value < 1.0))
        group = part.name or id(part)
        standins = self._draw_standins(part, mat, group, name)
        if standins is not None and standins.env_res:
            images["u_env_cube"] = self.env_maps[group].color
            images["u_env_depth"] = self.env_maps[group].depth
        if standins is not None and standins.shadows is not None:
            images["u_shadow_atlas"] = self.shadow_atlas.depth
        kt_blend = name is not None and sti.blended_material(mat, part.kind, self.plan)
        d = _Draw(part, mat, None, None, blended or kt_blend, part.positions.mean(0), images, None,
                  name=name, has_uv=has_uv, buffers=(vbo, fmt, names, index), group=group, standins=standins)
        self._bind(d)
        if kt_blend:
            d.tint = _Draw(part, mat, None, None, True, d.centre, {k: v for k, v in images.items()
                                                                  if k not in ("u_env_cube", "u_env_depth",
                                                                               "u_shadow_atlas")},
                           None, name=name, has_uv=has_uv, buffers=d.buffers, group=group,
                           standins=sti.DrawStandins(tint_pass=True))
            self._bind(d.tint)
        return d

    def _bind(self, d: _Draw) -> None:
        """Give draw ``d`` the program of its variant (literal, or live while its material or
        the lights are being edited: :meth:`update`), a vertex array for it (one per variant,
        on the same buffers) and its uniforms.  A live program does not depend on the values
        it reads, so a draw whose variant is unchanged keeps its program and only gets the
        new values."""
        live_mat = (d.name in self.live_materials if d.name is not None
                    else d.material.name in self.live_areas)
        if d.variant != (live_mat, self.live_lights):
            defines = material_defines(self.scene, d.material, self.mode, n_lights=len(self.lights),
                                       has_uv=d.has_uv, blinn=self.blinn, depth_bits=self.depth_bits,
                                       allow_bump=self.mode == "phong", live_material=live_mat,
                                       live_lights=self.live_lights, needs=self._needs,
                                       user_model=self.shading is not None,
                                       screen_space=self.interpolation == "screen", standins=d.standins)
            prog = self.programs.get("raster", defines, user=self.shading)
            vao = self._vertex_array(d, prog)
            d.prog, d.vao, d.variant = prog, vao, (live_mat, self.live_lights)
            d.fixed = self._static_uniforms(prog, d)
            d.light_uniforms = "LIVE_LIGHTS" in defines
        if not live_mat and not d.light_uniforms:
            d.uniforms = d.fixed
            return
        u = _Uniforms(d.prog)
        u.items = list(d.fixed.items)
        if live_mat:
            for k, v in material_uniforms(d.material).items():
                u.set(k, v)
        if d.light_uniforms:
            for k, v in self._light_values.items():
                u.set(k, v)
            if d.standins is not None and d.standins.shadows is not None:
                self._shadow_uniforms(u, d.standins.shadows, live=True)
        d.uniforms = u

    @staticmethod
    def _shadow_uniforms(u: _Uniforms, layout: sti.ShadowLayout, live: bool) -> None:
        """The shadow layout's uniforms: the tiles' clip matrices (only directional lights'
        tiles are read: the compiler keeps the array up to the last one, :meth:`_Uniforms.set`)
        and, in a live-lights program (``SHADOW_LIVE``), the lights' positions and cube
        ranges."""
        if "u_shadow_clip" in u.prog:
            u.set("u_shadow_clip", sti.mat4_array(layout.clips))
        if live:
            u.set("u_shadow_pos", np.array(layout.pos, dtype=np.float64).reshape(-1, 3))
            u.set("u_shadow_range", np.array(layout.ranges, dtype=np.float64).reshape(-1, 2))

    def _static_uniforms(self, prog, d: _Draw) -> _Uniforms:
        """Samplers, the bump gradient's transform, the sky colours, the depth levels and the
        stand-ins' matrices of one draw (lights, material and map constants are compiled in,
        raster_shaders.material_defines; the camera is set per frame)."""
        part, mat = d.part, d.material
        u = _Uniforms(prog)
        env = self.env_maps.get(d.group) if d.standins is not None and d.standins.env_res else None
        if env is not None:
            u.set("u_env_centre", tuple(float(x) for x in env.centre))
            u.set("u_env_range", (float(env.near), float(env.far)))
        if d.standins is not None and d.standins.shadows is not None:
            self._shadow_uniforms(u, d.standins.shadows, live=False)
        if mat.bump is not None:  # per part, not per material
            u.set("u_grad_from_object", np.linalg.inv(part.world_from_object[:3, :3]))
        env = self.scene.environment
        if env is None or env.kind == "sky":
            e = env or Environment()
            u.set("u_env_zenith", tuple(e.zenith))
            u.set("u_env_horizon", tuple(e.horizon))
            u.set("u_env_ground", tuple(e.ground))
        for name, unit in UNITS.items():
            u.set(name, unit)
        if self.depth_bits == 16:
            u.set("u_depth_levels", float(2 ** 16 - 1))
        return u

    def _cull_groups(self) -> np.ndarray:
        """Mark the draws of objects whose parts together are closed and outward-wound
        (:func:`closed_outward`; a CSG object's parts are grouped by its name, unnamed parts
        are tested alone) and have no opacity map (cut-outs show back faces); returns the
        (G, 8, 3) corners of each group's bounding box, the test of :meth:`_cull_flags`."""
        groups: dict[object, list[_Draw]] = {}
        for d in self.draws:
            if not d.blended and d.material.opacity is None:
                groups.setdefault(d.part.name or id(d), []).append(d)
        boxes = []
        for draws in groups.values():
            P = np.vstack([d.part.positions for d in draws])
            offsets = np.cumsum([0] + [len(d.part.positions) for d in draws[:-1]])
            F = np.vstack([d.part.faces + o for d, o in zip(draws, offsets)])
            if not closed_outward(P, F):
                continue
            boxes.append(_box_corners(P))
            for d in draws:
                d.cull = len(boxes) - 1
        return np.array(boxes, dtype=np.float64).reshape(-1, 8, 3)

    def _cull_flags(self, camera: Camera, near: float) -> np.ndarray:
        """Per cull group: True when its whole bounding box lies beyond the near plane (so the
        camera is outside the solid and no front face is clipped open): back faces hidden."""
        return _beyond_near(camera, self.cull_boxes, near)

    def _report(self) -> tuple[list[sp.Note], list[str]]:
        """(``left_out`` notes, features used): shader features not compiled, the mode's
        :data:`SUPPORT` table for the scene's needs, stand-ins this scene or the options did not
        draw (with why),
        objects with no triangle."""
        needs = ft.scene_needs(self.scene)
        left = [sp.Note(f, "not needed by the scene (not compiled)", sp.Status.NOT_NEEDED)
                for f in SHADER_FEATURES if f not in needs]
        table = SUPPORT[self.mode]
        left += sp.notes(table, needs)
        covered = dict(self.plan.covered)
        if not self.env_maps:  # e.g. only environment-mapped mirrors: no dynamic map built
            covered.pop(ft.REFLECTION, None)
            if not self.plan.blend:
                covered.pop(ft.REFRACTION, None)
        enabled = {ft.REFLECTION: self.plan.envmap, ft.REFRACTION: self.plan.envmap or self.plan.blend,
                   ft.SHADOWS: self.plan.shadows, ft.ABSORPTION: True}
        for f, why in NOT_RASTER.items():  # a stand-in the mode has but did not draw here
            if f in needs and f not in covered and table[f].status is sp.Status.APPROXIMATED:
                left.append(sp.Note(f, why + ("" if enabled[f] else f" ({self.plan.off_reason})")))
        if self.empty_objects:
            left.append(sp.Note("objects", f"{', '.join(self.empty_objects)} tessellate(s) to no triangle "
                                "(no surface: not drawn)"))
        self._covered = covered
        return left, sp.used(needs, left)

    @property
    def standins_used(self) -> dict[str, str]:
        """Scene features drawn by a stand-in, and how."""
        self._reported()
        return dict(self._covered)

    # ------------------------------------------------------------------ live edits
    @property
    def live(self) -> bool:
        """Some draws use live programs (values in uniforms): :meth:`settle` compiles them in."""
        return any(d.variant != (False, False) for d in self.draws
                   + [d.tint for d in self.draws if d.tint is not None])

    def update(self, scene: Scene) -> bool:
        """Take ``scene`` if it differs from the session's only in values that live programs
        read from uniforms: materials' colour, emission, ka, kd, ks, kr, shininess (and kt,
        ior, absorption, which no raster method uses), point and directional lights' position
        or direction, colour and intensity, and area lights' colour and intensity (their
        stand-ins' uniforms and their polygon's emission; a moved polygon is geometry).  The
        edited materials' draws (all lit draws for a
        light edit) switch to live programs (compiled once per variant, then only uniforms
        change: no recompile, no upload); :meth:`settle` compiles the values back in.

        The stand-ins' maps follow: the environment maps are redrawn at the next frame after
        any edit taken here (they show the lit scene); the shadow maps only when a light moved
        (its new layout read from uniforms by the live programs, ``SHADOW_LIVE``), not for a
        colour or intensity edit (depth only).  With stand-ins, a material edit of kt or ior
        (literals of the refraction and the blending) or of kr from or to 0 (an environment map
        more or less) is not taken.
        Returns False, changing nothing, for any other difference (new objects, environment,
        ambient, area lights, light kinds...): the caller builds a new session."""
        old = self.scene
        if scene is old:
            return True
        for f in fields(scene):
            if f.name not in ("materials", "lights", "camera", "name", "description", "source") \
                    and not _same(getattr(scene, f.name), getattr(old, f.name)):
                return False
        if scene.materials.keys() != old.materials.keys() or len(scene.lights) != len(old.lights):
            return False
        edited = set()
        for name, m in scene.materials.items():
            o = old.materials[name]
            if m is o or m == o:
                continue
            if replace(o, **{k: getattr(m, k) for k in _VALUE_FIELDS}) != m:
                return False
            edited.add(name)
        areas = {}
        for i, (a, b) in enumerate(zip(scene.lights, old.lights)):
            if isinstance(a, AreaLight) or isinstance(b, AreaLight):
                if type(a) is not type(b) or not _same(replace(b, color=a.color,
                                                               intensity=a.intensity), a):
                    return False  # its polygon (or stand-in grid) is geometry: a new session
                if not _same(a, b):  # radiance only: the polygon's emission, live
                    areas[f"{AREA_LIGHT_PREFIX}{i}"] = tuple(float(x) for x in a.radiance)
        lights = scene.point_lights()
        if [light_kind(x) for x in lights] != [light_kind(x) for x in self.lights]:
            return False
        lights_edited = any(not _same(a, b) for a, b in zip(lights, self.lights))
        moved = [not np.array_equal(light_values(a)[0], light_values(b)[0]) for a, b in zip(lights, self.lights)]
        if self.plan.any and any(getattr(scene.materials[n], k) != getattr(old.materials[n], k)
                                 for n in edited for k in ("kt", "ior")):
            return False  # which stand-ins a material gets, and their literals
        if self.plan.any and any(self._standin_role(scene.materials[d.name], d) != self._standin_role(d.material, d)
                                 for d in self.draws if d.name in edited):
            return False  # kr from or to 0: an environment map more or less
        if any(moved) and self.shadow_atlas is not None:
            # the shadow maps are the lights' views: redrawn at the next frame (a colour or
            # intensity edit changes no depth: the maps are kept)
            layout = sti.shadow_layout(lights, self.part_boxes, self.standin_options.shadow_resolution,
                                       self.standin_options.shadow_bias)
            self.shadow_layout = self.shadow_atlas.layout = layout
            self._shadows_drawn = False
            for d in self.draws:
                if d.standins is not None and d.standins.shadows is not None:
                    d.standins = replace(d.standins, shadows=layout)
        self.scene, self.lights = scene, lights
        if lights_edited:
            self._light_values = light_uniforms(lights)
            rf.recompile(self.programs, scene, self.furs, self.shells, lights)  # lights are literals there
        self.live_materials |= edited
        self.live_areas |= set(areas)
        self.live_lights = self.live_lights or lights_edited
        self._env_drawn = False  # the maps show the edited materials at the next frame
        for d in self.draws:
            if d.name is not None:
                d.material = scene.materials[d.name]
            elif d.material.name in areas:
                d.material = replace(d.material, emission=areas[d.material.name])
            if d.name in edited or lights_edited or (d.name is None and d.material.name in areas):
                self._bind(d)  # a live program (cached after its first use), new uniforms
            if d.tint is not None:
                d.tint.material = d.material
                if d.name in edited:
                    self._bind(d.tint)
        self._uniforms_of.clear()
        return True

    def settle(self, budget: int | None = None) -> bool:
        """Compile the current values back into literal programs (the fast static variant),
        at most ``budget`` programs per call (None: all; llvmpipe compiles a program's machine
        code at its first draw, so a caller that draws after each call spreads the work over
        frames); once no draw is live, release the literal programs no draw uses any more
        (live ones are kept for the next edit) and have the environment maps redrawn at the
        next frame (drawn by the live programs, they differed from the literal ones' by float32
        rounding).  Returns True when no draw is live."""
        was_live = self.live
        self.live_materials, self.live_lights, self.live_areas = set(), False, set()
        start = self.programs.compiles
        for d in self.draws + [d.tint for d in self.draws if d.tint is not None]:
            if d.variant != (False, False):
                if budget is not None and self.programs.compiles - start >= budget:
                    break
                self._bind(d)
        self._uniforms_of.clear()
        if self.live:
            return False
        if was_live:
            self._env_drawn = False
        used = [d.prog for d in self.draws] + ([self.background.prog] if self.background else [])
        used += [d.tint.prog for d in self.draws if d.tint is not None] + [v.prog for v in self.furs]
        if self.shadow_atlas is not None:
            used.append(self.programs.get("shadow_depth", base_defines()))
        gone = {id(p) for p in self.programs.release_unused(used)}
        for d in self.draws + [d.tint for d in self.draws if d.tint is not None]:
            for k in [k for k in d.vaos if k in gone]:
                d.vaos.pop(k).release()
        self._camera_of.clear()
        return True

    def release(self) -> None:
        """Free the session's GL objects (buffers, vertex arrays, programs, textures, FBOs)."""
        vaos = [v for d in self.draws for v in d.vaos.values()]
        vaos += [v for d in self.draws if d.tint is not None for v in d.tint.vaos.values()]
        for m in list(self.env_maps.values()) + ([self.shadow_atlas] if self.shadow_atlas else []):
            m.release()
        self.env_maps, self.shadow_atlas = {}, None
        for obj in vaos + self._gl_objects + list(self._gl_images.values()) + list(self.programs.programs.values()):
            obj.release()
        for v in self.volumes:
            v.vao.release()
            v.texture.release()
        for v in self.furs:
            v.vao.release()
            for b in v.buffers:
                b.release()
        for _, target in self._volume_targets.values():
            gl.release_framebuffer(target)
        for _, free in self._fbos.values():
            free()
        self._gl_objects, self._gl_images, self._fbos = [], {}, OrderedDict()
        self.volumes, self._volume_targets, self._depth_of, self.furs = [], OrderedDict(), {}, []
        self.programs.programs.clear()
        self._uniforms_of, self._camera_of = {}, {}
        self.draws, self.background = [], None

    def gl_bytes(self) -> int:
        """Bytes of GL memory the session holds (:func:`.gl.object_bytes`): geometry buffers,
        images, the stand-ins' maps and its framebuffers."""
        objs = [*self._gl_objects, *self._gl_images.values(), *(f for f, _ in self._fbos.values()),
                *(v.texture for v in self.volumes), *(b for v in self.furs for b in v.buffers)]
        for m in [*self.env_maps.values(), self.shadow_atlas]:
            if m is not None:
                objs += [getattr(m, "color", None), m.depth]
        return sum(gl.object_bytes(o) for o in objs if o is not None)

    # ------------------------------------------------------------------ drawing
    def near_far(self, camera: Camera) -> tuple[float, float]:
        return self.prepared.clip_planes(camera)

    def framebuffer(self, width: int, height: int):
        """A cached float32 RGBA colour + depth FBO of this size (depth format per
        ``depth_bits``: 24-bit fixed point, also used for the emulated 16 bits, or 32-bit
        float)."""
        key = (width, height)
        if key not in self._fbos:
            color = self.ctx.texture((width, height), 4, dtype="f4")
            if self.depth_bits == 32:
                from .raster_depth import FloatDepthFramebuffer
                holder = FloatDepthFramebuffer(self.ctx, color)
                self._fbos[key] = (holder.fbo, holder.release)
                self._depth_of[id(holder.fbo)] = (color, holder.depth_texture(self.ctx))
            else:
                depth = self.ctx.depth_texture((width, height))
                fbo = self.ctx.framebuffer([color], depth)

                def free(fbo=fbo, color=color, depth=depth):  # releasing an FBO keeps its attachments
                    gl.release_framebuffer(fbo)
                    color.release()
                    depth.release()
                self._fbos[key] = (fbo, free)
                self._depth_of[id(fbo)] = (color, depth)
            if len(self._fbos) > 4:
                old, free = self._fbos.popitem(last=False)[1]
                self._release_volume_target(self._depth_of.pop(id(old), (None,))[0])
                free()
        return self._fbos[key][0]

    # ------------------------------------------------------------------ the media's pass
    def _volume_target(self, fbo):
        """(colour-only FBO on ``fbo``'s colour texture, ``fbo``'s depth texture): the volume
        pass draws into the first while sampling the second (no feedback loop: the depth
        texture is not attached to the FBO drawn into)."""
        import moderngl
        color, depth = self._depth_of.get(id(fbo), (None, None))
        if color is None:  # the caller's FBO (the UI's): its attachments, if textures
            attached = fbo.color_attachments
            color = attached[0] if attached else None
            depth = fbo.depth_attachment
            if not isinstance(color, moderngl.Texture) or not isinstance(depth, moderngl.Texture):
                raise WorkbenchError("drawing hypertextures needs a framebuffer with colour and depth textures")
        if depth.depth:  # moderngl's depth textures compare by default: read as window depths
            depth.compare_func = ""
        target = self._volume_targets.get(id(color))
        if target is None or target[0] is not color:
            target = (color, self.ctx.framebuffer(color_attachments=[color]))
            self._volume_targets[id(color)] = target
            if len(self._volume_targets) > 4:
                gl.release_framebuffer(self._volume_targets.popitem(last=False)[1][1])
        return target[1], depth

    def _release_volume_target(self, color) -> None:
        if color is not None and id(color) in self._volume_targets:
            gl.release_framebuffer(self._volume_targets.pop(id(color))[1])

    def draw_to(self, fbo, camera: Camera, near: float | None = None, far: float | None = None):
        """Draw the scene seen by ``camera`` into ``fbo`` (colour attachment 0 + depth), after
        the stand-ins' maps when the scene changed since they were drawn (shadow maps: at the
        first frame and after a light moved, :meth:`update`; environment maps: at the first
        frame, after every edit :meth:`update` takes and once the values settle).  Neither depends on the
        camera, so a camera move redraws neither.  Returns the (near, far) used."""
        if not (near and far):  # the automatic planes only when needed (Python, per draw)
            n0, f0 = self.near_far(camera)
            near, far = near or n0, far or f0
        if not 0.0 < near < far:
            raise WorkbenchError(f"clip planes need 0 < near < far, got near {near:.6g} and far {far:.6g}")
        if (self.shadow_atlas is not None and not self._shadows_drawn) or (self.env_maps and not self._env_drawn):
            t0 = time.perf_counter()
            if self.shadow_atlas is not None and not self._shadows_drawn:
                self._draw_shadow_maps()
            if self.env_maps and not self._env_drawn:
                self.draw_environment_maps()
            self.timings["standin_maps"] = time.perf_counter() - t0
        self._draw_pass(fbo, (0, 0, fbo.width, fbo.height), camera, near, far)
        return near, far

    def draw_environment_maps(self, rounds: int = 2) -> None:
        """Draw every environment map's six faces from its object's centre, the object left
        out, with the image's programs.  Mapped objects see each other's maps as last drawn:
        ``rounds`` passes over all maps (from maps cleared to the background) give
        ``rounds - 1`` bounces between them (a mirror sees the glass ball refracting the
        mirror's first-round map)."""
        bg = tuple(float(x) for x in self.scene.background)
        for env in self.env_maps.values():
            env.fbo.clear(*bg, 0.0, depth=1.0)
        for _ in range(rounds):
            for env in self.env_maps.values():
                for viewport, face in env.faces():
                    self._draw_pass(env.fbo, viewport, face, env.near, env.far, skip=env.key)
        self._env_drawn = True
        self.maps_drawn["environment"] += 1

    def _draw_shadow_maps(self) -> None:
        """Depth of every surface (area lights' polygons excepted: their stand-in lights sit on
        them) seen from each tile of the shadow atlas (:class:`.raster_standins.ShadowAtlas`)."""
        import moderngl
        ctx, atlas = self.ctx, self.shadow_atlas
        prog = self.programs.get("shadow_depth", base_defines())
        atlas.fbo.use()
        atlas.fbo.depth_mask = True
        atlas.fbo.clear(depth=1.0)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        for viewport, clip in atlas.tiles():
            ctx.viewport = viewport
            prog["u_clip_from_world"].write(np.ascontiguousarray(clip.T, dtype="f4").tobytes())
            for d in self.draws:
                if d.name is not None:
                    self._vertex_array(d, prog).render(moderngl.TRIANGLES)
        self._camera_of.pop(id(prog), None)
        self._shadows_drawn = True
        self.maps_drawn["shadow"] += 1

    def _standin_role(self, mat: Material, d: _Draw) -> tuple[bool, bool]:
        """(environment-mapped, blended) of draw ``d``'s part with material ``mat``."""
        return sti.mapped_material(mat, d.part.kind, self.plan), sti.blended_material(mat, d.part.kind, self.plan)

    def _vertex_array(self, d: _Draw, prog):
        """The vertex array of draw ``d``'s buffers for ``prog`` (made once per program)."""
        vao = d.vaos.get(id(prog))
        if vao is None:
            vbo, fmt, names, index = d.buffers
            vao = d.vaos[id(prog)] = self.ctx.vertex_array(prog, [(vbo, fmt, *names)], index,
                                                           index_element_size=4, skip_errors=True)
        return vao

    def _draw_pass(self, fbo, viewport: tuple, camera: Camera, near: float, far: float, skip=None) -> None:
        """The scene seen by ``camera`` into the ``viewport`` of ``fbo`` (cleared there), all
        draws but those of object ``skip`` (an environment map's own object)."""
        import moderngl
        ctx = self.ctx
        V = camera.camera_from_world()
        clip = camera.clip_from_camera(near, far) @ V
        eye = tuple(float(x) for x in camera.position)
        fbo.use()
        ctx.viewport = viewport
        bg = tuple(float(x) for x in self.scene.background)
        fbo.clear(*bg, 0.0, depth=1.0, viewport=viewport)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        cam_pos = np.asarray(camera.position)
        draws = self.draws if skip is None else [d for d in self.draws if d.group != skip]
        # opaque front to back (early depth rejection), then the environment where nothing is,
        # then blended surfaces back to front without depth writes
        opaque = sorted((d for d in draws if not d.blended),
                        key=lambda d: float(np.linalg.norm(d.centre - cam_pos)))
        blended = sorted((d for d in draws if d.blended),
                         key=lambda d: -float(np.linalg.norm(d.centre - cam_pos)))
        clip_bytes = np.ascontiguousarray(clip.T, dtype="f4").tobytes()
        ctx.provoking_vertex = moderngl.LAST_VERTEX_CONVENTION  # flat: provoking_layout
        ctx.front_face, ctx.cull_face = "ccw", "back"
        cull = self._cull_flags(camera, near)
        for d in opaque:
            culled = d.cull >= 0 and cull[d.cull]
            if culled:
                ctx.enable(moderngl.CULL_FACE)
            self._render_draw(d, clip_bytes, eye)
            if culled:
                ctx.disable(moderngl.CULL_FACE)
        if self.background is not None:
            bg_draw = self.background
            ctx.depth_func = "<="
            fbo.depth_mask = False
            bg_draw.uniforms.apply()
            _write(bg_draw.prog, "u_world_from_camera", np.linalg.inv(V)[:3, :3].T)
            th = np.tan(np.radians(camera.fov_y) / 2.0)
            _set(bg_draw.prog, "u_tan", (float(th * camera.aspect), float(th)))
            for name, tex in bg_draw.images.items():
                tex.use(UNITS[name])
            bg_draw.vao.render(moderngl.TRIANGLES, vertices=3)
            ctx.depth_func = "<"
        # the media and the furs' shells (camera pass only) interleaved with the blended
        # surfaces, back to front
        volumes = self.volumes + self.furs if skip is None else []
        if volumes:
            far_first = lambda item: -float(np.linalg.norm(item.centre - cam_pos))
            blended = sorted(blended + volumes, key=far_first)
        if blended:
            ctx.enable(moderngl.BLEND)
            fbo.depth_mask = False
            target = None
            for d in blended:
                if isinstance(d, rf.FurDraw):
                    rf.draw(ctx, d, clip_bytes, eye, self.shells)
                    continue
                if isinstance(d, rv.VolumeDraw):
                    if target is None:
                        target = self._volume_target(fbo)
                    ctx.disable(moderngl.DEPTH_TEST)
                    target[0].use()
                    ctx.viewport = viewport
                    ctx.blend_func = moderngl.ONE, moderngl.SRC_ALPHA  # L + T behind
                    rv.draw(ctx, d, target[1], camera, near, far, viewport)
                    fbo.use()
                    ctx.viewport = viewport
                    ctx.enable(moderngl.DEPTH_TEST)
                    continue
                # closed solids seen from outside their box: only their front faces (the back
                # ones would blend in twice); from inside, the inner (back) faces are the surface
                if _closed(d.part.kind) and _beyond_near(camera, [_box_corners(d.part.positions)], near)[0]:
                    ctx.enable(moderngl.CULL_FACE)
                if d.tint is not None:
                    # stand-in transparency: behind *= kt C, then + the surface's own light
                    ctx.blend_func = moderngl.ZERO, moderngl.SRC_COLOR
                    self._render_draw(d.tint, clip_bytes, eye)
                    ctx.blend_func = moderngl.ONE, moderngl.ONE
                else:
                    ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
                self._render_draw(d, clip_bytes, eye)
                ctx.disable(moderngl.CULL_FACE)
        fbo.depth_mask = True
        ctx.disable(moderngl.BLEND)

    def _render_draw(self, d: _Draw, clip_bytes: bytes, eye: tuple) -> None:
        """One draw; a program keeps its uniforms, so a draw's material uniforms are written
        only when another draw used its program last, and the camera's once per frame."""
        import moderngl
        key = id(d.prog)
        if self._uniforms_of.get(key) is not d:
            d.uniforms.apply()
            self._uniforms_of[key] = d
        if self._camera_of.get(key) != clip_bytes:
            d.prog["u_clip_from_world"].write(clip_bytes)
            _set(d.prog, "u_eye", eye)
            self._camera_of[key] = clip_bytes
        for name, tex in d.images.items():
            tex.use(UNITS[name])
        d.vao.render(moderngl.TRIANGLES)

    def draw(self, camera: Camera | None = None, *, near: float | None = None,
             far: float | None = None, with_depth: bool = False):
        """Render and read back.

        Returns
        -------
        image : (H, W, 3) float32 linear RGB, row 0 at the top.
        depth : (H, W) float32 camera-space depth (inf where nothing was drawn), only with
            ``with_depth``, as ``(image, depth, (near, far))``.
        """
        camera = camera or self.scene.camera
        fbo = self.framebuffer(camera.width, camera.height)
        nf = self.draw_to(fbo, camera, near, far)
        image = self.read_image(fbo)
        if not with_depth:
            return image
        d = np.frombuffer(fbo.read(components=1, attachment=-1, dtype="f4"), dtype=np.float32)
        d = d.reshape(camera.height, camera.width)[::-1].astype(np.float64)
        n, f = nf
        # window depth d in [0, 1] -> camera depth: z_ndc = 2 d - 1 and
        # 2 n f / ((f + n) - z_ndc (f - n)) = n f / (f - d (f - n)) (never 0 for 0 < n < f)
        depth = (n * f) / (f - d * (f - n))
        depth[d >= 1.0] = np.inf
        return image, depth.astype(np.float32), nf

    @staticmethod
    def read_image(fbo) -> np.ndarray:
        """The colour attachment of ``fbo`` as (H, W, 3) float32, row 0 at the top (reading
        RGB, not RGBA, halves llvmpipe's read-back time)."""
        raw = np.frombuffer(fbo.read(components=3, dtype="f4"), dtype=np.float32)
        return np.ascontiguousarray(raw.reshape(fbo.height, fbo.width, 3)[::-1])


def depth_view(depth: np.ndarray, near: float, far: float) -> np.ndarray:
    """Grey image of a depth map: 1 at ``near``, 0 at ``far`` and where nothing was drawn,
    linear in camera-space depth. (H, W, 3) float32."""
    g = np.where(np.isfinite(depth), 1.0 - (depth - near) / (far - near), 0.0)
    return np.repeat(np.clip(g, 0.0, 1.0)[..., None], 3, -1).astype(np.float32)


# --------------------------------------------------------------------------- registered methods
_SESSIONS: OrderedDict = OrderedDict()
_MAX_SESSIONS = 6


def session_for(scene: Scene, mode: str, tessellation: int, blinn: bool, depth_bits: int,
                shading=None, interpolation: str = "perspective", normals: str = "smooth",
                standins: sti.StandinOptions | None = None, volume_resolution: int = rv.DEFAULT_RESOLUTION,
                step_scale: float = 1.0, shells: int = rf.DEFAULT_SHELLS) -> tuple[RasterSession, bool]:
    """A cached :class:`RasterSession` for the scene's content (camera excluded), shading
    model (``shading``: a user's, by its source text and parameter values), interpolation,
    normal rule, stand-ins, the media's texture resolution and step and the furs' shells; returns
    ``(session, created)``."""
    ctx = gl.context()
    key = (id(ctx), id(scene.objects), id(scene.materials), id(scene.lights), id(scene.environment),
           scene.ambient, mode, tessellation, blinn, depth_bits, None if shading is None else shading.key,
           interpolation, normals, standins, int(volume_resolution), float(step_scale), int(shells))
    hit = _SESSIONS.get(key)
    if hit is not None and hit[1] is scene.objects:
        _SESSIONS.move_to_end(key)
        return hit[0], False
    session = RasterSession(scene, mode, tessellation=tessellation, blinn=blinn, depth_bits=depth_bits, ctx=ctx,
                            shading=shading, interpolation=interpolation, normals=normals,
                            standins=standins, volume_resolution=volume_resolution, step_scale=step_scale,
                            shells=shells)
    _SESSIONS[key] = (session, scene.objects)
    if len(_SESSIONS) > _MAX_SESSIONS:
        _SESSIONS.popitem(last=False)[1][0].release()
    return session, True


_BYTES_PER_TRIANGLE = 1024
"""A triangle's tessellated part (float64), its vertex and index buffers (unshared vertices
for flat shading) and the draws' copies (about 280 B measured at tessellation 48)."""
_BYTES_PER_PIXEL = 160
"""Colour and depth attachments, read-backs and the float32 image and depth."""
_FIXED_BYTES = 64 * 2 ** 20
"""GL context, programs, textures."""


class _RasterRenderer:
    """Shared implementation of the three registered raster methods (and of the users' shading
    models, :mod:`.user_shading`: Phong with ``shading``)."""

    name = ""
    mode = ""
    ui_kind = "gl"
    knob = Knob("tessellation", (1, 2, 3, 4, 6, 8, 12, 16, 24, 32), DEFAULT_LEVEL,
                "tessellation level of analytic primitives (sphere: 4L x 8L, see tessellate)")
    options = {
        "tessellation": Option(int, DEFAULT_LEVEL, "tessellation level >= 1 (the quality knob)"),
        "blinn": Option(bool, False, "Blinn-Phong (N.H)^n instead of Phong (R.S)^n"),
        "depth_bits": Option(int, 24, "depth buffer: 16 (fixed, emulated), 24 (fixed), 32 (float)",
                             DEPTH_CHOICES),
        "view": Option(str, "color", "color image or depth view (white near, black far)", ("color", "depth")),
        "near": Option(float, 0.0, "near clip plane (0: the camera's, or from the scene bounds)"),
        "far": Option(float, 0.0, "far clip plane (0: the camera's, or from the scene bounds)"),
        "interpolation": Option(str, "perspective", "varyings perspective-correct (GL) or linear in "
                                "screen space (the course's scanline formulas, GLSL noperspective)",
                                INTERPOLATIONS),
        "normals": Option(str, "smooth", "vertex normals: the tessellation's (analytic, area-weighted) "
                          "or face_mean (the course's plain mean of the incident faces' normals)",
                          NORMAL_RULES),
        "standins": Option(sti.parse_standins, "on",
                           "stand-ins for global effects where the scene needs them (gouraud, phong): on, off "
                           "(the bare local model) or a subset of envmap,blend,shadows"),
        "envmap_resolution": Option(int, sti.DEFAULT_ENV_RESOLUTION,
                                    "texels per side of each face of a dynamic environment map"),
        "shadow_resolution": Option(int, sti.DEFAULT_SHADOW_RESOLUTION, "texels per side of each shadow map"),
        "shadow_bias": Option(float, sti.DEFAULT_SHADOW_BIAS,
                              "shadow-map bias, a fraction of the scene's extent (small: acne)"),
        "envmap_iterations": Option(int, sti.DEFAULT_ENV_ITERATIONS,
                                    "parallax-correction steps of environment-map lookups (0: seen from the "
                                    "object's centre)"),
        "volume_resolution": Option(int, rv.DEFAULT_RESOLUTION,
                                    "texels per side of a hypertexture's 3D density texture (its own grid "
                                    "when set)", low=2),
        "step_scale": Option(float, 1.0, "factor of the hypertextures' ray-march step (their 'step')"),
        "shells": Option(int, rf.DEFAULT_SHELLS, f"layered shells drawn for each fur (1..{rf.MAX_SHELLS})",
                         low=1),
    }

    memory_options = ("tessellation", "envmap_resolution", "shadow_resolution", "volume_resolution", "shells")

    #: Whether the method draws the stand-ins (:mod:`.raster_standins`): Gouraud and Phong; flat
    #: shading and users' shading models draw the bare local model.
    draws_standins = False

    def session(self, scene: Scene, width: int | None = None, height: int | None = None, *, ctx=None,
                max_memory=None, **options) -> RasterSession:
        """A :class:`RasterSession` drawing this method as :meth:`render` would with
        ``options`` (the same names and defaults: tessellation, blinn, depth_bits,
        interpolation, normals, standins and their knobs; ``view``, ``near`` and ``far`` are the
        draw's, not the session's), for the interactive window's GL panels (``ui_kind``
        ``"gl"``), in ``ctx`` (default: the thread's context).  Its estimate
        (:meth:`estimate_bytes` at ``width`` x ``height``, by default the scene camera's) is
        checked against the limit of :func:`workbench.core.memory.memory_limit` (``max_memory``)
        before anything is allocated (:func:`.base.check_memory`: one-line WorkbenchError)."""
        return self._session(scene, width, height, ctx, max_memory, None, options)

    def _session(self, scene: Scene, width, height, ctx, max_memory, shading, options: dict) -> RasterSession:
        opts = convert_options(self, options)
        w = int(width or scene.camera.width)
        h = int(height or scene.camera.height)
        sized = scene.with_camera(scene.camera.with_resolution(w, h))
        check_memory(self, sized, w, h, {**opts, "shading": shading}, max_memory)
        standins = self._standins(opts["standins"], opts["envmap_resolution"], opts["shadow_resolution"],
                                  opts["shadow_bias"], opts["envmap_iterations"])
        return RasterSession(scene, self.mode or self.name, tessellation=opts["tessellation"], blinn=opts["blinn"],
                             depth_bits=opts["depth_bits"], ctx=ctx, shading=shading,
                             interpolation=opts["interpolation"], normals=opts["normals"], standins=standins,
                             volume_resolution=opts["volume_resolution"], step_scale=opts["step_scale"],
                             shells=opts["shells"])

    def estimate_bytes(self, scene: Scene, width: int, height: int, *, tessellation: int = DEFAULT_LEVEL,
                       standins: str = "on", envmap_resolution: int = sti.DEFAULT_ENV_RESOLUTION,
                       shadow_resolution: int = sti.DEFAULT_SHADOW_RESOLUTION,
                       shadow_bias: float = sti.DEFAULT_SHADOW_BIAS,
                       envmap_iterations: int = sti.DEFAULT_ENV_ITERATIONS, shading=None,
                       volume_resolution: int = rv.DEFAULT_RESOLUTION, step_scale: float = 1.0,
                       shells: int = rf.DEFAULT_SHELLS, **_) -> int:
        """Triangles (:func:`.estimates.triangle_bound` at ``tessellation``), pixels, the
        stand-ins' maps (:func:`.raster_standins.standin_bytes`), the media's 3D textures
        (twice: the baked grid and its GL copy; refused above their own limit,
        :func:`.raster_volume.volume_bytes`) and the furs' meshes (:func:`.raster_fur.shell_bytes`)."""
        if not 1 <= tessellation <= MAX_LEVEL:
            raise WorkbenchError(f"method {self.name!r}: tessellation must be within 1..{MAX_LEVEL}, "
                                 f"got {tessellation}")
        opts = self._standins(standins, envmap_resolution, shadow_resolution, shadow_bias, envmap_iterations)
        volumes = self._volume_bytes(scene, volume_resolution, step_scale)
        fur = self._shell_bytes(scene, tessellation, shells)
        return fur + raster_bytes(scene, width, height, tessellation, _BYTES_PER_TRIANGLE, _BYTES_PER_PIXEL,
                            _FIXED_BYTES) + sti.standin_bytes(scene, opts, self.mode or self.name,
                                                              user_model=shading is not None) + 2 * volumes

    def _volume_bytes(self, scene: Scene, volume_resolution: int, step_scale: float) -> int:
        try:
            return rv.volume_bytes(scene, volume_resolution, step_scale)
        except WorkbenchError as e:
            raise WorkbenchError(f"method {self.name!r}: {e}") from None

    def _shell_bytes(self, scene: Scene, tessellation: int, shells: int) -> int:
        try:
            return rf.shell_bytes(scene, tessellation, shells)
        except WorkbenchError as e:
            raise WorkbenchError(f"method {self.name!r}: {e}") from None

    def _standins(self, standins, envmap_resolution, shadow_resolution, shadow_bias,
                  envmap_iterations) -> sti.StandinOptions:
        try:
            return sti.StandinOptions.parse(standins, envmap_resolution, shadow_resolution, shadow_bias,
                                            envmap_iterations)
        except WorkbenchError as e:
            raise WorkbenchError(f"method {self.name!r}: {e}") from None

    def render(self, scene: Scene, width: int, height: int, *, tessellation: int = DEFAULT_LEVEL,
               blinn: bool = False, depth_bits: int = 24, view: str = "color", near: float = 0.0,
               far: float = 0.0, shading=None, interpolation: str = "perspective",
               normals: str = "smooth", standins: str = "on",
               envmap_resolution: int = sti.DEFAULT_ENV_RESOLUTION,
               shadow_resolution: int = sti.DEFAULT_SHADOW_RESOLUTION,
               shadow_bias: float = sti.DEFAULT_SHADOW_BIAS,
               envmap_iterations: int = sti.DEFAULT_ENV_ITERATIONS,
               volume_resolution: int = rv.DEFAULT_RESOLUTION, step_scale: float = 1.0,
               shells: int = rf.DEFAULT_SHELLS) -> RenderResult:
        if not 1 <= tessellation <= MAX_LEVEL:
            raise WorkbenchError(f"method {self.name!r}: tessellation must be within 1..{MAX_LEVEL}, "
                                 f"got {tessellation}")
        if near < 0 or far < 0 or (near and far and far <= near):
            raise WorkbenchError(f"method {self.name!r}: need 0 < near < far, got near={near}, far={far}")
        opts = self._standins(standins, envmap_resolution, shadow_resolution, shadow_bias, envmap_iterations)
        self._volume_bytes(scene, volume_resolution, step_scale)
        self._shell_bytes(scene, tessellation, shells)
        session, created = session_for(scene, self.mode or self.name, tessellation, blinn, depth_bits, shading,
                                       interpolation, normals, opts, volume_resolution, step_scale, shells)
        t0 = time.perf_counter()
        image, depth, (n, f) = session.draw(scene.camera.with_resolution(width, height),
                                            near=near or None, far=far or None, with_depth=True)
        t_draw = time.perf_counter() - t0
        gl.check_errors(session.ctx)
        timings = {"draw": t_draw, "compile": 0.0}
        if created:
            timings.update(session.timings)
        if view == "depth":
            image = depth_view(depth, n, f)
        stats = {"gl_renderer": gl.renderer_name(session.ctx), "triangles": session.n_triangles,
                 "near": n, "far": f, "depth_bits": depth_bits, "programs": len(session.programs.programs),
                 "draw_calls": len(session.draws), "session_reused": not created,
                 "interpolation": interpolation, "normals": normals, "standins": session.standins_used}
        if session.volumes:
            stats["volume_resolutions"] = [v.resolution for v in session.volumes]
        if session.furs:
            stats["shells"] = session.shells
        return RenderResult(self.name, image, timings, stats, list(session.features_used),
                            list(session.left_out), depth=depth)


class FlatRenderer(_RasterRenderer):
    name = "flat"
    support = SUPPORT["flat"]


class GouraudRenderer(_RasterRenderer):
    name = "gouraud"
    support = SUPPORT["gouraud"]
    draws_standins = True


class PhongRenderer(_RasterRenderer):
    name = "phong"
    support = SUPPORT["phong"]
    draws_standins = True
