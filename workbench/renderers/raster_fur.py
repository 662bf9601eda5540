"""Fur (Kajiya and Kay 1989 texels, :mod:`workbench.scene.kinds.fur`) in the raster methods:
layered shells, the real-time stand-in of Lengyel, Praun, Finkelstein and Hoppe, "Real-time
fur over arbitrary surfaces" (I3D 2001), drawn after the opaque pass (which draws the base);
the Z-buffer draws the same shells in numpy (:mod:`.zbuffer_fur`).

The shells.  ``N`` (option ``shells``) copies of the base's tessellation (object space, the
session's level), shell ``i`` scaled per axis by ``(size + o_i) / size`` with
``o_i = length (i + 1/2) / N`` (:func:`~workbench.scene.kinds.fur.shell_scales`): for a sphere
base the sphere of radius ``r + o_i``; for a box base the box of half-sizes ``b + o_i``, each
face's plane moved out by ``o_i`` and stretched to meet its neighbours (the true offset
surface of a box has rounded edges and corners: there the shell lies up to ``sqrt(3) o_i``
from the base, and the texel is evaluated at the fragment's true point, so those layers thin
out towards the tips).

A shell fragment at object-space point ``x`` (its normal ``n`` is the shell's, ``d`` the view
ray's direction)::

    D(x), T(x)     the texel of fur.density / fur_kernels.texel (GLSL: shaders/include/fur_texel.glsl,
                   the roots' hash shaders/include/hash.glsl, the value noise's lowbias32)
    a   = 1 - exp(-density min(L / |cos(d, n)|, length))      where D = 1, L = length / N
          (the path through the layer, in object space; clamped at the shell's depth at grazing
          incidence)
    J   = kd C Ia + sum_l I_l s_l (kd C sin(T, L_l) + ks max(0, cos phi_l)^shininess)
    out = (a J, a), composited over what is behind: pixel = a J + (1 - a) pixel

``I_l s_l`` the raster's lights (:func:`.raster_shaders.light_list`: colour x intensity, the
``1 / r^2`` falloff and emitter lobe where set): the ray march's source term
(:mod:`workbench.renderers.kernels.media`) with its visibility 1, since the raster has no
shadow feelers (the march's feelers against the surfaces are left out: the floor's shadow
side of the fur is lit here).  As ``N`` grows, the layers' sum tends to the march's integral
along the ray (tests/renderers/raster/test_raster_fur.py measures it), apart from the shadows.

Order: a pixel's ray crosses each (convex) shell at most twice; drawing first the back faces
from the outermost shell inwards, then the front faces from the innermost outwards, is back to
front for any camera outside the shells (instanced: one draw per side, instance ``k`` the
shell ``N - 1 - k`` then ``k``).  Several furs and the blended surfaces are ordered by their
centres' distance, as the media (:mod:`.raster_volume`).  The depth test against the opaque
pass is on, depth writes off.  The shells are drawn in the camera's pass only (the stand-ins'
shadow and environment maps show the base alone); their interpolation is GL's
perspective-correct one whatever the ``interpolation`` option.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..core.errors import WorkbenchError
from ..scene.kinds import fur as fur_kind
from ..scene.kinds import kind_of
from ..scene.model import Scene
from .estimates import triangle_bound
from .raster_shaders import _float, _vec3, base_defines, light_list

DEFAULT_SHELLS = 16
"""Shells per fur (option ``shells``)."""
MAX_SHELLS = 1024
REASON = "layered shells (N = option shells), no shadows"
"""The support tables' reason (approximated) for the raster methods and the Z-buffer."""
_BYTES_PER_VERTEX = 2 * 3 * 4 + 64
"""The GL vertex buffer (object-space point and normal, float32) and the float64 arrays it is
built from; the shells are instances of it (no copy per shell)."""


def furs(scene: Scene) -> list:
    """The scene's fur objects (kinds whose feature is texels)."""
    return [o for o in scene.objects if kind_of(o).FEATURE == fur_kind.FEATURE]


def check_shells(shells) -> int:
    """``shells`` as an int in ``1..MAX_SHELLS``; WorkbenchError (one line) otherwise."""
    if isinstance(shells, bool) or not isinstance(shells, (int, np.integer)) or not 1 <= shells <= MAX_SHELLS:
        raise WorkbenchError(f"shells must be an integer within 1..{MAX_SHELLS}, got {shells!r}")
    return int(shells)


def fur_triangles(scene: Scene, level: int) -> int:
    """Upper bound of the triangles of one shell of every fur (their bases' tessellations)."""
    fs = furs(scene)
    return triangle_bound(replace(scene, objects=type(scene.objects)(fs)), level) if fs else 0


