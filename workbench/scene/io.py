"""Read a scene from TOML (``tomllib``) into the pure-data model, validating everything.

Every error is a :class:`SceneError` whose message names the file, the key and what was
expected; the scene is built only after every table has been checked, so a bad file never
yields a half-loaded scene.
"""
from __future__ import annotations

import tomllib
import warnings
from pathlib import Path

import numpy as np

from ..core import transform as tf
from ..core.errors import SceneWarning
from ..core.tol import tol
from . import model as m
from .kinds import KINDS, kind_of, world_bounds
from .readers import (FLOAT32_MAX, Ctx, SceneError, boolean, check_keys, file_path, matrix, num,
                      parallel, polygon_vertices, rgb, string, vec)

LARGEST_EXACT_INTEGER = 2 ** 53      # every number becomes a float64 (and float32 on the GPU)


def _where(path: list) -> str:
    """``["objects", 2, "center", 0]`` -> ``[[objects]] #3.center[0]`` (the messages' style)."""
    if not path:
        return "top level"
    head, rest = path[0], path[1:]
    if head in ("objects", "lights") and rest and isinstance(rest[0], int):
        out, rest = f"[[{head}]] #{rest[0] + 1}", rest[1:]
    elif head == "materials" and rest:
        out, rest = f"[materials.{rest[0]}]", rest[1:]
    else:
        out = f"[{head}]"
    for k in rest:
        out += f"[{k}]" if isinstance(k, int) else f".{k}"
    return out


def _numbers_fit(ctx, x, path: list) -> None:
    """Every number anywhere in the scene fits what reads it, before any section is parsed:
    floats finite and within float32 range (GL buffers, uniforms and shader literals, and the
    float32 images, are float32: 1e39 is finite in float64 and infinite on the GPU); integers
    within +-2^53 (exact as the float64 every number becomes; beyond, ``np.isfinite`` and
    int64 conversions fail)."""
    if isinstance(x, dict):
        for k, v in x.items():
            _numbers_fit(ctx, v, path + [k])
    elif isinstance(x, list):
        for i, v in enumerate(x):
            _numbers_fit(ctx, v, path + [i])
    elif isinstance(x, bool):
        return
    elif isinstance(x, int):
        if abs(x) > LARGEST_EXACT_INTEGER:
            ctx.fail(_where(path), f"integer {x} is too large (|n| <= 2^53 = {LARGEST_EXACT_INTEGER})")
    elif isinstance(x, float):
        if not np.isfinite(x):
            ctx.fail(_where(path), f"expected a finite number, got {x!r}")
        if abs(x) > FLOAT32_MAX:
            ctx.fail(_where(path), f"{x!r} is outside the float32 range |x| <= {FLOAT32_MAX:.8g} "
                                   f"(the GPU and the images are float32)")


def _image_file(ctx, t, where, key, required):
    """``path`` of an image map, opened and decoded now (Pillow, as the renderers read it), so
    a file that is not a readable image fails at load, not mid-render."""
    p = file_path(ctx, t, where, key, required)
    if p is not None:
        from PIL import Image
        try:
            with Image.open(p) as im:
                im.load()
                size = im.size
        except Exception as e:  # noqa: BLE001 -- Pillow raises many kinds for a bad file
            ctx.fail(f"{where}.{key}", f"not a readable image: {p} ({type(e).__name__}: {e})")
        if min(size) < 1:
            ctx.fail(f"{where}.{key}", f"image {p} is empty ({size[0]}x{size[1]})")
    return p


# --------------------------------------------------------------------------- sections
def _camera(ctx, t) -> m.Camera:
    w = "[camera]"
    check_keys(ctx, t, w, {"position", "look_at", "up", "fov_y", "resolution", "near", "far"},
                {"position", "look_at"})
    pos, at = vec(ctx, t, w, "position"), vec(ctx, t, w, "look_at")
    if np.linalg.norm(np.subtract(at, pos)) <= tol.degenerate * max(np.linalg.norm(at), np.linalg.norm(pos)):
        ctx.fail(f"{w}.look_at", "must differ from position (zero-length view direction)")
    up = vec(ctx, t, w, "up", (0.0, 1.0, 0.0), nonzero=True)
    if parallel(np.subtract(at, pos), up):
        ctx.fail(f"{w}.up", "is parallel to the view direction")
    res = t.get("resolution", [320, 240])
    if not (isinstance(res, list) and len(res) == 2 and all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= 16384 for x in res)):
        ctx.fail(f"{w}.resolution", f"expected [width, height], integers in 1..16384, got {res!r}")
    near = num(ctx, t, w, "near", 0.0, lo=0.0, lo_open=True) if "near" in t else None
    far = num(ctx, t, w, "far", 0.0, lo=0.0, lo_open=True) if "far" in t else None
    if near is not None and far is not None and far <= near:
        ctx.fail(f"{w}.far", f"must be greater than near ({near}), got {far}")
    return m.Camera(pos, at, up, num(ctx, t, w, "fov_y", 45.0, lo=0.0, lo_open=True, hi=179.0),
                    res[0], res[1], near, far)


