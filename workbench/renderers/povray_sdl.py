"""Any scene as a POV-Ray 3.7 scene description (SDL): the exporter behind the ``povray`` method.

What is written, and how it maps (POV-Ray 3.7 reference, "Scene description language"):

Camera.  POV-Ray's default camera is left-handed (``right = +x``, ``up = +y``, ``direction =
+z``).  The scene's coordinates are written unchanged (right-handed, y up) and the camera is
given by its three vectors, without ``look_at`` or ``angle`` (which would re-derive them with
POV-Ray's handedness): ``direction = f``, ``right = 2 tan(fov_y / 2) aspect r``, ``up = 2
tan(fov_y / 2) u`` with ``(r, u, -f)`` the columns of ``world_from_camera``.  POV-Ray's
eye ray through the screen point ``(x, y)`` in ``[-1/2, 1/2]^2`` is ``direction + x right + y
up``, so pixel ``(i, j)`` gets ``x = (j + 1/2) / W - 1/2``, ``y = 1/2 - (i + 1/2) / H``:
exactly :meth:`workbench.scene.model.Camera.rays` (tested by projecting a point).

Geometry.  Each object kind writes its own SDL (its module's ``povray(obj, w, in_csg)``, see
:mod:`workbench.scene.kinds`, through :class:`Writer`): object-space shapes followed by
``matrix`` (``world_from_object``, transposed to POV-Ray's row-vector form).  sphere, box,
polygon (``Plane`` as its four corners), ``quadric`` ``clipped_by`` its bounds box (inside
CSG ``intersection``-ed with it), meshes as ``mesh2``, CSG as ``merge`` (the boundary of the
union: no inner surfaces), ``intersection``, ``difference``; and POV-Ray's own ``blob`` (the
same field), ``isosurface`` (the function read back from its compiled program), ``lathe``
and ``prism`` (``linear_spline``).

Local model (``local_model.py``) to ``finish``.  POV-Ray scales ambient, diffuse and
emission by ``1 - transmit`` (measured with POV-Ray 3.7.0.10), so for a material with
transmission ``kt < 1``:

=================  ==========================================================================
``ka``             ``ambient ka / (1 - kt)`` (times the pigment and ``ambient_light`` = Ia)
``kd``             ``diffuse kd / (1 - kt)``
``ks``, ``n``      ``phong ks phong_size n`` (``max(R.S, 0)^n``, the same exponent); with the
                   option ``blinn``: ``specular ks roughness 1/n`` (``max(N.H, 0)^n``)
``kr``             ``reflection kr`` (not tinted, as ours)
``kt``, ``ior``    pigment ``transmit kt`` (not tinted) and ``interior { ior }``
emission ``E``     ``emission E / (C (1 - kt))`` (POV-Ray multiplies emission by the pigment)
=================  ==========================================================================

Lights.  Point lights without falloff as plain ``light_source``; inverse-square ones with
``fade_power 2`` and a tiny ``fade_distance`` ``d0`` (POV-Ray's attenuation ``2 / (1 +
(d / d0)^2)``) and the colour times ``1 / (2 d0^2)``: ``1 / d^2`` within a relative
``(d0 / d)^2`` (``d0`` is :data:`FADE_FRACTION` of the scene's size).  Directional lights as
``parallel`` lights far away.  Area lights: their stand-ins (without the cosine lobe) and the
emitting polygon (``no_shadow``).  Shadows through transmissive surfaces are attenuated by
``transmit`` at each crossing (POV-Ray always does; the ray tracer's ``transmissive_shadows``).

Textures.  ``checker`` (planar and solid projections; the planar one as POV-Ray's 3D checker
stretched :data:`CHECKER_STRETCH` times along the projection's pole and centred on a cell so
that it only varies across the plane) and ``image`` (``uv`` on meshes with uvs, and planar)
with ``interpolate 2`` (bilinear) and ``gamma srgb``; pigment transforms map object space to
our pattern coordinates.  Everything else goes to ``left_out`` with the reason.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..scene import features as ft
from ..scene import model as m
from ..scene.kinds import kind_of, leaves
from .support import Note
from .texturing import frame

FADE_FRACTION = 1e-4
"""``fade_distance`` of inverse-square lights as a fraction of the scene's size."""
PARALLEL_DISTANCE = 1e4
"""Directional lights are placed this many scene sizes away (POV-Ray's parallel lights need a
location; nothing beyond it casts shadows)."""
CHECKER_STRETCH = 1e6
"""A planar checker is POV-Ray's 3D checker with its third axis this many scene sizes long."""


