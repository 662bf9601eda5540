"""Read a scene from TOML (``tomllib``) into the pure-data model, validating everything.

Every error is a :class:`SceneError` whose message names the file, the key and what was
expected; the scene is built only after every table has been checked, so a bad file never
yields a half-loaded scene.
"""
from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from ..core import transform as tf
from ..core.errors import WorkbenchError
from ..core.tol import tol
from . import model as m


class SceneError(WorkbenchError):
    """A scene file (or scene dictionary) is invalid; the message says where and why."""


class _Ctx:
    """Where we are in the file, for messages."""

    def __init__(self, source: str, base_dir: Path):
        self.source, self.base_dir = source, base_dir

    def fail(self, where: str, msg: str):
        raise SceneError(f"{self.source}: {where}: {msg}")


# --------------------------------------------------------------------------- value readers
def _check_keys(ctx: _Ctx, table: Any, where: str, allowed: set[str], required: set[str] = frozenset()):
    if not isinstance(table, dict):
        ctx.fail(where, f"expected a table, got {type(table).__name__}")
    unknown = sorted(set(table) - allowed)
    if unknown:
        ctx.fail(f"{where}.{unknown[0]}", f"unknown key (expected one of: {', '.join(sorted(allowed))})")
    missing = sorted(required - set(table))
    if missing:
        ctx.fail(f"{where}.{missing[0]}", "missing required key")


def _num(ctx, t, where, key, default=None, *, lo=None, hi=None, lo_open=False, integer=False):
    if key not in t:
        if default is None:
            ctx.fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or (integer and not isinstance(v, int)):
        ctx.fail(f"{where}.{key}", f"expected {'an integer' if integer else 'a number'}, got {v!r}")
    if not np.isfinite(v):
        ctx.fail(f"{where}.{key}", f"expected a finite number, got {v!r}")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        ctx.fail(f"{where}.{key}", f"expected a number {'>' if lo_open else '>='} {lo}, got {v!r}")
    if hi is not None and v > hi:
        ctx.fail(f"{where}.{key}", f"expected a number <= {hi}, got {v!r}")
    return int(v) if integer else float(v)


def _vec(ctx, t, where, key, default=None, *, n=3, nonzero=False, lo=None):
    if key not in t:
        if default is None:
            ctx.fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    ok = isinstance(v, list) and len(v) == n and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in v)
    if not ok:
        ctx.fail(f"{where}.{key}", f"expected a list of {n} finite numbers, got {v!r}")
    if nonzero and not tf.normalize(v).any():   # a direction: any length has one, 0 has none
        ctx.fail(f"{where}.{key}", f"expected a non-zero vector, got {v!r}")
    if lo is not None and min(v) < lo:
        ctx.fail(f"{where}.{key}", f"expected components >= {lo}, got {v!r}")
    return tuple(float(x) for x in v)


def _rgb(ctx, t, where, key, default):
    return _vec(ctx, t, where, key, default, n=3, lo=0.0)


def _str(ctx, t, where, key, default=None, *, choices=None):
    if key not in t:
        if default is None:
            ctx.fail(f"{where}.{key}", "missing required key")
        return default
    v = t[key]
    if not isinstance(v, str):
        ctx.fail(f"{where}.{key}", f"expected a string, got {v!r}")
    if choices is not None and v not in choices:
        ctx.fail(f"{where}.{key}", f"expected one of {', '.join(repr(c) for c in choices)}, got {v!r}")
    return v


def _bool(ctx, t, where, key, default):
    v = t.get(key, default)
    if not isinstance(v, bool):
        ctx.fail(f"{where}.{key}", f"expected true or false, got {v!r}")
    return v


def _matrix(ctx, t, where, key, n=4):
    v = t[key]
    ok = (isinstance(v, list) and len(v) == n and all(isinstance(r, list) and len(r) == n for r in v)
          and all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x)
                  for r in v for x in r))
    if not ok:
        ctx.fail(f"{where}.{key}", f"expected a {n}x{n} matrix (list of {n} lists of {n} numbers)")
    return np.array(v, dtype=np.float64)