def _light(ctx, t, i):
    w = f"[[lights]] #{i + 1}"
    if not isinstance(t, dict):
        ctx.fail(w, "expected a table")
    kind = string(ctx, t, w, "type", choices=("point", "directional", "area"))
    common = {"type", "color", "intensity"}
    if kind == "point":
        check_keys(ctx, t, w, common | {"position", "falloff"}, {"position"})
        return m.PointLight(vec(ctx, t, w, "position"), rgb(ctx, t, w, "color", (1.0, 1.0, 1.0)),
                            num(ctx, t, w, "intensity", 1.0, lo=0.0),
                            string(ctx, t, w, "falloff", "none", choices=("none", "inverse_square")))
    if kind == "directional":
        check_keys(ctx, t, w, common | {"direction"}, {"direction"})
        return m.DirectionalLight(tuple(tf.normalize(vec(ctx, t, w, "direction", nonzero=True)).tolist()),
                                  rgb(ctx, t, w, "color", (1.0, 1.0, 1.0)),
                                  num(ctx, t, w, "intensity", 1.0, lo=0.0))
    check_keys(ctx, t, w, common | {"vertices", "stand_in"}, {"vertices"})
    verts = polygon_vertices(ctx, t, w)
    return m.AreaLight(m._ro(verts), rgb(ctx, t, w, "color", (1.0, 1.0, 1.0)),
                       num(ctx, t, w, "intensity", 1.0, lo=0.0),
                       num(ctx, t, w, "stand_in", 1, lo=1, hi=16, integer=True))



_MAP_KEYS = {"projection", "scale", "path", "center", "pole", "equator"}


def _mapping(ctx, t, w, default_projection):
    proj = string(ctx, t, w, "projection", default_projection,
                choices=("uv", "planar", "cylindrical", "spherical", "solid"))
    pole = tuple(tf.normalize(vec(ctx, t, w, "pole", (0.0, 1.0, 0.0), nonzero=True)).tolist())
    equator = tuple(tf.normalize(vec(ctx, t, w, "equator", (1.0, 0.0, 0.0), nonzero=True)).tolist())
    if proj in ("spherical", "cylindrical") and parallel(pole, equator):
        ctx.fail(f"{w}.equator", "must not be parallel to the pole")
    return dict(projection=proj, scale=num(ctx, t, w, "scale", 1.0, lo=0.0, lo_open=True),
                center=vec(ctx, t, w, "center", (0.0, 0.0, 0.0)), pole=pole, equator=equator)


def _image_projection(ctx, t, w, kind):
    if kind == "image" and t.get("projection") == "solid":
        ctx.fail(f"{w}.projection", "an image map needs a 2D projection (uv, planar, cylindrical or "
                                    "spherical), not 'solid'")


def _texture(ctx, t, w):
    check_keys(ctx, t, w, _MAP_KEYS | {"type", "colors", "mortar"}, {"type"})
    kind = string(ctx, t, w, "type", choices=("checker", "bricks", "marble", "wood", "grid", "image"))
    _image_projection(ctx, t, w, kind)
    colors = t.get("colors", [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]])
    if not (isinstance(colors, list) and len(colors) == 2):
        ctx.fail(f"{w}.colors", "expected two colours [[r, g, b], [r, g, b]]")
    cols = tuple(rgb(ctx, {"c": c}, f"{w}.colors", "c", None) for c in colors)
    return m.Texture(kind, colors=cols, path=_image_file(ctx, t, w, "path", kind == "image"),
                     mortar=num(ctx, t, w, "mortar", 0.08, lo=0.0, hi=0.5),
                     **_mapping(ctx, t, w, "uv"))


def _bump(ctx, t, w):
    check_keys(ctx, t, w, _MAP_KEYS | {"type", "strength", "mortar"}, {"type"})
    kind = string(ctx, t, w, "type", choices=("bricks", "noise", "waves", "image"))
    _image_projection(ctx, t, w, kind)
    return m.Bump(kind, strength=num(ctx, t, w, "strength", 1.0),
                  path=_image_file(ctx, t, w, "path", kind == "image"),
                  mortar=num(ctx, t, w, "mortar", 0.08, lo=0.0, hi=0.5),
                  **_mapping(ctx, t, w, "planar"))