@dataclass
class Export:
    """The SDL text, the files it reads (copied beside it: ``{name in SDL: source path}``) and
    what it could not express (``"feature: reason"``)."""

    sdl: str
    files: dict[str, str] = field(default_factory=dict)
    left_out: list[Note] = field(default_factory=list)


def _v(a) -> str:
    return "<" + ", ".join(f"{float(x):.10g}" for x in a) + ">"


def _matrix(W: np.ndarray) -> str:
    """POV-Ray's ``matrix`` of a 4x4 ``world_from_object`` (column vectors): POV-Ray multiplies
    row vectors, so its 3x3 part is ``W[:3, :3]`` transposed and its last row the translation."""
    W = np.asarray(W, dtype=np.float64)
    rows = [W[:3, 0], W[:3, 1], W[:3, 2], W[:3, 3]]
    return "matrix <" + ", ".join(f"{float(x):.10g}" for r in rows for x in r) + ">"


def _affine_inverse_matrix(A: np.ndarray) -> str:
    """``matrix`` of the pigment transform whose pattern lookup is ``A`` (object point ->
    pattern point): POV-Ray evaluates a pattern at the inverse of its transform."""
    return _matrix(np.linalg.inv(A))


def scene_size(scene: m.Scene) -> float:
    """A length of the order of the scene's size (max |coordinate| of the camera, lights and
    object origins, at least 1): the scale of the light placements above."""
    pts = [scene.camera.position, scene.camera.look_at]
    for light in scene.point_lights():
        if isinstance(light, m.PointLight):
            pts.append(light.position)

    for o in scene.objects:
        pts.extend(np.asarray(x.world_from_object)[:3, 3] for x in leaves(o))
    return float(max(1.0, np.abs(np.asarray(pts, dtype=np.float64)).max()))