def _path(ctx, t, where, key, required=True):
    if key not in t:
        if required:
            ctx.fail(f"{where}.{key}", "missing required key")
        return None
    p = Path(_str(ctx, t, where, key))
    p = p if p.is_absolute() else ctx.base_dir / p
    if not p.is_file():
        ctx.fail(f"{where}.{key}", f"file not found: {p}")
    return str(p)


FLOAT32_MAX = float(np.finfo(np.float32).max)
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
    """``_path`` of an image map, opened and decoded now (Pillow, as the renderers read it), so
    a file that is not a readable image fails at load, not mid-render."""
    p = _path(ctx, t, where, key, required)
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


def _parallel(a, b) -> bool:
    """Directions ``a`` and ``b`` (3,), non-zero, at an angle whose sine is at most
    ``tol.degenerate`` (whatever their lengths)."""
    return float(np.linalg.norm(np.cross(tf.normalize(a), tf.normalize(b)))) <= tol.degenerate


# --------------------------------------------------------------------------- sections
def _camera(ctx, t) -> m.Camera:
    w = "[camera]"
    _check_keys(ctx, t, w, {"position", "look_at", "up", "fov_y", "resolution", "near", "far"},
                {"position", "look_at"})
    pos, at = _vec(ctx, t, w, "position"), _vec(ctx, t, w, "look_at")
    if np.linalg.norm(np.subtract(at, pos)) <= tol.degenerate * max(np.linalg.norm(at), np.linalg.norm(pos)):
        ctx.fail(f"{w}.look_at", "must differ from position (zero-length view direction)")
    up = _vec(ctx, t, w, "up", (0.0, 1.0, 0.0), nonzero=True)
    if _parallel(np.subtract(at, pos), up):
        ctx.fail(f"{w}.up", "is parallel to the view direction")
    res = t.get("resolution", [320, 240])
    if not (isinstance(res, list) and len(res) == 2 and all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= 16384 for x in res)):
        ctx.fail(f"{w}.resolution", f"expected [width, height], integers in 1..16384, got {res!r}")
    near = _num(ctx, t, w, "near", 0.0, lo=0.0, lo_open=True) if "near" in t else None
    far = _num(ctx, t, w, "far", 0.0, lo=0.0, lo_open=True) if "far" in t else None
    if near is not None and far is not None and far <= near:
        ctx.fail(f"{w}.far", f"must be greater than near ({near}), got {far}")
    return m.Camera(pos, at, up, _num(ctx, t, w, "fov_y", 45.0, lo=0.0, lo_open=True, hi=179.0),
                    res[0], res[1], near, far)


def _light(ctx, t, i):
    w = f"[[lights]] #{i + 1}"
    if not isinstance(t, dict):
        ctx.fail(w, "expected a table")
    kind = _str(ctx, t, w, "type", choices=("point", "directional", "area"))
    common = {"type", "color", "intensity"}
    if kind == "point":
        _check_keys(ctx, t, w, common | {"position", "falloff"}, {"position"})
        return m.PointLight(_vec(ctx, t, w, "position"), _rgb(ctx, t, w, "color", (1.0, 1.0, 1.0)),
                            _num(ctx, t, w, "intensity", 1.0, lo=0.0),
                            _str(ctx, t, w, "falloff", "none", choices=("none", "inverse_square")))
    if kind == "directional":
        _check_keys(ctx, t, w, common | {"direction"}, {"direction"})
        return m.DirectionalLight(tuple(tf.normalize(_vec(ctx, t, w, "direction", nonzero=True))),
                                  _rgb(ctx, t, w, "color", (1.0, 1.0, 1.0)),
                                  _num(ctx, t, w, "intensity", 1.0, lo=0.0))
    _check_keys(ctx, t, w, common | {"vertices", "stand_in"}, {"vertices"})
    verts = _polygon_vertices(ctx, t, w)
    return m.AreaLight(m._ro(verts), _rgb(ctx, t, w, "color", (1.0, 1.0, 1.0)),
                       _num(ctx, t, w, "intensity", 1.0, lo=0.0),
                       _num(ctx, t, w, "stand_in", 1, lo=1, hi=16, integer=True))


