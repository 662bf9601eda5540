"""Shader files, ``#include`` resolution, ``#define`` injection and the program cache.

Shaders live in ``shaders/*.vert|frag`` with shared code in ``shaders/include/*.glsl``.  The
only text processing is:

* an ``#include "name.glsl"`` directive line is replaced by that file (each file once per
  program), bracketed by ``#line`` directives so that compiler messages give the right line
  and source-string number (see :func:`source_names`);
* the ``#define``s of a variant are inserted right after ``#version``, followed by
  ``#line 2 0``.

:func:`material_defines` is the one function that decides, from the scene's needs and the
material, which code is compiled (values as literals, or as uniforms in the live variants
drawn while a slider edits them: :func:`material_uniforms`, :func:`light_uniforms`); :class:`ProgramCache` keys programs by (shader name,
defines).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..core.resources import data_dir
from ..core.tol import tol
from ..scene import features as ft
from ..scene.model import DirectionalLight, Material, Scene

SHADER_DIR = data_dir("shaders")
INCLUDE_DIR = SHADER_DIR / "include"

PROJ = {"uv": 0, "planar": 1, "cylindrical": 2, "spherical": 3, "solid": 4}
KIND = {"checker": 1, "bricks": 2, "marble": 3, "wood": 4, "grid": 5, "image": 6, "noise": 7,
        "waves": 8, "constant": 9}
ENV_KIND = {"sky": 1, "image": 2}
MODES = {"flat": "MODE_FLAT", "gouraud": "MODE_GOURAUD", "phong": "MODE_PHONG"}


def source_names(stage_file: str) -> list[str]:
    """Source-string numbers used in ``#line`` directives: 0 is the stage file, then each
    include in order of first appearance."""
    names = [stage_file]
    _resolve(SHADER_DIR / stage_file, names, set())
    return names


def _resolve(path: Path, names: list[str], seen: set[str]) -> str:
    """File text with its ``#include`` lines replaced by the included files (once each)."""
    out = []
    number = names.index(path.name) if path.name in names else 0
    for lineno, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        words = line.split()
        if len(words) == 2 and words[0] == "#include" and words[1].startswith('"') and words[1].endswith('"'):
            inc = words[1][1:-1]
            if inc in seen:
                continue
            seen.add(inc)
            if inc not in names:
                names.append(inc)
            inc_path = INCLUDE_DIR / inc
            if not inc_path.is_file():
                raise WorkbenchError(f"{path.name}:{lineno}: include file not found: {inc_path}")
            out.append(f"#line 1 {names.index(inc)}")
            out.append(_resolve(inc_path, names, seen))
            out.append(f"#line {lineno + 1} {number}")
        else:
            out.append(line)
    return "\n".join(out)


def build_source(stage_file: str, defines: dict[str, object]) -> str:
    """The full text of one shader stage: defines injected after ``#version``, then ``#line``,
    includes resolved."""
    names = [stage_file]
    text = _resolve(SHADER_DIR / stage_file, names, set())
    first, _, rest = text.partition("\n")
    if not first.startswith("#version"):
        raise WorkbenchError(f"{stage_file}: first line must be #version")
    lines = [first] + [f"#define {k} {v}".rstrip() for k, v in sorted(defines.items())]
    lines.append("#line 2 0")
    return "\n".join(lines) + "\n" + rest + "\n"


def _float(x) -> str:
    """A GLSL float literal of the float32 rounding of ``x`` (the value a uniform would hold:
    the shortest decimal of that float32's exact value parses back to it)."""
    return repr(float(np.float32(x)))


def _vec3(v) -> str:
    return "vec3(" + ", ".join(_float(x) for x in v) + ")"


def _mapping_defines(prefix: str, m) -> dict[str, object]:
    """Kind, projection and the map's constants as literals: ``<prefix>_MAPPING`` (a GLSL
    ``Mapping(center, sp, se, w, scale, width)``), and per map ``TEX_COLOR0/1``,
    ``BUMP_STRENGTH``, ``OPACITY_VALUE`` and ``OPACITY_HAS_ALPHA`` (1: an image's alpha channel,
    0: its luminance)."""
    from . import texturing as tx
    sp, se, w = tx.frame(m.pole, m.equator)
    width = m.width if prefix == "OPACITY" else m.mortar
    d = {f"{prefix}_KIND": KIND[m.kind], f"{prefix}_PROJ": PROJ[m.projection],
         f"{prefix}_MAPPING": f"Mapping({_vec3(m.center)}, {_vec3(sp)}, {_vec3(se)}, {_vec3(w)}, "
                              f"{_float(m.scale)}, {_float(width)})"}
    if prefix == "TEX":
        d["TEX_COLOR0"], d["TEX_COLOR1"] = _vec3(m.colors[0]), _vec3(m.colors[1])
    elif prefix == "BUMP":
        d["BUMP_STRENGTH"] = _float(m.strength)
    else:
        d["OPACITY_VALUE"] = _float(m.value)
        d["OPACITY_HAS_ALPHA"] = _float(m.kind == "image" and tx.has_alpha(m.path))
    return d


