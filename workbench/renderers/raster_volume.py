"""Hypertextures (Perlin and Hoffert 1989) in the raster methods: a fragment-shader ray march
through a 3D texture of the density (``shaders/volume.frag``), composited over the opaque
pass; the Z-buffer method does the same march in numpy (:mod:`.zbuffer_volume`).

The march (one model, shared with the ray caster and Whitted so that the methods converge to
each other).  In the object space of the hypertexture, the pixel's ray ``o + t d`` (world,
``d`` unit) is ``O + t D`` (``D`` not unit; ``t`` shared).  Its segment ``[t0, t1]`` is the
overlap with the bounding sphere ``|x| < R`` (R = ``bound_radius``), clipped at the camera
(``t >= 0``: the camera may be inside) and at the opaque surface behind (the depth buffer)::

    N   = max(1, ceil(L / s))          L = (t1 - t0) |D| object-space length, s = step x step_scale
    h   = (t1 - t0) / N,  x_j = O + (t0 + (j + 1/2) h) D          midpoints, j = 0 .. N-1
    D_j = the 3D texture at x_j        trilinear, texel centres tiling [-R, R]^3, clamped edges
                                       (hypertexture.density_grid / sample_grid's convention)
    tau_j = density D_j h |D|          optical depth of the step
    c_j = ramp(D_j),  a_j = albedo c_j,  J_j = (1 - a_j) emission c_j + a_j ambient
    L  += T (1 - exp(-tau_j)) J_j ;  T *= exp(-tau_j)               front to back

and the pixel is ``L + T behind``: emission-absorption with ambient in-scattering (the scene's
ambient term is the only light the medium scatters).  ``T`` is grey, so GL blending
``(ONE, SRC_ALPHA)`` of the fragment ``(L, T)`` composites it over what is drawn.  Several
media are drawn back to front by the distance of their centres (interleaved with the blended
surfaces): where their bounding spheres overlap, each is marched alone and the order is only
approximately right.

The texture's resolution is the option ``volume_resolution`` (a hypertexture with ``grid = N``
brings its own N: the exact twin of the other methods); its bytes (``grid_bytes``) are checked
against :data:`~workbench.scene.kinds.hypertexture.GRID_BYTES` before anything is baked.
The media are drawn in the camera's pass only: the stand-ins' environment and shadow maps do
not show them.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..core.errors import WorkbenchError
from ..scene.kinds import hypertexture as ht
from ..scene.kinds import kind_of
from ..scene.model import Camera, Scene
from .raster_shaders import _float, _vec3, base_defines

DEFAULT_RESOLUTION = 64
"""Texels per side of a hypertexture's 3D texture (option ``volume_resolution``)."""
REASON = ("ray-marched through a 3D texture of the density (option volume_resolution); "
          "emission-absorption with ambient in-scattering only")
"""The support tables' reason (approximated) for the raster methods and the Z-buffer."""
#: Texture units of the volume pass (after the surface pass's, raster.UNITS).
DEPTH_UNIT, DENSITY_UNIT = 7, 8


def media(scene: Scene) -> list:
    """The scene's hypertextures (participating-medium kinds but the fur, whose texels the
    raster draws as shells: :mod:`.raster_fur`)."""
    return [o for o in scene.objects if getattr(kind_of(o), "MEDIUM", False) and kind_of(o).FEATURE != "texels"]


def resolution_of(h: ht.Hypertexture, volume_resolution: int) -> int:
    """The texture resolution of ``h``: its own ``grid`` when set, else the option."""
    return int(h.grid) if h.grid else int(volume_resolution)


def volume_bytes(scene: Scene, volume_resolution: int, step_scale: float = 1.0) -> int:
    """Bytes of the scene's density textures (float32, one channel), after checking the
    options: ``volume_resolution >= 2``, ``step_scale > 0`` giving at most
    ``hypertexture.MAX_STEPS`` steps across a bounding sphere, and the textures' total within
    ``hypertexture.GRID_BYTES``.  Raises WorkbenchError (one line) otherwise."""
    if int(volume_resolution) < 2:
        raise WorkbenchError(f"volume_resolution must be >= 2, got {volume_resolution}")
    if not step_scale > 0.0:
        raise WorkbenchError(f"step_scale must be > 0, got {step_scale}")
    total = 0
    for o in media(scene):
        steps = 2.0 * ht.bound_radius(o) / (o.step * step_scale)
        if steps > ht.MAX_STEPS:
            raise WorkbenchError(f"hypertexture {o.name or ''}: step {o.step} x step_scale {step_scale} gives "
                                 f"{steps:.3g} steps across its bounding sphere, above {ht.MAX_STEPS}")
        total += ht.grid_bytes(resolution_of(o, volume_resolution))
    if total > ht.GRID_BYTES:
        raise WorkbenchError(f"hypertexture 3D textures at volume_resolution {volume_resolution} need "
                             f"{total / 2**20:.0f} MiB, above the limit of {ht.GRID_BYTES / 2**20:.0f} MiB: "
                             "lower volume_resolution (or the objects' grid)")
    return total


def back_to_front(objects: list, eye) -> list:
    """``objects`` sorted by decreasing distance of their centre (object-space origin) from ``eye``."""
    eye = np.asarray(eye, dtype=np.float64)
    return sorted(objects, key=lambda o: -float(np.linalg.norm(np.asarray(o.world_from_object)[:3, 3] - eye)))