def _polygon_vertices(ctx, t, w):
    v = t.get("vertices")
    if not (isinstance(v, list) and len(v) >= 3 and all(
            isinstance(p, list) and len(p) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in p) for p in v)):
        ctx.fail(f"{w}.vertices", "expected a list of at least 3 points [x, y, z]")
    v = np.array(v, dtype=np.float64)
    cross = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
    diam = float(np.ptp(v, axis=0).max())
    if np.linalg.norm(cross) <= tol.degenerate * diam * max(diam, float(np.abs(v).max())):
        ctx.fail(f"{w}.vertices", "polygon has zero area (collinear or repeated points)")
    n = cross / np.linalg.norm(cross)
    dev = np.abs((v - v[0]) @ n).max()
    if dev > tol.planar * diam:
        ctx.fail(f"{w}.vertices", f"polygon is not planar (a vertex is {dev:.3g} off its plane)")
    return v


_MAP_KEYS = {"projection", "scale", "path", "center", "pole", "equator"}


def _mapping(ctx, t, w, default_projection):
    proj = _str(ctx, t, w, "projection", default_projection,
                choices=("uv", "planar", "cylindrical", "spherical", "solid"))
    pole = tuple(tf.normalize(_vec(ctx, t, w, "pole", (0.0, 1.0, 0.0), nonzero=True)))
    equator = tuple(tf.normalize(_vec(ctx, t, w, "equator", (1.0, 0.0, 0.0), nonzero=True)))
    if proj in ("spherical", "cylindrical") and _parallel(pole, equator):
        ctx.fail(f"{w}.equator", "must not be parallel to the pole")
    return dict(projection=proj, scale=_num(ctx, t, w, "scale", 1.0, lo=0.0, lo_open=True),
                center=_vec(ctx, t, w, "center", (0.0, 0.0, 0.0)), pole=pole, equator=equator)


def _image_projection(ctx, t, w, kind):
    if kind == "image" and t.get("projection") == "solid":
        ctx.fail(f"{w}.projection", "an image map needs a 2D projection (uv, planar, cylindrical or "
                                    "spherical), not 'solid'")


def _texture(ctx, t, w):
    _check_keys(ctx, t, w, _MAP_KEYS | {"type", "colors", "mortar"}, {"type"})
    kind = _str(ctx, t, w, "type", choices=("checker", "bricks", "marble", "wood", "grid", "image"))
    _image_projection(ctx, t, w, kind)
    colors = t.get("colors", [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]])
    if not (isinstance(colors, list) and len(colors) == 2):
        ctx.fail(f"{w}.colors", "expected two colours [[r, g, b], [r, g, b]]")
    cols = tuple(_rgb(ctx, {"c": c}, f"{w}.colors", "c", None) for c in colors)
    return m.Texture(kind, colors=cols, path=_image_file(ctx, t, w, "path", kind == "image"),
                     mortar=_num(ctx, t, w, "mortar", 0.08, lo=0.0, hi=0.5),
                     **_mapping(ctx, t, w, "uv"))


def _bump(ctx, t, w):
    _check_keys(ctx, t, w, _MAP_KEYS | {"type", "strength", "mortar"}, {"type"})
    kind = _str(ctx, t, w, "type", choices=("bricks", "noise", "waves", "image"))
    _image_projection(ctx, t, w, kind)
    return m.Bump(kind, strength=_num(ctx, t, w, "strength", 1.0),
                  path=_image_file(ctx, t, w, "path", kind == "image"),
                  mortar=_num(ctx, t, w, "mortar", 0.08, lo=0.0, hi=0.5),
                  **_mapping(ctx, t, w, "planar"))