def _opacity(ctx, t, w):
    check_keys(ctx, t, w, _MAP_KEYS | {"type", "value", "width"}, {"type"})
    kind = string(ctx, t, w, "type", choices=("constant", "grid", "checker", "image"))
    _image_projection(ctx, t, w, kind)
    return m.Opacity(kind, value=num(ctx, t, w, "value", 1.0, lo=0.0, hi=1.0),
                     path=_image_file(ctx, t, w, "path", kind == "image"),
                     width=num(ctx, t, w, "width", 0.2, lo=0.0, hi=1.0),
                     **_mapping(ctx, t, w, "uv"))


def _material(ctx, name, t):
    w = f"[materials.{name}]"
    keys = {"color", "ka", "kd", "ks", "shininess", "kr", "kt", "ior", "absorption", "emission",
            "texture", "bump", "opacity", "environment"}
    check_keys(ctx, t, w, keys)
    unit = dict(lo=0.0, hi=1.0)
    kr, kt = num(ctx, t, w, "kr", 0.0, **unit), num(ctx, t, w, "kt", 0.0, **unit)
    if kr + kt > 1.0:
        ctx.fail(f"{w}.kt", f"kr + kt = {kr:g} + {kt:g} = {kr + kt:g} > 1: on total internal "
                            "reflection the transmitted share goes to reflection, so the surface "
                            "would create energy (DESIGN erratum 9); lower kr or kt")
    return m.Material(
        name, rgb(ctx, t, w, "color", (0.8, 0.8, 0.8)), num(ctx, t, w, "ka", 0.1, **unit),
        num(ctx, t, w, "kd", 0.8, **unit), num(ctx, t, w, "ks", 0.0, **unit),
        num(ctx, t, w, "shininess", 32.0, lo=0.0), kr,
        kt, num(ctx, t, w, "ior", 1.0, lo=0.0, lo_open=True),
        rgb(ctx, t, w, "absorption", (0.0, 0.0, 0.0)), rgb(ctx, t, w, "emission", (0.0, 0.0, 0.0)),
        _texture(ctx, t["texture"], f"{w}.texture") if "texture" in t else None,
        _bump(ctx, t["bump"], f"{w}.bump") if "bump" in t else None,
        _opacity(ctx, t["opacity"], f"{w}.opacity") if "opacity" in t else None,
        boolean(ctx, t, w, "environment", False))


def _transform(ctx, t, w) -> np.ndarray:
    if "transform" not in t:
        return np.eye(4)
    tt, w = t["transform"], f"{w}.transform"
    check_keys(ctx, tt, w, {"translate", "rotate", "scale", "matrix"})
    if "matrix" in tt:
        if len(tt) > 1:
            ctx.fail(f"{w}.matrix", "give either matrix or translate/rotate/scale, not both")
        M = matrix(ctx, tt, w, "matrix")
        if not np.allclose(M[3], [0, 0, 0, 1]):
            ctx.fail(f"{w}.matrix", "last row must be [0, 0, 0, 1] (affine transform)")
    else:
        s = tt.get("scale", 1.0)
        sv = vec(ctx, {"s": [s] * 3 if isinstance(s, (int, float)) and not isinstance(s, bool) else s},
                  w, "s", None)
        if min(abs(x) for x in sv) <= tol.degenerate * max(abs(x) for x in sv):
            ctx.fail(f"{w}.scale", f"scale must be non-zero on every axis (each at least "
                                   f"{tol.degenerate:g} times the largest), got {s!r}")
        M = (tf.translate(vec(ctx, tt, w, "translate", (0.0, 0.0, 0.0)))
             @ tf.rotate_xyz(vec(ctx, tt, w, "rotate", (0.0, 0.0, 0.0))) @ tf.scale(sv))
    sing = np.linalg.svd(M[:3, :3], compute_uv=False)   # descending
    if not sing[-1] > tol.degenerate * sing[0]:
        ctx.fail(f"{w}", f"transform is singular (singular values {sing[0]:.3g} .. {sing[-1]:.3g}: "
                         f"the smallest must exceed {tol.degenerate:g} times the largest)")
    return M


_COMMON = {"type", "material", "transform", "name", "tessellation"}


def _object(ctx, t, w, materials, inherited=None) -> m.SceneObject:
    """One ``[[objects]]`` table (or CSG operand): the common keys here, the rest by its kind
    (:mod:`.kinds`)."""
    if not isinstance(t, dict):
        ctx.fail(w, "expected a table")
    kind = KINDS[string(ctx, t, w, "type", choices=tuple(KINDS))]
    mat = t.get("material", inherited)
    if mat is None:
        ctx.fail(f"{w}.material", "missing required key")
    if not isinstance(mat, str):
        ctx.fail(f"{w}.material", f"expected a material name, got {mat!r}")
    if mat not in materials:
        known = ", ".join(sorted(materials)) or "none defined"
        ctx.fail(f"{w}.material", f"unknown material {mat!r} (defined: {known})")
    common = dict(material=mat, world_from_object=m._ro(_transform(ctx, t, w)),
                  name=string(ctx, t, w, "name", ""),
                  tessellation=num(ctx, t, w, "tessellation", 0, lo=1, hi=12, integer=True) if "tessellation" in t else None)
    check_keys(ctx, t, w, _COMMON | kind.KEYS, kind.REQUIRED)
    if kind.COMPOSITE:
        def child(table, where, inherited_material):
            return _object(ctx, table, where, materials, inherited_material)
        return kind.parse(ctx, t, w, common, child, kind_of)
    return kind.parse(ctx, t, w, common)