def centre(o) -> np.ndarray:
    """World position of the medium's centre (its object-space origin)."""
    return np.asarray(o.world_from_object, dtype=np.float64)[:3, 3].copy()


def defines(scene: Scene, h: ht.Hypertexture, step_scale: float) -> dict[str, object]:
    """The ``#define``s of one medium's march (``shaders/volume.frag``): its optics and the
    scene's ambient as literals."""
    d = base_defines()
    d["RADIUS"] = _float(ht.bound_radius(h))
    d["STEP"] = _float(h.step * step_scale)
    d["DENSITY"] = _float(h.density)
    d["ALBEDO"], d["EMISSION"] = _vec3(h.albedo), _vec3(h.emission)
    d["SCENE_AMBIENT"] = _vec3(scene.ambient)
    d["N_STOPS"] = len(h.ramp)
    d["RAMP_D"] = "float[](" + ", ".join(_float(r[0]) for r in h.ramp) + ")"
    d["RAMP_C"] = "vec3[](" + ", ".join(_vec3(r[1:]) for r in h.ramp) + ")"
    return d


def scissor(camera: Camera, o, near: float) -> tuple[int, int, int, int] | None:
    """GL scissor box (x, y from the bottom, w, h) holding the projection of the medium's
    bounding cube, or None (the whole viewport) when a corner is not beyond the near plane.
    Only saves fragments: the march discards those its ray misses."""
    W = np.asarray(o.world_from_object, dtype=np.float64)
    corners = ht.bound_points(o) @ W[:3, :3].T + W[:3, 3]
    xy, depth = camera.project(corners)
    if not (depth > near).all():
        return None
    x0 = max(int(math.floor(xy[:, 0].min())) - 1, 0)
    x1 = min(int(math.ceil(xy[:, 0].max())) + 1, camera.width)
    r0 = max(int(math.floor(xy[:, 1].min())) - 1, 0)
    r1 = min(int(math.ceil(xy[:, 1].max())) + 1, camera.height)
    if x1 <= x0 or r1 <= r0:
        return (0, 0, 0, 0)
    return (x0, camera.height - r1, x1 - x0, r1 - r0)


@dataclass
class VolumeDraw:
    """One medium on the GPU: the object, its program, its density texture and empty vertex array."""

    obj: object
    prog: object
    texture: object
    vao: object
    resolution: int

    @property
    def centre(self) -> np.ndarray:
        return centre(self.obj)


def build(ctx, programs, scene: Scene, volume_resolution: int, step_scale: float) -> tuple[list[VolumeDraw], float]:
    """Bake and upload the density texture of every medium of ``scene`` (R32F, linear filter,
    clamped edges: :func:`~workbench.scene.kinds.hypertexture.density_grid`) and compile its
    march.  Returns the draws and the seconds spent baking (numpy)."""
    import moderngl
    volume_bytes(scene, volume_resolution, step_scale)  # refuses before anything is baked
    out, bake = [], 0.0
    for o in media(scene):
        res = resolution_of(o, volume_resolution)
        t0 = time.perf_counter()
        grid = ht.density_grid(o, res)
        bake += time.perf_counter() - t0
        tex = ctx.texture3d((res, res, res), 1, np.ascontiguousarray(grid, dtype="f4").tobytes(), dtype="f4")
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = tex.repeat_z = False
        prog = programs.get("volume", defines(scene, o, step_scale))
        out.append(VolumeDraw(o, prog, tex, ctx.vertex_array(prog, []), res))
    return out, bake


def draw(ctx, v: VolumeDraw, depth_texture, camera: Camera, near: float, far: float, viewport: tuple) -> None:
    """March medium ``v`` over the colour target bound by the caller (blending ``(ONE,
    SRC_ALPHA)`` set by the caller, no depth attachment), reading the opaque pass's window
    depth from ``depth_texture``."""
    import moderngl
    prog = v.prog
    world_from_object = np.asarray(v.obj.world_from_object, dtype=np.float64)
    object_from_world = np.linalg.inv(world_from_object)
    V = camera.camera_from_world()
    th = math.tan(math.radians(camera.fov_y) / 2.0)
    values = {"u_object_from_world": object_from_world.T, "u_world_from_camera": np.linalg.inv(V)[:3, :3].T,
              "u_eye": np.asarray(camera.position, dtype=np.float64),
              "u_tan": np.array([th * camera.aspect, th]), "u_viewport": np.asarray(viewport, dtype=np.float64),
              "u_near_far": np.array([near, far])}
    for name, value in values.items():
        if name in prog:
            prog[name].write(np.ascontiguousarray(value, dtype="f4").tobytes())
    for name, unit in (("u_scene_depth", DEPTH_UNIT), ("u_density", DENSITY_UNIT)):
        if name in prog:
            prog[name].value = unit
    depth_texture.use(DEPTH_UNIT)
    v.texture.use(DENSITY_UNIT)
    box = scissor(camera, v.obj, near)
    if box is not None:
        if box[2] == 0 or box[3] == 0:
            return
        ctx.scissor = (viewport[0] + box[0], viewport[1] + box[1], box[2], box[3])
    v.vao.render(moderngl.TRIANGLES, vertices=3)
    ctx.scissor = None