class Writer:
    """Writes one scene's SDL; object kinds write theirs through it (``povray(obj, w,
    in_csg)``, see :mod:`workbench.scene.kinds`): :meth:`vec`, :meth:`num`, :meth:`matrix`,
    :meth:`texture` (pigment, finish, interior of a material by name), :meth:`leave` (a
    note for ``left_out``) and :meth:`shape` (any object: CSG operands)."""

    def __init__(self, scene: m.Scene, blinn: bool):
        self.scene, self.blinn = scene, blinn
        self.size = scene_size(scene)
        self.out = Export("")
        self.noted: set[Note] = set()

    def leave(self, feature: str, reason: str):
        """A note for ``left_out`` (once)."""
        note = Note(feature, reason)
        if note not in self.noted:
            self.noted.add(note)
            self.out.left_out.append(note)

    # ------------------------------------------------------------------ materials
    def pigment(self, mat: m.Material) -> str:
        t = mat.kt
        col = np.asarray(mat.color, dtype=np.float64)
        tex = mat.texture
        plain = f"pigment {{ color rgbt {_v([*col, t])} }}"
        if tex is None:
            return plain
        if tex.kind == "checker" and tex.projection in ("planar", "solid"):
            c0, c1 = (col * np.asarray(c) for c in tex.colors)
            return (f"pigment {{ checker color rgbt {_v([*c0, t])} color rgbt {_v([*c1, t])} "
                    f"{_affine_inverse_matrix(self.pattern_map(tex))} }}")
        if tex.kind == "image" and tex.projection in ("planar", "uv"):
            name = f"tex{len(self.out.files)}{Path(tex.path).suffix.lower()}"
            self.out.files[name] = tex.path
            kind = {".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg", ".tga": "tga", ".ppm": "ppm"}.get(
                Path(tex.path).suffix.lower())
            if kind is not None:
                img = (f"image_map {{ {kind} \"{name}\" gamma srgb interpolate 2 "
                       f"transmit all {t:.10g} }}")
                if tex.projection == "uv":  # pattern = scale * uv
                    A = np.diag([tex.scale, tex.scale, 1.0, 1.0])
                    return f"pigment {{ uv_mapping {img} {_affine_inverse_matrix(A)} }}"
                return f"pigment {{ {img} {_affine_inverse_matrix(self.pattern_map(tex))} }}"
        self.leave(ft.TEXTURES, f"{tex.kind} texture ({tex.projection} projection) of "
                   f"{mat.name!r} not expressed in POV-Ray (its plain colour used)")
        return plain

    def pattern_map(self, tex) -> np.ndarray:
        """(4, 4) affine map from object space to POV-Ray pattern space: ``scale (P - c)``
        (solid) or ``(scale u, scale v, w / L + 1/2)`` (planar, ``u, v`` as
        :func:`workbench.renderers.texturing.project`, ``w`` along the pole, ``L`` =
        :data:`CHECKER_STRETCH` scene sizes: the third coordinate stays inside one cell)."""
        c = np.asarray(tex.center, dtype=np.float64)
        A = np.eye(4)
        if tex.projection == "solid":
            A[:3, :3] *= tex.scale
        else:
            sp, se, w = frame(tex.pole, tex.equator)
            A[0, :3], A[1, :3] = tex.scale * se, tex.scale * w
            A[2, :3] = sp / (CHECKER_STRETCH * self.size)
            A[2, 3] = 0.5
        A[:3, 3] += -A[:3, :3] @ c
        return A

    def finish(self, mat: m.Material) -> str:
        t = mat.kt
        scale = 1.0 / (1.0 - t) if t < 1.0 else 0.0
        if t >= 1.0 and (mat.ka > 0 or mat.kd > 0 or mat.is_emitter):
            self.leave(ft.REFRACTION, f"ambient, diffuse and emission of {mat.name!r} (kt = 1): "
                       "POV-Ray scales them by 1 - transmit")
        parts = [f"ambient {mat.ka * scale:.10g}", f"diffuse {mat.kd * scale:.10g}"]
        if mat.ks > 0:
            if self.blinn:
                parts.append(f"specular {mat.ks:.10g} roughness {1.0 / max(mat.shininess, 1e-300):.10g}")
            else:
                parts.append(f"phong {mat.ks:.10g} phong_size {mat.shininess:.10g}")
        if mat.kr > 0:
            parts.append(f"reflection {mat.kr:.10g}")
        if mat.is_emitter:
            col = np.asarray(mat.color, dtype=np.float64)
            E = np.asarray(mat.emission, dtype=np.float64)
            if mat.texture is not None or np.any((E > 0) & (col <= 0)):
                self.leave(ft.EMITTERS, f"emission of {mat.name!r} (POV-Ray multiplies emission by the "
                           "pigment: a textured or black colour cannot carry it)")
            else:
                parts.append(f"emission rgb {_v(np.where(col > 0, E / np.maximum(col, 1e-300), 0.0) * scale)}")
        return "finish { " + " ".join(parts) + " }"

    def texture(self, name: str, transform: str = "") -> str:
        """``texture`` (pigment, finish, then ``transform`` if given) and ``interior``."""
        mat = self.scene.materials[name]
        for f, on, why in ((ft.BUMP, mat.bump is not None, "bump map"),
                           (ft.OPACITY, mat.opacity is not None, "opacity map"),
                           (ft.ENVIRONMENT, mat.environment, "environment mapping"),
                           (ft.ABSORPTION, mat.kt > 0 and max(mat.absorption) > 0, "Beer-Lambert absorption")):
            if on:
                self.leave(f, f"{why} of {name!r} not exported to POV-Ray")
        s = f"texture {{ {self.pigment(mat)} {self.finish(mat)} {transform}}}"
        if mat.kt > 0:
            s += f" interior {{ ior {mat.ior:.10g} }}"
        return s

    # ------------------------------------------------------------------ for the kinds
    def vec(self, a) -> str:
        """``<x, y, z>`` (any length) with 10 significant digits."""
        return _v(a)

    def num(self, x) -> str:
        """A number with 10 significant digits."""
        return f"{float(x):.10g}"

    def matrix(self, W) -> str:
        """``matrix <...>`` of a (4, 4) ``world_from_object`` (:func:`_matrix`)."""
        return _matrix(W)

    def shape(self, o: m.SceneObject, in_csg: bool) -> str:
        """The object's SDL, written by its kind's ``povray(o, w, in_csg)`` (shape in object
        space, texture, ``matrix``); a kind that cannot express the object returns None and
        it is left out (noted)."""
        write = getattr(kind_of(o), "povray", None)  # optional for a plugin kind
        sdl = None if write is None else write(o, self, in_csg)
        if sdl is None:
            self.leave(kind_of(o).FEATURE, f"{o.kind} object kind not exported to POV-Ray")
            return ""
        return sdl

    # ------------------------------------------------------------------ lights, camera
    def light(self, light) -> str:
        col = np.asarray(light.color, dtype=np.float64) * light.intensity
        if isinstance(light, m.DirectionalLight):
            d = np.asarray(light.direction, dtype=np.float64)
            d = d / np.linalg.norm(d)
            far = -d * PARALLEL_DISTANCE * self.size
            return f"light_source {{ {_v(far)} color rgb {_v(col)} parallel point_at <0, 0, 0> }}"
        if light.falloff == "inverse_square":
            d0 = FADE_FRACTION * self.size
            return (f"light_source {{ {_v(light.position)} color rgb {_v(col / (2.0 * d0 * d0))} "
                    f"fade_distance {d0:.10g} fade_power 2 }}")
        return f"light_source {{ {_v(light.position)} color rgb {_v(col)} }}"

    def camera(self, width: int, height: int) -> str:
        cam = self.scene.camera
        R = np.linalg.inv(cam.camera_from_world())[:3, :3]
        r, u, f = R[:, 0], R[:, 1], -R[:, 2]
        th = np.tan(np.radians(cam.fov_y) / 2.0)
        return (f"camera {{ perspective location {_v(cam.position)} direction {_v(f)} "
                f"right {_v(2.0 * th * width / height * r)} up {_v(2.0 * th * u)} }}")


