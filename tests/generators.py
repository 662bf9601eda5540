"""Hypothesis strategies for generated scenes (issue 26, item 5): objects of every kind in the
registry (:data:`workbench.scene.kinds.KINDS`), CSG combinations of its closed kinds,
materials (diffuse, emissive, glass, mirror), camera placements outside / grazing / inside an
object, and a global scale 10^U(-6, 6) applied through each object's transform
(:func:`workbench.compare.stress.scale_scene_dict`).

Scenes are plain dictionaries in the scene file's format (README, "Scene files"); tests write
them as TOML (:func:`write_scene`) and load them through the public ``workbench.load_scene``.
Each object is built about its object-space origin, which is inside every closed object the
generators make (an inside camera is put at an object's ``translate``), with a size about
``r`` (1 at scale 1).

Cases left out: glass touching the floor (objects float above it; every kind resting on a
floor at scales 1e-6, 1 and 1e6 is tests/renderers/raytrace/test_raytrace_scale_floor.py); isosurface fields are polynomials and square roots of sums of
squares (a field with NaN values or a jump is refused at load, tests/scene/kinds/test_kind_expression_checks.py).
"""
from __future__ import annotations

import math
from pathlib import Path

from hypothesis import strategies as st

from workbench.app.ui.export import toml_text
from workbench.compare.stress import scale_scene_dict
from workbench.scene.kinds import KINDS

KIND_NAMES = tuple(sorted(k for k in KINDS if not getattr(KINDS[k], "MEDIUM", False)))
"""Every surface kind of the registry (a medium, the hypertexture, has no surface for these
properties to compare: tests/renderers/media covers it)."""

CLOSED = ("sphere", "box", "quadric", "mesh", "blob", "isosurface", "lathe", "prism")
"""The kinds generated as closed solids (hosts of an inside camera)."""

CSG_OPERANDS = tuple(k for k in CLOSED if k != "mesh")
"""Closed kinds a CSG tree may hold (the ray tracer refuses a mesh inside a CSG tree: NotApplicable)."""

MATERIALS = {
    "diffuse": {"color": [0.8, 0.7, 0.6], "ka": 0.2, "kd": 0.7, "ks": 0.3, "shininess": 30.0},
    "emissive": {"color": [0.9, 0.9, 0.9], "ka": 0.0, "kd": 0.5, "emission": [1.5, 1.2, 0.8]},
    "glass": {"color": [1.0, 1.0, 1.0], "ka": 0.0, "kd": 0.0, "kt": 0.9, "kr": 0.1, "ior": 1.5},
    "mirror": {"color": [0.9, 0.9, 0.9], "ka": 0.0, "kd": 0.1, "kr": 0.85},
}
"""The four materials every generated scene defines (objects pick one by name)."""

FLOOR_Y = -1.6
"""Height of the floor (a ``plane``), below every object (objects have extent <= 1.5)."""

unit = st.floats(0.0, 1.0, allow_nan=False, allow_infinity=False)
angles = st.lists(st.floats(-90.0, 90.0, allow_nan=False), min_size=3, max_size=3)


def _u(draw, lo: float, hi: float) -> float:
    return lo + (hi - lo) * draw(unit)


