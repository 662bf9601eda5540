"""Users' shading models: a GLSL file defining one function becomes a method, ``glsl:FILE``.

The file defines (GLSL 3.30, no ``#version`` line)::

    vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m)

``P`` the world-space point, ``N`` the unit shading normal (towards the viewer), ``V`` the unit
vector towards the viewer, ``L`` the unit vector towards the light, ``m`` the material (fields
``color`` (times the texture), ``emission``, ``ka``, ``kd``, ``ks``, ``shininess``, ``kr``).  It
returns the light reflected towards ``V`` per unit light colour; the Phong method's fragment
shader calls it per light in place of the local model::

    I = E + ka C Ia + sum_l I_l(P) shade(P, N, V, L_l, m)

(``shaders/include/user_model.glsl``: the same light colours, falloffs and area-light lobes as
the built-in local model).  Everything else is the ``phong`` method's: tessellation (the
quality knob), textures, bump and opacity maps, environment reflection, options.

Parameters: a line ``#pragma parameter NAME DEFAULT [help text]`` declares a float option
``NAME`` of the method (``--set NAME=VALUE``), compiled in as ``#define NAME VALUE`` before
the user's code (GLSL compilers ignore unknown pragmas, so the file stays plain GLSL).

The user's text is appended to the fragment stage after a ``#line 1 <n>`` directive (``n``
its source-string number), so that a compiler message ``n:LINE(COL): error: ...`` (Mesa's
format) maps to the user's own line: :meth:`ShadingProgram.compile_error` turns it into one
line ``FILE:LINE: error: ...``, never the generated source.

A method name ``glsl:PATH`` is resolved by :func:`workbench.renderers.base.get_renderer`
(a new renderer per call: nothing is registered or cached here; the raster session cache
keys sessions by the program's source text, so an edited file is recompiled).  For a UI
file picker: :func:`method_name` (validated name of a file) and :func:`renderer_from_path`.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from ..core.errors import ShaderSourceError, WorkbenchError
from ..core.resources import data_dir
from ..scene.model import Scene
from .base import USER_PREFIX as PREFIX, Option, RenderResult
from .raster import SUPPORT, RasterSession, _RasterRenderer
from .raster_shaders import base_defines, build_source

FUNCTION = "shade"
SIGNATURE = "vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m)"
#: Largest user file read (bytes): a shading model is a page of code, not a data file.
MAX_BYTES = 1 << 20

_COMMENTS = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_DEFINITION = re.compile(r"\bvec3\s+" + FUNCTION + r"\s*\(")
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
#: Mesa's compiler messages: ``SOURCE:LINE(COLUMN): [preprocessor ]error: TEXT``.
_MESA_ERROR = re.compile(r"^(\d+):(\d+)\((\d+)\): ((?:preprocessor )?error): (.*)$", re.M)


@dataclass(frozen=True)
class Parameter:
    """A ``#pragma parameter NAME DEFAULT [help]`` of a user's file (``line``: where)."""

    name: str
    default: float
    help: str
    line: int


@dataclass(frozen=True)
class ShadingModel:
    """A user's shading model as read from ``path`` (absolute): its text and parameters."""

    path: str
    text: str
    parameters: tuple[Parameter, ...]