def _opacity(ctx, t, w):
    _check_keys(ctx, t, w, _MAP_KEYS | {"type", "value", "width"}, {"type"})
    kind = _str(ctx, t, w, "type", choices=("constant", "grid", "checker", "image"))
    _image_projection(ctx, t, w, kind)
    return m.Opacity(kind, value=_num(ctx, t, w, "value", 1.0, lo=0.0, hi=1.0),
                     path=_image_file(ctx, t, w, "path", kind == "image"),
                     width=_num(ctx, t, w, "width", 0.2, lo=0.0, hi=1.0),
                     **_mapping(ctx, t, w, "uv"))


def _material(ctx, name, t):
    w = f"[materials.{name}]"
    keys = {"color", "ka", "kd", "ks", "shininess", "kr", "kt", "ior", "absorption", "emission",
            "texture", "bump", "opacity", "environment"}
    _check_keys(ctx, t, w, keys)
    unit = dict(lo=0.0, hi=1.0)
    kr, kt = _num(ctx, t, w, "kr", 0.0, **unit), _num(ctx, t, w, "kt", 0.0, **unit)
    if kr + kt > 1.0:
        ctx.fail(f"{w}.kt", f"kr + kt = {kr:g} + {kt:g} = {kr + kt:g} > 1: on total internal "
                            "reflection the transmitted share goes to reflection, so the surface "
                            "would create energy (DESIGN erratum 9); lower kr or kt")
    return m.Material(
        name, _rgb(ctx, t, w, "color", (0.8, 0.8, 0.8)), _num(ctx, t, w, "ka", 0.1, **unit),
        _num(ctx, t, w, "kd", 0.8, **unit), _num(ctx, t, w, "ks", 0.0, **unit),
        _num(ctx, t, w, "shininess", 32.0, lo=0.0), kr,
        kt, _num(ctx, t, w, "ior", 1.0, lo=0.0, lo_open=True),
        _rgb(ctx, t, w, "absorption", (0.0, 0.0, 0.0)), _rgb(ctx, t, w, "emission", (0.0, 0.0, 0.0)),
        _texture(ctx, t["texture"], f"{w}.texture") if "texture" in t else None,
        _bump(ctx, t["bump"], f"{w}.bump") if "bump" in t else None,
        _opacity(ctx, t["opacity"], f"{w}.opacity") if "opacity" in t else None,
        _bool(ctx, t, w, "environment", False))


def _transform(ctx, t, w) -> np.ndarray:
    if "transform" not in t:
        return np.eye(4)
    tt, w = t["transform"], f"{w}.transform"
    _check_keys(ctx, tt, w, {"translate", "rotate", "scale", "matrix"})
    if "matrix" in tt:
        if len(tt) > 1:
            ctx.fail(f"{w}.matrix", "give either matrix or translate/rotate/scale, not both")
        M = _matrix(ctx, tt, w, "matrix")
        if not np.allclose(M[3], [0, 0, 0, 1]):
            ctx.fail(f"{w}.matrix", "last row must be [0, 0, 0, 1] (affine transform)")
    else:
        s = tt.get("scale", 1.0)
        sv = _vec(ctx, {"s": [s] * 3 if isinstance(s, (int, float)) and not isinstance(s, bool) else s},
                  w, "s", None)
        if min(abs(x) for x in sv) <= tol.degenerate * max(abs(x) for x in sv):
            ctx.fail(f"{w}.scale", f"scale must be non-zero on every axis (each at least "
                                   f"{tol.degenerate:g} times the largest), got {s!r}")
        M = (tf.translate(_vec(ctx, tt, w, "translate", (0.0, 0.0, 0.0)))
             @ tf.rotate_xyz(_vec(ctx, tt, w, "rotate", (0.0, 0.0, 0.0))) @ tf.scale(sv))
    sing = np.linalg.svd(M[:3, :3], compute_uv=False)   # descending
    if not sing[-1] > tol.degenerate * sing[0]:
        ctx.fail(f"{w}", f"transform is singular (singular values {sing[0]:.3g} .. {sing[-1]:.3g}: "
                         f"the smallest must exceed {tol.degenerate:g} times the largest)")
    return M