@st.composite
def shapes(draw, kind: str, closed: bool = False) -> dict:
    """One object table of ``kind`` about the origin (size about 1), no material nor transform.
    ``closed``: a solid (a closed lathe, a bounded quadric with an inside)."""
    r = _u(draw, 0.6, 1.0)
    if kind == "sphere":
        return {"type": "sphere", "radius": r}
    if kind == "plane":
        return {"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0],
                "size": [2 * r, _u(draw, 0.5, 2.0) * r]}
    if kind == "box":
        a = [r * _u(draw, 0.3, 1.0) for _ in range(3)]
        return {"type": "box", "min": [-x for x in a], "max": a}
    if kind == "polygon":
        k = draw(st.integers(3, 8))
        concave = draw(st.booleans())
        return {"type": "polygon", "vertices": [
            [r * (0.4 if concave and i % 2 else 1.0) * _cos(i, k), r * (0.4 if concave and i % 2 else 1.0) * _sin(i, k), 0.0]
            for i in range(k)]}
    if kind == "quadric":
        shape = "ellipsoid" if closed else draw(st.sampled_from(
            ("ellipsoid", "cylinder", "cone", "hyperboloid", "hyperboloid2", "paraboloid")))
        radii = [r, _u(draw, 0.4, 1.0), _u(draw, 0.4, 1.0) * r]
        q = {"type": "quadric", "shape": shape, "radii": radii}
        if shape != "ellipsoid":
            q["bounds"] = {"min": [-r, -r, -r], "max": [r, r, r]}
        return q
    if kind == "mesh":
        g = draw(st.sampled_from(("icosphere", "blob") if closed else ("icosphere", "torus", "blob")))
        return {"type": "mesh", "generate": {"kind": g, "subdivisions": 2, "radius": 0.8 * r,
                                             "seed": draw(st.integers(0, 9))}}
    if kind == "blob":
        comps = [{"center": [0.0, 0.0, 0.0], "radius": r}]
        for _ in range(draw(st.integers(0, 2))):
            comps.append({"center": [_u(draw, -0.5, 0.5) for _ in range(3)], "radius": _u(draw, 0.3, 0.8),
                          "strength": _u(draw, -0.8, 3.0)})
        return {"type": "blob", "threshold": _u(draw, 0.1, 0.5), "components": comps}
    if kind == "isosurface":
        # polynomial and sqrt-of-squares fields only: a field that divides by zero is being
        # fixed elsewhere (isosurface expressions giving NaN)
        if closed or draw(st.booleans()):  # an ellipsoid x^2/a^2 + y^2 + z^2 < r^2
            a = _u(draw, 0.5, 1.5)
            e = 1.1 * r * max(a, 1.0)
            return {"type": "isosurface", "function": f"x^2/{a * a!r} + y^2 + z^2", "threshold": r * r,
                    "max_gradient": 2.0 * 1.8 * e / min(a * a, 1.0), "bounds": {"min": [-e] * 3, "max": [e] * 3}}
        R, t = 0.7 * r, 0.25 * r  # a torus about the y axis
        e = 1.1 * (R + t)
        return {"type": "isosurface", "function": f"(sqrt(x^2 + z^2) - {R!r})^2 + y^2", "threshold": t * t,
                "max_gradient": 2.0 * (1.8 * e + R), "bounds": {"min": [-e, -1.1 * t, -e], "max": [e, 1.1 * t, e]}}
    if kind == "lathe":
        spline = draw(st.sampled_from(("linear", "cubic", "bezier")))
        if spline == "cubic":
            prof = [[0.0, 1.0], [0.0, -0.8], [0.6, -0.7], [0.3, -0.2], [0.8, 0.4], [0.4, 0.8], [0.0, 0.6], [0.0, -1.0]]
        elif spline == "bezier":
            prof = [[0.0, -0.8], [0.6, -0.8], [0.9, 0.0], [0.5, 0.2], [0.5, 0.2], [0.2, 0.4], [0.8, 0.9], [0.0, 0.8]]
        else:
            prof = [[0.0, -0.8], [0.5, -0.8], [0.3, -0.3], [0.7, 0.4], [0.4, 0.8], [0.0, 0.6]]
            if not closed and draw(st.booleans()):
                prof = prof[1:-1]  # an open lathe: a sheet
        out = {"type": "lathe", "points": [[r * a, r * b] for a, b in prof]}
        return out if spline == "linear" else {**out, "spline": spline}
    if kind == "prism":
        k = 2 * draw(st.integers(3, 6))
        inner = _u(draw, 0.35, 1.0)
        return {"type": "prism", "heights": [-_u(draw, 0.2, 0.6) * r, _u(draw, 0.2, 0.6) * r],
                "polygon": [[r * (inner if i % 2 else 1.0) * _cos(i, k), r * (inner if i % 2 else 1.0) * _sin(i, k)]
                            for i in range(k)]}
    if kind == "csg":
        op = draw(st.sampled_from(("union", "intersection", "difference")))
        left = draw(shapes(draw(st.sampled_from(CSG_OPERANDS)), closed=True))
        right = draw(shapes(draw(st.sampled_from(CSG_OPERANDS)), closed=True))
        shift = [_u(draw, -0.5, 0.5) for _ in range(3)] if op != "intersection" else [0.0, 0.0, 0.0]
        return {"type": "csg", "op": op, "left": left,
                "right": {**right, "transform": {"translate": shift, "scale": 0.7}}}
    raise AssertionError(f"no generator for kind {kind!r}: add one (the registry has {KIND_NAMES})")