def shell_bytes(scene: Scene, level: int, shells: int) -> int:
    """Bytes the shells add to a GL raster session: the furs' base meshes once (the ``shells``
    instances share them); checks ``shells``."""
    check_shells(shells)
    return 3 * fur_triangles(scene, level) * _BYTES_PER_VERTEX


def defines(scene: Scene, f: fur_kind.Fur, shells: int, lights) -> dict[str, object]:
    """The ``#define``s of one fur's shells (``shaders/fur_shell.*``): its texel, optics, the
    scene's ambient and lights as literals."""
    d = base_defines()
    size = np.broadcast_to(np.asarray(f.size, dtype=np.float64), (3,))
    d.update(BASE_BOX=int(f.base == "box"), SIZE=_vec3(size), LENGTH=_float(f.length),
             CELL=_float(1.0 / math.sqrt(f.strands)), THICKNESS=_float(f.thickness), DENSITY=_float(f.density),
             ALBEDO=_vec3(f.kd * np.asarray(f.color, dtype=np.float64)), KS=_float(f.ks),
             SHININESS=_float(f.shininess), N_SHELLS=int(shells), LAYER=_float(f.length / shells),
             SCENE_AMBIENT=_vec3(scene.ambient))
    if lights:
        d["FOR_EACH_LIGHT(X)"] = light_list(lights)
    return d


@dataclass
class FurDraw:
    """One fur on the GPU: the object, its program, vertex array and buffers."""

    obj: object
    prog: object
    vao: object
    buffers: tuple

    @property
    def centre(self) -> np.ndarray:
        return np.asarray(self.obj.world_from_object, dtype=np.float64)[:3, 3].copy()


def build(ctx, programs, scene: Scene, level: int, shells: int, lights) -> list[FurDraw]:
    """Upload each fur's base mesh (object space) and compile its shells' program."""
    check_shells(shells)
    out = []
    for f in furs(scene):
        P, N, F = fur_kind.base_mesh(f, level)
        vbo = ctx.buffer(np.ascontiguousarray(np.concatenate([P, N], 1), dtype="f4").tobytes())
        ibo = ctx.buffer(np.ascontiguousarray(F, dtype="i4").tobytes())
        prog = programs.get("fur_shell", defines(scene, f, shells, lights))
        out.append(FurDraw(f, prog, _vertex_array(ctx, prog, vbo, ibo), (vbo, ibo)))
    return out


def _vertex_array(ctx, prog, vbo, ibo):
    """The vertex array of a fur's mesh for ``prog`` (a sphere's program reads no normal)."""
    layout = ("3f 3f", "in_obj_position", "in_obj_normal") if "in_obj_normal" in prog else ("3f 12x", "in_obj_position")
    return ctx.vertex_array(prog, [(vbo, *layout)], ibo, index_element_size=4)


def recompile(programs, scene: Scene, draws: list[FurDraw], shells: int, lights) -> None:
    """New programs for the draws after a light edit (the lights are literals)."""
    for v in draws:
        prog = programs.get("fur_shell", defines(scene, v.obj, shells, lights))
        if prog is not v.prog:
            v.vao.release()
            v.prog = prog
            v.vao = _vertex_array(prog.ctx, prog, *v.buffers)


def draw(ctx, v: FurDraw, clip_bytes: bytes, eye, shells: int) -> None:
    """Draw fur ``v``'s shells back to front over the colour target bound by the caller (depth
    test on, depth writes off, blending ``(ONE, ONE_MINUS_SRC_ALPHA)`` set here; face culling
    left disabled on return)."""
    import moderngl
    prog = v.prog
    W = np.asarray(v.obj.world_from_object, dtype=np.float64)
    values = {"u_clip_from_world": None, "u_world_from_object": W.T,
              "u_object_from_world": np.linalg.inv(W[:3, :3]).T, "u_normal_matrix": np.linalg.inv(W[:3, :3]),
              "u_eye": np.asarray(eye, dtype=np.float64)}
    for name, value in values.items():
        if name in prog:
            prog[name].write(clip_bytes if value is None else np.ascontiguousarray(value, dtype="f4").tobytes())
    ctx.blend_func = moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA
    ctx.enable(moderngl.CULL_FACE)
    for cull, reverse in (("front", 1), ("back", 0)):  # far sides outermost first, then near sides
        ctx.cull_face = cull
        if "u_reverse" in prog:
            prog["u_reverse"].value = reverse
        v.vao.render(moderngl.TRIANGLES, instances=shells)
    ctx.cull_face = "back"
    ctx.disable(moderngl.CULL_FACE)