def quadric_matrix(shape: str, radii) -> tuple[np.ndarray, tuple | None]:
    """Symmetric Q (4, 4) of a named quadric (axis of symmetry y) and its natural bounds
    (``None`` when unbounded).  Inside is ``P^T Q P < 0``."""
    a, b, c = (1.0 / r ** 2 for r in radii)
    if shape == "ellipsoid":
        return np.diag([a, b, c, -1.0]), (tuple(-r for r in radii), tuple(radii))
    if shape == "cylinder":
        return np.diag([a, 0.0, c, -1.0]), None
    if shape == "cone":
        return np.diag([a, -b, c, 0.0]), None
    if shape == "hyperboloid":  # one sheet
        return np.diag([a, -b, c, -1.0]), None
    if shape == "hyperboloid2":  # two sheets
        return np.diag([-a, b, -c, -1.0]), None
    if shape == "paraboloid":  # x^2/a^2 + z^2/c^2 - y/b = 0, opens towards +y
        Q = np.diag([a, 0.0, c, 0.0])
        Q[1, 3] = Q[3, 1] = -0.5 / radii[1]
        return Q, None
    raise KeyError(shape)


_QUADRIC_SHAPES = ("ellipsoid", "cylinder", "cone", "hyperboloid", "hyperboloid2", "paraboloid")
_COMMON = {"type", "material", "transform", "name", "tessellation"}