def _cos(i: int, k: int) -> float:
    return math.cos(2 * math.pi * i / k)


def _sin(i: int, k: int) -> float:
    return math.sin(2 * math.pi * i / k)


@st.composite
def objects(draw, kinds=KIND_NAMES, materials=tuple(MATERIALS), closed=False) -> dict:
    """An object of one of ``kinds`` with a material of ``materials``, randomly turned."""
    o = draw(shapes(draw(st.sampled_from(kinds)), closed=closed))
    return {**o, "material": draw(st.sampled_from(materials)), "transform": {"rotate": draw(angles)}}


def _lights() -> list:
    return [{"type": "point", "position": [2.0, 4.0, 5.0], "intensity": 0.8},
            {"type": "directional", "direction": [-0.4, -1.0, -0.6], "intensity": 0.4}]


@st.composite
def scenes(draw, kinds=KIND_NAMES, materials=tuple(MATERIALS), placements=("outside", "grazing", "inside"),
           floor=None, max_objects=3) -> dict:
    """A scene dictionary at scale 1: one to ``max_objects`` objects side by side along x
    (1.6 apart), maybe a floor below them, and a camera ``outside`` (looking at the group from
    4 to 8 units), ``grazing`` (on the floor's plane, looking along it) or ``inside`` the first
    object (a closed kind, at its origin)."""
    placement = draw(st.sampled_from(placements))
    n = draw(st.integers(1, max_objects))
    objs = []
    for i in range(n):
        inside = placement == "inside" and i == 0
        o = draw(objects(tuple(k for k in kinds if k in CLOSED and k != "csg") if inside else kinds,
                         materials, closed=inside))
        o["transform"]["translate"] = [1.6 * (i - (n - 1) / 2), _u(draw, -0.2, 0.2), _u(draw, -0.2, 0.2)]
        objs.append(o)
    if placement == "grazing" or (floor if floor is not None else draw(st.booleans())):
        objs.append({"type": "plane", "name": "floor", "material": "diffuse", "point": [0.0, FLOOR_Y, 0.0],
                     "normal": [0.0, 1.0, 0.0], "size": [20.0, 20.0]})
    if placement == "outside":
        d = _u(draw, 4.0, 8.0) + 0.8 * n
        az, el = _u(draw, -1.2, 1.2), _u(draw, -0.2, 0.9)
        pos = [d * math.sin(az) * math.cos(el), d * math.sin(el), d * math.cos(az) * math.cos(el)]
        look = [0.0, 0.0, 0.0]
    elif placement == "grazing":
        pos = [_u(draw, -1.0, 1.0), FLOOR_Y + 1e-4 * draw(st.sampled_from((0.0, 1.0))), 6.0]
        look = [pos[0], FLOOR_Y, 0.0]
    else:
        pos = list(objs[0]["transform"]["translate"])
        look = [pos[0] + _u(draw, -1, 1), pos[1] + _u(draw, -1, 1), pos[2] - 1.0]
    return {"scene": {"background": [0.0, 0.0, 0.0], "ambient": [0.15, 0.15, 0.15]},
            "camera": {"position": pos, "look_at": look, "fov_y": 45.0, "resolution": [24, 18]},
            "materials": {k: dict(v) for k, v in MATERIALS.items()}, "lights": _lights(), "objects": objs}


scales = st.integers(-6, 6).map(lambda e: 10.0 ** e)
"""Global scales 1e-6 .. 1e6 (powers of ten: the scene's lengths stay exact decimals)."""


def scaled(scene: dict, factor: float) -> dict:
    """``scene`` with every length times ``factor`` (objects through their transforms)."""
    return scale_scene_dict(scene, factor)


def write_scene(scene: dict, folder: Path, name: str = "generated") -> Path:
    """The scene written as a TOML file in ``folder`` (its path)."""
    path = Path(folder) / f"{name}.toml"
    path.write_text(toml_text(scene), encoding="utf-8")
    return path