@dataclass(frozen=True)
class ShadingProgram:
    """A shading model with its parameter values: what a raster session compiles
    (``RasterSession(shading=...)``, ``ProgramCache.get(user=...)``).

    values : ``((name, value), ...)`` in the order of ``model.parameters``.
    """

    model: ShadingModel
    values: tuple[tuple[str, float], ...]

    @property
    def key(self) -> tuple:
        """Tells programs and sessions apart: the file, its text and the values."""
        return (self.model.path, self.model.text, self.values)

    def source(self, number: int) -> str:
        """The text appended to the fragment stage: the parameters' ``#define``s, then the
        user's file as source string ``number`` from its line 1."""
        lines = [f"#define {k} {float(v)!r}" for k, v in self.values]
        lines.append(f"#line 1 {number}")
        return "\n".join(lines) + "\n" + self.model.text + "\n"

    def compile_error(self, log: str, names: list[str], ctx) -> ShaderSourceError:
        """One line for a program that failed to compile with this model (``log``: the
        driver's message, ``names``: the source strings before the user's, ``ctx``: the
        moderngl context).

        Mesa reports some errors (an undeclared name, for one) with source-string number 0
        whatever ``#line`` said, so the user's line cannot always be told from the log of
        the whole shader: the model is compiled again alone (``shaders/user_check.frag``, the
        user's text as source string 0 after a fixed prelude), where every message about
        source 0 is the user's.  The first becomes ``FILE:LINE: error: ...`` (no column: Mesa's
        columns are not the characters' (a token 4 spaces in is reported at 2)); a call that
        links to no ``shade`` names the required signature; a model that compiles alone but
        not inside the workbench's shader (e.g. a macro clashing with the workbench's) gets
        the first error of the whole shader with the source string it hit.
        """
        path = self.model.path
        alone = _compile_alone(self, ctx)
        if alone is not None:
            errors = _MESA_ERROR.findall(alone)
            for src, line, col, kind, text in errors:
                if int(src) == 0:
                    return ShaderSourceError(f"{path}:{line}: {kind}: {text.strip()}")
            detail = next((ln.strip() for ln in alone.splitlines() if "error" in ln.lower()), "")
            if FUNCTION in detail or not errors:
                return ShaderSourceError(f"{path}: {FUNCTION}() must be defined as {SIGNATURE} "
                                         f"(linker: {detail or 'no message from the driver'})")
        errors = _MESA_ERROR.findall(log)
        if errors:
            src, line, col, kind, text = errors[0]
            where = names[int(src)] if int(src) < len(names) else path
            return ShaderSourceError(f"{path}: the shading model breaks the workbench's shader "
                                     f"({where}:{line}:{col}: {kind}: {text.strip()})")
        detail = next((ln.strip() for ln in log.splitlines() if "error" in ln.lower()), "no message from the driver")
        return ShaderSourceError(f"{path}: the shading model does not compile ({detail})")


def _compile_alone(program: ShadingProgram, ctx) -> str | None:
    """The driver's log of ``shaders/user_check.*`` with the model appended as source string
    0 (None: it compiled and linked)."""
    fs = build_source("user_check.frag", base_defines())
    fs += "\n".join(f"#define {k} {float(v)!r}" for k, v in program.values)
    fs += "\n#line 1 0\n" + program.model.text + "\n"
    try:
        ctx.program(vertex_shader=build_source("user_check.vert", {}), fragment_shader=fs).release()
    except Exception as e:  # moderngl's Error carries the driver's log
        return str(e)
    return None

def _parameter(path: str, lineno: int, words: list[str], rest: str) -> Parameter:
    where = f"{path}:{lineno}"
    if len(words) < 4:
        raise WorkbenchError(f"{where}: expected '#pragma parameter NAME DEFAULT [help]'")
    name = words[2]
    if not _IDENTIFIER.match(name) or name.startswith("gl_"):
        raise WorkbenchError(f"{where}: parameter name {name!r} is not a GLSL identifier")
    if name in _RasterRenderer.options:
        raise WorkbenchError(f"{where}: parameter {name!r} clashes with the method option of that name")
    try:
        default = float(words[3])
    except ValueError:
        raise WorkbenchError(f"{where}: parameter {name!r}: default {words[3]!r} is not a number") from None
    if not math.isfinite(default):
        raise WorkbenchError(f"{where}: parameter {name!r}: default must be finite, got {words[3]!r}")
    return Parameter(name, default, rest, lineno)


def bundled_examples() -> dict[str, Path]:
    """The example shading models installed with the workbench (``examples/shading/*.glsl``),
    by file stem: ``glsl:toon`` names ``examples/shading/toon.glsl`` in a checkout or a wheel."""
    return {f.stem: f for f in sorted((data_dir("examples") / "shading").glob("*.glsl"))}


def resolve_path(path: str | Path) -> Path:
    """The file a ``glsl:`` method names: ``path`` itself when it exists, else, for a bare name
    without a folder (``toon`` or ``toon.glsl``), the bundled example of that stem.

    Raises
    ------
    WorkbenchError
        One line naming the missing file (and the bundled examples, for a bare name).
    """
    p = Path(path).expanduser()
    if p.exists():
        return p
    bare = len(p.parts) == 1 and p.suffix in ("", ".glsl")
    examples = bundled_examples() if bare else {}
    if p.stem in examples:
        return examples[p.stem]
    hint = f" (bundled examples: {', '.join(examples)})" if bare and examples else ""
    raise WorkbenchError(f"shading model {str(path)!r}: no such file{hint}")