def _object(ctx, t, w, materials, *, in_csg=False, inherited=None) -> m.SceneObject:
    if not isinstance(t, dict):
        ctx.fail(w, "expected a table")
    kind = _str(ctx, t, w, "type", choices=("sphere", "plane", "box", "quadric", "polygon", "mesh", "csg"))
    mat = t.get("material", inherited)
    if mat is None:
        ctx.fail(f"{w}.material", "missing required key")
    if not isinstance(mat, str):
        ctx.fail(f"{w}.material", f"expected a material name, got {mat!r}")
    if mat not in materials:
        known = ", ".join(sorted(materials)) or "none defined"
        ctx.fail(f"{w}.material", f"unknown material {mat!r} (defined: {known})")
    common = dict(material=mat, world_from_object=m._ro(_transform(ctx, t, w)),
                  name=_str(ctx, t, w, "name", ""),
                  tessellation=_num(ctx, t, w, "tessellation", 0, lo=1, hi=12, integer=True) if "tessellation" in t else None)
    if kind == "sphere":
        _check_keys(ctx, t, w, _COMMON | {"center", "radius"}, {"radius"})
        return m.Sphere(**common, center=_vec(ctx, t, w, "center", (0.0, 0.0, 0.0)),
                        radius=_num(ctx, t, w, "radius", lo=0.0, lo_open=True))
    if kind == "plane":
        _check_keys(ctx, t, w, _COMMON | {"point", "normal", "size", "u_axis"}, {"normal", "size"})
        size = _vec(ctx, t, w, "size", n=2)
        if min(size) <= 0:
            ctx.fail(f"{w}.size", f"expected two positive numbers [width, height], got {list(size)}")
        return m.Plane(**common, point=_vec(ctx, t, w, "point", (0.0, 0.0, 0.0)),
                       normal=tuple(tf.normalize(_vec(ctx, t, w, "normal", nonzero=True))),
                       size=size, u_axis=_vec(ctx, t, w, "u_axis", (1.0, 0.0, 0.0), nonzero=True))
    if kind == "box":
        _check_keys(ctx, t, w, _COMMON | {"min", "max"}, {"min", "max"})
        lo, hi = _vec(ctx, t, w, "min"), _vec(ctx, t, w, "max")
        if any(a >= b for a, b in zip(lo, hi)):
            ctx.fail(f"{w}.max", f"must exceed min on every axis (min {list(lo)}, max {list(hi)})")
        return m.Box(**common, min=lo, max=hi)
    if kind == "quadric":
        _check_keys(ctx, t, w, _COMMON | {"Q", "shape", "radii", "bounds"})
        if ("Q" in t) == ("shape" in t):
            ctx.fail(f"{w}.Q", "give exactly one of Q (4x4 symmetric matrix) or shape")
        natural = None
        if "Q" in t:
            Q = _matrix(ctx, t, w, "Q")
            # entry by entry: Q_ij and Q_ji scale alike under a transform of the quadric
            asym = np.abs(Q - Q.T) - tol.symmetric * np.maximum(np.abs(Q), np.abs(Q.T))
            if (asym > 0).any():
                i, j = np.unravel_index(np.argmax(asym), Q.shape)
                ctx.fail(f"{w}.Q", f"matrix is not symmetric (Q[{i}][{j}] = {Q[i, j]} but Q[{j}][{i}] = {Q[j, i]})")
            if not Q[:3].any():   # exactly: a tiny term is a huge quadric, not none
                ctx.fail(f"{w}.Q", "degenerate quadric (no x, y or z terms)")
            shape = "general"
        else:
            shape = _str(ctx, t, w, "shape", choices=_QUADRIC_SHAPES)
            radii = _vec(ctx, t, w, "radii", (1.0, 1.0, 1.0))
            if min(radii) <= 0:
                ctx.fail(f"{w}.radii", f"expected three positive numbers, got {list(radii)}")
            Q, natural = quadric_matrix(shape, radii)
        if "bounds" in t:
            bt = t["bounds"]
            _check_keys(ctx, bt, f"{w}.bounds", {"min", "max"}, {"min", "max"})
            lo, hi = _vec(ctx, bt, f"{w}.bounds", "min"), _vec(ctx, bt, f"{w}.bounds", "max")
            if any(a >= b for a, b in zip(lo, hi)):
                ctx.fail(f"{w}.bounds.max", "must exceed bounds.min on every axis")
        elif natural is not None:
            lo, hi = natural
        else:
            ctx.fail(f"{w}.bounds", f"required for an unbounded quadric ({shape}): bounds = {{min = [..], max = [..]}}")
        return m.Quadric(**common, Q=m._ro(Q), bounds_min=lo, bounds_max=hi, shape=shape)
    if kind == "polygon":
        _check_keys(ctx, t, w, _COMMON | {"vertices"}, {"vertices"})
        return m.Polygon(**common, vertices=m._ro(_polygon_vertices(ctx, t, w)))
    if kind == "mesh":
        _check_keys(ctx, t, w, _COMMON | {"path", "generate", "vertices", "faces", "crease_angle"})
        return _mesh(ctx, t, w, common)
    _check_keys(ctx, t, w, _COMMON | {"op", "left", "right"}, {"op", "left", "right"})
    op = _str(ctx, t, w, "op", choices=("union", "intersection", "difference"))
    left = _object(ctx, t["left"], f"{w}.left", materials, in_csg=True, inherited=mat)
    right = _object(ctx, t["right"], f"{w}.right", materials, in_csg=True, inherited=mat)
    for side, child in (("left", left), ("right", right)):
        if isinstance(child, (m.Plane, m.Polygon)):
            ctx.fail(f"{w}.{side}.type", f"CSG needs solids; a {child.kind} has no inside")
    return m.CSG(**common, op=op, left=left, right=right)