def base_defines() -> dict[str, object]:
    """Constants every program gets (tolerances from the one ``tol`` object)."""
    return {"TOL_ZERO": f"{tol.zero:.6e}", "TOL_NORMAL_CANCEL": f"{tol.normal_cancel:.6e}",
            "TOL_BUMP_STEP": f"{tol.bump_step:.6e}"}


def light_values(light) -> tuple[np.ndarray, np.ndarray]:
    """(pos, color) of one point or directional light as the shaders use them: the position,
    or the direction towards a directional light; ``color * intensity``."""
    color = np.asarray(light.color, dtype=np.float64) * light.intensity
    if isinstance(light, DirectionalLight):
        return -np.asarray(light.direction, dtype=np.float64), color
    return np.asarray(light.position, dtype=np.float64), color


def light_kind(light) -> tuple:
    """What a light compiles to besides its values (:func:`light_values`): the flags POINT,
    INV_SQ, LOBE and the lobe normal.  Lights of equal kinds share a live program."""
    if isinstance(light, DirectionalLight):
        return (False, False, None)
    lobe = light.cosine_normal
    return (True, light.falloff == "inverse_square", None if lobe is None else tuple(float(x) for x in lobe))


def light_list(lights, live: bool = False) -> str:
    """Body of the ``FOR_EACH_LIGHT(X)`` macro: ``X(POINT, INV_SQ, LOBE, pos, color,
    lobe_normal)`` per light, as GLSL literals (``lighting.glsl`` folds them: each light
    compiles to its own arithmetic, with no uniform read).  ``pos`` is the position, or the
    direction towards a directional light; ``color`` is ``color * intensity``
    (:func:`light_values`).  ``live``: ``pos`` and ``color`` of light ``i`` are the uniforms
    ``u_light_pos[i]`` and ``u_light_color[i]`` instead (:func:`light_uniforms`; the flags and
    the lobe normal stay literals)."""
    def flag(b: bool) -> str:
        return "true" if b else "false"
    items = []
    for i, light in enumerate(lights):
        point, inv_sq, lobe = light_kind(light)
        pos, color = light_values(light)
        where, what = ((f"u_light_pos[{i}]", f"u_light_color[{i}]") if live
                       else (_vec3(pos), _vec3(color)))
        items.append(f"X({flag(point)}, {flag(inv_sq)}, {flag(lobe is not None)}, {where}, "
                     f"{what}, {_vec3(np.zeros(3) if lobe is None else lobe)})")
    return " ".join(items)


#: Material fields a live program reads from uniforms (``u_mat_<field>``).
LIVE_MATERIAL_FIELDS = ("color", "emission", "ka", "kd", "ks", "kr", "shininess")


def material_uniforms(material: Material) -> dict[str, object]:
    """Uniform values of a live-material program (``LIVE_MATERIAL``, :func:`material_defines`)."""
    out: dict[str, object] = {}
    for k in LIVE_MATERIAL_FIELDS:
        v = getattr(material, k)
        out[f"u_mat_{k}"] = tuple(float(x) for x in v) if k in ("color", "emission") else float(v)
    return out


def light_uniforms(lights) -> dict[str, np.ndarray]:
    """Uniform values of a live-lights program (``LIVE_LIGHTS``): (N, 3) float32 arrays."""
    pos = np.zeros((len(lights), 3), np.float32)
    color = np.zeros((len(lights), 3), np.float32)
    for i, light in enumerate(lights):
        pos[i], color[i] = light_values(light)
    return {"u_light_pos": pos, "u_light_color": color}