def load_model(path: str | Path) -> ShadingModel:
    """Read and check a user's shading model (exists, is readable UTF-8 text of at most
    :data:`MAX_BYTES`, defines ``shade``, declares valid parameters).

    Raises
    ------
    WorkbenchError
        One line naming the file and what is wrong.
    """
    p = resolve_path(path)
    if not p.is_file():
        raise WorkbenchError(f"shading model {str(path)!r}: not a file")
    p = p.resolve()
    try:
        if p.stat().st_size > MAX_BYTES:
            raise WorkbenchError(f"{p}: {p.stat().st_size} bytes; a shading model is at most {MAX_BYTES}")
        text = p.read_text(encoding="utf-8")
    except OSError as e:
        raise WorkbenchError(f"{p}: cannot read the shading model ({e.strerror or e})") from None
    except UnicodeDecodeError:
        raise WorkbenchError(f"{p}: not a UTF-8 text file") from None
    params: list[Parameter] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        words = line.split()
        if words[:1] == ["#version"]:
            raise WorkbenchError(f"{p}:{lineno}: no #version line: the model is part of the "
                                 f"workbench's GLSL 3.30 shader")
        if words[:2] == ["#pragma", "parameter"]:
            rest = line.split(None, 4)[4].strip() if len(words) > 4 else ""
            params.append(_parameter(str(p), lineno, words, rest))
    names = [q.name for q in params]
    if len(set(names)) != len(names):
        raise WorkbenchError(f"{p}: parameter declared twice ({', '.join(sorted({n for n in names if names.count(n) > 1}))})")
    if not _DEFINITION.search(_COMMENTS.sub(" ", text)):
        raise WorkbenchError(f"{p}: no function {SIGNATURE} (the function a shading model defines)")
    return ShadingModel(str(p), text, tuple(params))


class UserShadingRenderer(_RasterRenderer):
    """The Phong method with a user's shading model (built per :func:`renderer_from_path`)."""

    mode = "phong"
    support = SUPPORT["phong"]

    def __init__(self, model: ShadingModel, name: str):
        self.model = model
        self.name = name
        self.options = dict(_RasterRenderer.options)
        for q in model.parameters:
            self.options[q.name] = Option(float, q.default, q.help or f"parameter of {Path(model.path).name}")

    def session(self, scene: Scene, width: int | None = None, height: int | None = None, *, ctx=None,
                max_memory=None, **options) -> RasterSession:
        """A Phong :class:`~.raster.RasterSession` with the user's model at its parameters'
        values in ``options`` (defaults: theirs; the other options and the memory check as
        :meth:`.raster._RasterRenderer.session`), for the interactive window's GL panel; a
        compile error raises :class:`WorkbenchError` naming the user's file and line."""
        values = tuple((q.name, float(options.pop(q.name, q.default))) for q in self.model.parameters)
        return self._session(scene, width, height, ctx, max_memory, ShadingProgram(self.model, values), options)

    def render(self, scene: Scene, width: int, height: int, **options) -> RenderResult:
        values = tuple((q.name, float(options.pop(q.name, q.default))) for q in self.model.parameters)
        result = super().render(scene, width, height, shading=ShadingProgram(self.model, values), **options)
        result.stats["shading_model"] = self.model.path
        return result


def renderer_from_path(path: str | Path, name: str | None = None) -> UserShadingRenderer:
    """A renderer for the shading model in ``path`` (``name``: the method name it reports,
    ``glsl:PATH`` by default).  Raises :class:`WorkbenchError` (one line) for a missing,
    unreadable or invalid file; compile errors come at the first render."""
    return UserShadingRenderer(load_model(path), name or PREFIX + str(path))


def method_name(path: str | Path) -> str:
    """The method name of the shading model in ``path`` (``glsl:`` + its absolute path),
    after checking the file (:func:`load_model`): what a UI puts in its method list."""
    return PREFIX + load_model(path).path