def _environment(ctx, t):
    w = "[environment]"
    check_keys(ctx, t, w, {"type", "path", "zenith", "horizon", "ground"}, {"type"})
    kind = string(ctx, t, w, "type", choices=("sky", "image"))
    d = m.Environment()
    return m.Environment(kind, _image_file(ctx, t, w, "path", kind == "image"),
                         rgb(ctx, t, w, "zenith", d.zenith), rgb(ctx, t, w, "horizon", d.horizon),
                         rgb(ctx, t, w, "ground", d.ground))


# --------------------------------------------------------------------------- entry points
def unlit_area_lights(lights, objects) -> list[int]:
    """Indices of the area lights with no object's world bounding box in front of them (on the
    side of their normal, :attr:`AreaLight.normal`)."""
    boxes = [world_bounds(o, np.eye(4)) for o in objects]
    out = []
    for k, light in enumerate(lights):
        if not isinstance(light, m.AreaLight):
            continue
        c, n = light.vertices.mean(0), light.normal
        reach = float(np.ptp(light.vertices, axis=0).max())
        ahead = False
        for lo, hi in boxes:
            if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
                ahead = True
                break
            corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
            if ((corners - c) @ n > tol.zero * max(1.0, reach)).any():
                ahead = True
                break
        if not ahead:
            out.append(k)
    return out


def scene_from_dict(data: dict, source: str = "<dict>", base_dir: Path | str = ".") -> m.Scene:
    """Build a validated :class:`Scene` from a parsed TOML dictionary."""
    ctx = Ctx(source, Path(base_dir))
    _numbers_fit(ctx, data, [])
    check_keys(ctx, data, "top level", {"scene", "camera", "lights", "materials", "objects", "environment"},
                {"camera", "objects"})
    st = data.get("scene", {})
    check_keys(ctx, st, "[scene]", {"name", "description", "background", "ambient"})
    camera = _camera(ctx, data["camera"])
    lights_t = data.get("lights", [])
    if not isinstance(lights_t, list):
        ctx.fail("lights", "expected an array of tables [[lights]]")
    lights = tuple(_light(ctx, lt, i) for i, lt in enumerate(lights_t))
    mats_t = data.get("materials", {})
    if not isinstance(mats_t, dict):
        ctx.fail("materials", "expected tables [materials.NAME]")
    materials = {name: _material(ctx, name, mt) for name, mt in mats_t.items()}
    objs_t = data["objects"]
    if not isinstance(objs_t, list) or not objs_t:
        ctx.fail("objects", "expected at least one [[objects]] table")
    objects = tuple(_object(ctx, ot, f"[[objects]] #{i + 1}", materials) for i, ot in enumerate(objs_t))
    env = _environment(ctx, data["environment"]) if "environment" in data else None
    for k in unlit_area_lights(lights, objects):
        warnings.warn(SceneWarning(
            f"{source}: lights #{k + 1} (area) faces away from every object and lights nothing: an "
            "area light emits from its front face, the side from which its vertices turn "
            "counter-clockwise (reverse them to turn it)"), stacklevel=2)
    return m.Scene(
        name=string(ctx, st, "[scene]", "name", Path(source).stem), camera=camera, materials=materials,
        objects=objects, lights=lights, description=string(ctx, st, "[scene]", "description", ""),
        background=rgb(ctx, st, "[scene]", "background", (0.0, 0.0, 0.0)),
        ambient=rgb(ctx, st, "[scene]", "ambient", (0.1, 0.1, 0.1)), environment=env, source=source)


def load_scene(path: str | Path) -> m.Scene:
    """Load and validate a scene file (TOML).  A bare name (``"whitted"``) finds a bundled scene.

    Raises
    ------
    SceneError
        With a message naming the file, the key and what was expected.
    """
    from .library import resolve
    p = resolve(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{p}: not valid TOML: {e}") from None
    except UnicodeDecodeError as e:
        raise SceneError(f"{p}: not a UTF-8 text file ({e.reason})") from None
    except OSError as e:
        raise SceneError(f"{p}: cannot read the scene file ({e.strerror or e})") from None
    return scene_from_dict(data, str(p), p.parent)