def material_defines(scene: Scene, material: Material, mode: str, *, n_lights: int,
                     has_uv: bool, blinn: bool, depth_bits: int, allow_bump: bool,
                     live_material: bool = False, live_lights: bool = False,
                     needs: frozenset[str] | None = None, user_model: bool = False,
                     screen_space: bool = False, standins=None) -> dict[str, object]:
    """The ``#define``s of one draw: what the scene needs and this material uses, nothing else.

    ``MODE_*`` (flat, gouraud, phong); the scene's ambient and the material's constants as
    literals (``SCENE_AMBIENT``, ``MAT_COLOR``, ``MAT_EMISSION``, ``MAT_KA``, ``MAT_KD``,
    ``MAT_KS``, ``MAT_KR``, ``MAT_SHININESS``: llvmpipe reads uniforms per fragment, literals
    fold); ``N_LIGHTS`` and ``FOR_EACH_LIGHT(X)`` (:func:`light_list`
    of the scene's first ``n_lights`` point and directional lights, their data compiled in;
    empty for a material with ``kd = ks = 0``, which no light changes),
    ``SPECULAR`` for a material with
    ``ks > 0`` (and ``BLINN`` when asked), ``HAS_UV`` (mesh uvs), ``TEX_KIND/TEX_PROJ``, ``BUMP_KIND/BUMP_PROJ``
    (only when ``allow_bump``: per-fragment normals), ``OPACITY_KIND/OPACITY_PROJ``,
    ``ENV_MAP`` + ``ENV_KIND`` for environment-mapped materials, ``DEPTH_LEVELS`` for an
    emulated 16-bit depth buffer.

    Live variants, drawn while a slider edits values (the program then serves every value, so
    an edit sets uniforms instead of compiling): ``live_material`` makes the ``MAT_*``
    constants the uniforms ``u_mat_*`` (``LIVE_MATERIAL``, :func:`material_uniforms`) and
    compiles what any value of them needs (the lights, ``SPECULAR``, ``ENV_MAP`` for an
    environment-mapped material, whatever kd, ks and kr are); ``live_lights`` reads the lights'
    positions and colours from uniform arrays (``LIVE_LIGHTS``, :func:`light_uniforms`).
    ``needs``: ``ft.scene_needs(scene)`` when the caller has it.  ``user_model``: a user's shading
    model replaces the local model (``USER_MODEL``, ``shaders/include/user_model.glsl``; the
    lights are compiled in whatever kd and ks are, since the user's model may use neither).
    ``screen_space``: ``SCREEN_SPACE``, every smooth varying linear in screen space (the
    course's scanline interpolation, GLSL's ``noperspective`` made robust to near-plane
    clipping: ``shaders/include/screen_space.glsl``).
    ``standins``: the global-effect stand-ins this draw compiles (a
    :class:`~.raster_standins.DrawStandins`, or None: the bare local model), see
    :func:`standin_defines`.
    """
    needs = ft.scene_needs(scene) if needs is None else needs
    d = base_defines()
    d[MODES[mode]] = ""
    d["SCENE_AMBIENT"] = _vec3(scene.ambient)
    if live_material:
        d["LIVE_MATERIAL"] = ""
        for k in LIVE_MATERIAL_FIELDS:
            d[f"MAT_{k.upper()}"] = f"u_mat_{k}"
    else:
        d["MAT_COLOR"], d["MAT_EMISSION"] = _vec3(material.color), _vec3(material.emission)
        for k in ("ka", "kd", "ks", "kr", "shininess"):
            d[f"MAT_{k.upper()}"] = _float(getattr(material, k))
    d["N_LIGHTS"] = n_lights
    if user_model:
        d["USER_MODEL"] = ""
    if (live_material or user_model or material.kd > 0 or material.ks > 0) and n_lights > 0:
        d["FOR_EACH_LIGHT(X)"] = light_list(scene.point_lights()[:n_lights], live=live_lights)
        if live_lights:
            d["LIVE_LIGHTS"] = ""
    elif material.kd > 0 or material.ks > 0:
        d["FOR_EACH_LIGHT(X)"] = ""
    if live_material or material.ks > 0:
        d["SPECULAR"] = ""
        if blinn:
            d["BLINN"] = ""
    if has_uv:
        d["HAS_UV"] = ""
    if material.texture is not None and ft.TEXTURES in needs:
        d.update(_mapping_defines("TEX", material.texture))
    if material.bump is not None and allow_bump:
        d.update(_mapping_defines("BUMP", material.bump))
    if material.opacity is not None:
        d.update(_mapping_defines("OPACITY", material.opacity))
    if material.environment and (material.kr > 0 or live_material):
        d["ENV_MAP"] = ""
        d["ENV_KIND"] = ENV_KIND[scene.environment.kind if scene.environment else "sky"]
    if depth_bits == 16:
        d["DEPTH_LEVELS"] = ""
    if screen_space:
        d["SCREEN_SPACE"] = ""
    if standins is not None:
        d.update(standin_defines(material, standins, lit=bool(d.get("FOR_EACH_LIGHT(X)")),
                                 live_lights="LIVE_LIGHTS" in d))
    return d