def export(scene: m.Scene, width: int, height: int, *, max_trace_level: int = 5,
           adc_bailout: float = 1e-3, blinn: bool = False) -> Export:
    """The scene as POV-Ray 3.7 SDL for a ``width`` x ``height`` image.

    ``max_trace_level`` (POV-Ray's, primary rays = level 1, as the ray tracer's ``max_depth``)
    and ``adc_bailout`` (POV-Ray's adaptive depth control: a ray whose weight falls below it
    is not traced, as the ray tracer's ``threshold``) go to ``global_settings`` with
    ``assumed_gamma 1`` (linear colours throughout; the output is written with
    ``File_Gamma=1.0`` by the caller).
    """
    w = Writer(scene, blinn)
    parts = ["#version 3.7;",
             f"global_settings {{ assumed_gamma 1.0 max_trace_level {int(max_trace_level)} "
             f"adc_bailout {adc_bailout:.10g} ambient_light rgb {_v(scene.ambient)} }}",
             f"background {{ color rgb {_v(scene.background)} }}",
             w.camera(width, height)]
    if scene.environment is not None:
        w.leave(ft.ENVIRONMENT, f"the environment ({scene.environment.kind}) is not exported: "
                "escaping rays see the background colour")
    for light in scene.point_lights():
        if isinstance(light, m.PointLight) and light.cosine_normal is not None:
            w.leave(ft.AREA_LIGHTS, "stand-in point lights without their cosine lobe "
                    "(POV-Ray has no Lambertian point light)")
        parts.append(w.light(light))
    for light in scene.lights:
        if isinstance(light, m.AreaLight):
            v = np.asarray(light.vertices)
            pts = ", ".join(_v(p) for p in [*v, v[0]])
            parts.append(f"polygon {{ {len(v) + 1}, {pts} pigment {{ color rgb <1, 1, 1> }} "
                         f"finish {{ ambient 0 diffuse 0 emission rgb {_v(light.radiance)} }} no_shadow }}")
    for o in scene.objects:
        parts.append(w.shape(o, False))
    w.out.sdl = "\n".join(p for p in parts if p) + "\n"
    return w.out