def _mesh(ctx, t, w, common):
    import trimesh  # heavy: only when a scene has meshes
    sources = [k for k in ("path", "generate", "vertices") if k in t]
    if len(sources) != 1:
        ctx.fail(w, "a mesh needs exactly one of path, generate or vertices (+ faces)")
    if "path" in t:
        p = _path(ctx, t, w, "path")
        try:
            tm = trimesh.load(p, force="mesh", process=False)
        except Exception as e:  # trimesh raises many kinds
            ctx.fail(f"{w}.path", f"cannot read mesh {p}: {e}")
        source = p
    elif "generate" in t:
        g = t["generate"]
        _check_keys(ctx, g, f"{w}.generate", {"kind", "subdivisions", "seed", "amplitude", "radius"}, {"kind"})
        kind = _str(ctx, g, f"{w}.generate", "kind", choices=("icosphere", "blob", "torus"))
        from .generate import generate_mesh
        tm = generate_mesh(kind, subdivisions=_num(ctx, g, f"{w}.generate", "subdivisions", 4, lo=0, hi=8, integer=True),
                           seed=_num(ctx, g, f"{w}.generate", "seed", 0, lo=0, hi=2 ** 32 - 1, integer=True),
                           amplitude=_num(ctx, g, f"{w}.generate", "amplitude", 0.15, lo=0.0),
                           radius=_num(ctx, g, f"{w}.generate", "radius", 1.0, lo=0.0, lo_open=True))
        source = f"generated:{kind}"
    else:
        v = t["vertices"]
        f = t.get("faces")
        try:
            V, F = np.array(v, dtype=np.float64), np.array(f, dtype=np.int64)
        except (TypeError, ValueError):
            ctx.fail(f"{w}.vertices", "expected vertices = [[x, y, z], ...] and faces = [[i, j, k], ...]")
        if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
            ctx.fail(f"{w}.faces", "expected vertices (N x 3) and faces (M x 3)")
        if not np.isfinite(V).all():
            ctx.fail(f"{w}.vertices", "contains a non-finite number")
        if F.size and (F.min() < 0 or F.max() >= len(V)):
            ctx.fail(f"{w}.faces", f"face index out of range 0..{len(V) - 1}")
        tm = trimesh.Trimesh(V, F, process=False)
        source = "inline"
    if len(tm.faces) == 0:
        ctx.fail(f"{w}", f"mesh from {source} has no triangles")
    if not np.isfinite(tm.vertices).all():
        ctx.fail(f"{w}", f"mesh from {source} has non-finite vertices")
    if np.abs(tm.vertices).max() > FLOAT32_MAX:
        ctx.fail(f"{w}", f"mesh from {source} has vertices outside the float32 range "
                         f"|x| <= {FLOAT32_MAX:.8g} (the GPU is float32)")
    uvs = None
    vis = getattr(tm, "visual", None)
    if vis is not None and getattr(vis, "uv", None) is not None and len(vis.uv) == len(tm.vertices):
        uvs = m._ro(vis.uv)
    from .mesh_normals import DEFAULT_CREASE_ANGLE, crease_normals
    crease = _num(ctx, t, w, "crease_angle", DEFAULT_CREASE_ANGLE, lo=0.0, hi=180.0)
    V, F, N, uvs = crease_normals(tm.vertices, tm.faces, crease, uvs)
    return m.Mesh(**common, vertices=m._ro(V), faces=np.asarray(F, dtype=np.int64),
                  normals=m._ro(N), uvs=None if uvs is None else m._ro(uvs), source=source)


def _environment(ctx, t):
    w = "[environment]"
    _check_keys(ctx, t, w, {"type", "path", "zenith", "horizon", "ground"}, {"type"})
    kind = _str(ctx, t, w, "type", choices=("sky", "image"))
    d = m.Environment()
    return m.Environment(kind, _image_file(ctx, t, w, "path", kind == "image"),
                         _rgb(ctx, t, w, "zenith", d.zenith), _rgb(ctx, t, w, "horizon", d.horizon),
                         _rgb(ctx, t, w, "ground", d.ground))


# --------------------------------------------------------------------------- entry points
def scene_from_dict(data: dict, source: str = "<dict>", base_dir: Path | str = ".") -> m.Scene:
    """Build a validated :class:`Scene` from a parsed TOML dictionary."""
    ctx = _Ctx(source, Path(base_dir))
    _numbers_fit(ctx, data, [])
    _check_keys(ctx, data, "top level", {"scene", "camera", "lights", "materials", "objects", "environment"},
                {"camera", "objects"})
    st = data.get("scene", {})
    _check_keys(ctx, st, "[scene]", {"name", "description", "background", "ambient"})
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
    return m.Scene(
        name=_str(ctx, st, "[scene]", "name", Path(source).stem), camera=camera, materials=materials,
        objects=objects, lights=lights, description=_str(ctx, st, "[scene]", "description", ""),
        background=_rgb(ctx, st, "[scene]", "background", (0.0, 0.0, 0.0)),
        ambient=_rgb(ctx, st, "[scene]", "ambient", (0.1, 0.1, 0.1)), environment=env, source=source)


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