def standin_defines(material: Material, s, *, lit: bool, live_lights: bool = False) -> dict[str, object]:
    """The ``#define``s of the stand-ins one draw compiles (``shaders/include/standins.glsl``;
    ``s`` a :class:`~.raster_standins.DrawStandins`): ``ENV_CUBE`` + ``ENV_RES`` + ``ENV_ITERATIONS``
    (the object's dynamic environment map: kr reflection), ``ENV_KT`` + ``MAT_KT`` + ``MAT_IOR`` (kt
    refraction through the same map), ``TINT_PASS`` + ``MAT_KT`` (the multiplicative pass of
    blended transparency), and for a lit material ``SHADOW_MAPS`` with the shadow atlas's
    layout (``SHADOW_RES``, ``SHADOW_COLS``, ``SHADOW_TILES``, the per-light lists
    ``SHADOW_BASE_LIST``, ``SHADOW_CUBE_LIST``, ``SHADOW_POS_LIST``, ``SHADOW_RANGE_LIST`` and the world-space
    ``SHADOW_BIAS``); with ``live_lights`` ``SHADOW_LIVE`` instead of the position and range
    lists (uniforms ``u_shadow_pos``, ``u_shadow_range``: a moved light keeps its program)."""
    d: dict[str, object] = {}
    if s.env_res > 0:
        d["ENV_CUBE"], d["ENV_RES"], d["ENV_ITERATIONS"] = "", int(s.env_res), int(s.env_iterations)
        if s.env_kt:
            d["ENV_KT"], d["MAT_KT"], d["MAT_IOR"] = "", _float(material.kt), _float(material.ior)
    if s.tint_pass:
        d["TINT_PASS"], d["MAT_KT"] = "", _float(material.kt)
    L = s.shadows
    if L is not None and lit:
        d["SHADOW_MAPS"] = ""
        d["SHADOW_RES"], d["SHADOW_COLS"], d["SHADOW_TILES"] = int(L.resolution), int(L.cols), int(L.tiles)
        d["SHADOW_BASE_LIST"] = "int[](" + ", ".join(str(int(b)) for b in L.base) + ")"
        d["SHADOW_CUBE_LIST"] = "bool[](" + ", ".join("true" if c else "false" for c in L.cube) + ")"
        if live_lights:
            d["SHADOW_LIVE"] = ""
        else:
            d["SHADOW_POS_LIST"] = "vec3[](" + ", ".join(_vec3(p) for p in L.pos) + ")"
            d["SHADOW_RANGE_LIST"] = ("vec2[](" + ", ".join(f"vec2({_float(n)}, {_float(f)})" for n, f in L.ranges)
                                      + ")")
        d["SHADOW_BIAS"] = _float(L.bias_world)
    return d


class ProgramCache:
    """moderngl programs of one context keyed by (shader name, defines); compile time summed
    in ``compile_seconds``."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.programs: dict[tuple, object] = {}
        self.compile_seconds = 0.0
        self.compiles = 0  # programs compiled so far (tests: no compile per slider frame)

    def get(self, name: str, defines: dict[str, object], user=None):
        """The program of shader ``name`` with ``defines``.  ``user``: a user's code appended
        to the fragment stage (``user.source(number)``, with ``number`` its source-string
        number in ``#line`` directives; ``user.key`` tells programs apart;
        ``user.compile_error(log, names, ctx)`` turns the driver's log into the one-line message
        raised; see :mod:`.user_shading`)."""
        import time
        key = (name, tuple(sorted((k, str(v)) for k, v in defines.items())),
               None if user is None else user.key)
        prog = self.programs.get(key)
        if prog is None:
            t0 = time.perf_counter()
            vs, fs = build_source(f"{name}.vert", defines), build_source(f"{name}.frag", defines)
            if user is not None:
                fs += user.source(len(source_names(name + ".frag")))
            try:
                prog = self.ctx.program(vertex_shader=vs, fragment_shader=fs)
            except Exception as e:  # moderngl raises its own Error with the driver log
                if user is not None:
                    raise user.compile_error(str(e), source_names(name + ".frag"), self.ctx) from None
                raise WorkbenchError(f"shader {name} failed to compile with {dict(key[1])}: {e}\n"
                                     f"(source strings: {source_names(name + '.frag')})") from None
            self.programs[key] = prog
            self.compiles += 1
            self.compile_seconds += time.perf_counter() - t0
        return prog

    def release_unused(self, used) -> list:
        """Release the programs that are not in ``used`` (programs, by identity) and are not
        live variants (those serve every value: kept for the next edit); returns the released
        programs."""
        keep = {id(p) for p in used}
        gone = []
        for key, prog in list(self.programs.items()):
            live = any(k in ("LIVE_MATERIAL", "LIVE_LIGHTS") for k, _ in key[1])
            if id(prog) not in keep and not live:
                gone.append(self.programs.pop(key))
        for prog in gone:
            prog.release()
        return gone
