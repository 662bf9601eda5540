"""``workbench stress``: the stiff and extreme cases of DESIGN.md, run from a data catalogue.

The catalogue (``stress/cases.toml`` at the repository root) holds base scenes
(``[scenes.NAME]``, scene TOML tables), method groups (``[groups]``) and ``[[case]]`` entries.
A case is either

* ``kind = "scene"``: a base scene (or a bundled scene name) with dotted-key overrides
  (``set = {"materials.m.shininess" = 0.0}``), rendered with each method of ``methods`` (names
  or group names) and checked by a scene check (``check``, see :data:`SCENE_CHECKS`); or
* ``kind = "api"``: a function called by its dotted name (``call``) through an adapter
  (``check``, see :data:`API_CHECKS`) that builds the inputs from ``params`` and computes the
  expected value from a closed form.

Adding a case that uses an existing check needs no code.  Each (case, method) gives one row:
expected (analytic value or invariant), measured, deviation, tolerance, NaN/Inf count, time
and a verdict: ``ok``, ``inaccurate: by X``, ``breaks: ...`` (exception, or NaN/Inf produced)
or ``unavailable: ...`` (method not registered, function not importable, or the method does
not apply).  No case is ever skipped silently.
"""
from __future__ import annotations

import copy
import csv
import datetime as _dt
import fnmatch
import importlib
import io
import time
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..core.errors import NotApplicable, WorkbenchError
from ..core.resources import data_dir
from ..renderers.base import available, render
from ..scene.io import scene_from_dict
from . import formulas
from .analytic import interior, sphere_hits
from .html import esc, page, table
from .outputs import dumps, jsonable, machine_info, staged

CATALOGUE = data_dir("stress") / "cases.toml"
DEFAULT_SIZE = (48, 36)


@dataclass
class Row:
    case: str
    title: str
    method: str
    expected: str = ""
    measured: str = ""
    deviation: float = float("nan")
    tolerance: float = float("nan")
    nonfinite: int = 0
    time_s: float = 0.0
    verdict: str = ""
    note: str = ""
    features_used: list = field(default_factory=list)
    left_out: list = field(default_factory=list)


@dataclass
class Outcome:
    """What a check returns: ``deviation`` is compared with the case's ``tolerance``."""

    expected: str
    measured: str
    deviation: float
    nonfinite: int = 0
    note: str = ""


# --------------------------------------------------------------------------- scene building
def _set_dotted(d: dict, key: str, value, where: str):
    parts = key.split(".")
    node = d
    for p in parts[:-1]:
        node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
        if not isinstance(node, (dict, list)):
            raise WorkbenchError(f"{where}: cannot set {key!r}: {p!r} is not a table or an array")
    last = parts[-1]
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value


_GEOMETRIC = {"position", "look_at", "center", "radius", "point", "size", "vertices", "min", "max",
              "translate", "near", "far"}


def scale_scene_dict(d, factor: float):
    """A copy of a scene dictionary with every length multiplied by ``factor``.  The camera,
    lights and other scene-level lengths (:data:`_GEOMETRIC` keys) are multiplied; each object
    is scaled through its transform (:func:`scaled_transform`), so every kind scales whole,
    whatever its parameters are (a lathe's profile, a prism's polygon and heights, an
    isosurface's bounds and field), CSG children with their parent.  Rendering must not change:
    lights without falloff, same field of view."""
    if isinstance(d, dict):
        return {k: (np.multiply(v, factor).tolist() if k in _GEOMETRIC
                    else [scale_object_dict(o, factor) for o in v] if k == "objects" and isinstance(v, list)
                    else scale_scene_dict(v, factor))
                for k, v in d.items()}
    if isinstance(d, list):
        return [scale_scene_dict(v, factor) for v in d]
    return d


def scale_object_dict(obj, factor: float):
    """An object table scaled by ``factor`` about the world origin (its transform's)."""
    if not isinstance(obj, dict):
        return obj
    return {**obj, "transform": scaled_transform(obj.get("transform"), factor)}


def scaled_transform(t, factor: float) -> dict:
    """The transform table (``translate``/``rotate``/``scale`` or ``matrix``; None: identity)
    followed by a uniform scale ``factor`` about the origin.  ``T = Tr(t) R S(s)`` gives
    ``factor T = Tr(factor t) R S(factor s)`` (a uniform scale commutes with ``R``)."""
    t = dict(t or {})
    if "matrix" in t:
        M = np.asarray(t["matrix"], dtype=float)
        return {"matrix": (np.diag([factor, factor, factor, 1.0]) @ M).tolist()}
    sc = t.get("scale", 1.0)
    t["scale"] = np.multiply(sc, factor).tolist()
    if "translate" in t:
        t["translate"] = np.multiply(t["translate"], factor).tolist()
    return t


class Catalogue:
    """The parsed catalogue with scene building; validation errors name the case and key."""

    def __init__(self, path: str | Path = CATALOGUE):
        self.path = Path(path)
        try:
            data = tomllib.loads(self.path.read_text(encoding="utf-8"))
        except (OSError, tomllib.TOMLDecodeError) as e:
            raise WorkbenchError(f"{self.path}: cannot read the stress catalogue: {e}") from None
        self.scenes: dict = data.get("scenes", {})
        self.groups: dict = data.get("groups", {})
        self.defaults: dict = data.get("defaults", {})
        self.cases: list[dict] = data.get("case", [])
        seen = set()
        for i, c in enumerate(self.cases):
            where = f"{self.path.name}: [[case]] #{i + 1}"
            for key in ("id", "title", "kind", "check"):
                if key not in c:
                    raise WorkbenchError(f"{where}: missing key {key!r}")
            if c["id"] in seen:
                raise WorkbenchError(f"{where}: duplicate id {c['id']!r}")
            seen.add(c["id"])
            checks = SCENE_CHECKS if c["kind"] == "scene" else API_CHECKS if c["kind"] == "api" else None
            if checks is None:
                raise WorkbenchError(f"{where} ({c['id']}): kind must be 'scene' or 'api', got {c['kind']!r}")
            if c["check"] not in checks:
                raise WorkbenchError(f"{where} ({c['id']}): unknown check {c['check']!r} for kind "
                                     f"{c['kind']!r} (known: {', '.join(sorted(checks))})")
            if c["kind"] == "scene" and "scene" not in c:
                raise WorkbenchError(f"{where} ({c['id']}): a scene case needs 'scene'")
            if c["kind"] == "api" and ("call" not in c or "method" not in c):
                raise WorkbenchError(f"{where} ({c['id']}): an api case needs 'call' and 'method'")

    def methods(self, case: dict) -> list[str]:
        if case["kind"] == "api":
            return [case["method"]]
        spec = case.get("methods", self.defaults.get("methods", "all"))
        names = [spec] if isinstance(spec, str) else list(spec)
        out = []
        for n in names:
            out += self.groups.get(n, [n])
        return list(dict.fromkeys(out))

    def scene_dict(self, case: dict, variant: dict | None = None) -> dict:
        """The case's scene as a dictionary, with its overrides (and a variant's) applied."""
        name = case["scene"]
        if name in self.scenes:
            d = copy.deepcopy(self.scenes[name])
        else:
            from ..scene.library import resolve
            d = tomllib.loads(resolve(name).read_text(encoding="utf-8"))
        where = f"{self.path.name}: case {case['id']}"
        for spec in (case, variant or {}):
            for k, v in spec.get("set", {}).items():
                _set_dotted(d, k, copy.deepcopy(v), where)
            if spec.get("remove"):
                d["objects"] = [o for o in d.get("objects", []) if o.get("name") not in spec["remove"]]
            if spec.get("remove_lights"):
                d["lights"] = []
        w, h = case.get("size", self.defaults.get("size", DEFAULT_SIZE))
        d.setdefault("camera", {})["resolution"] = [int(w), int(h)]
        return d

    def scene(self, case: dict, variant: dict | None = None, factor: float | None = None):
        d = self.scene_dict(case, variant)
        if factor is not None:
            d = scale_scene_dict(d, factor)
        if case["scene"] in self.scenes:
            base_dir = self.path.parent
        else:  # a bundled scene: its relative asset paths are relative to its own file
            from ..scene.library import resolve
            base_dir = resolve(case["scene"]).parent
        return scene_from_dict(d, source=f"{self.path.name}:{case['id']}", base_dir=base_dir)


def per_method(case: dict, key: str, method: str, default):
    """A case value that may be given per method: ``key = value`` or ``key = {method = value,
    "*" = default}``."""
    v = case.get(key, default)
    return v.get(method, v.get("*", default)) if isinstance(v, dict) else v


# --------------------------------------------------------------------------- scene checks
class SceneRun:
    """Renders for one (case, method), accumulating the NaN/Inf count of every image."""

    def __init__(self, cat: Catalogue, case: dict, method: str):
        self.cat, self.case, self.method = cat, case, method
        self.nonfinite = 0
        self.stats: dict = {}
        self.features_used: list[str] = []
        self.left_out: list = []  # support.Note records of the case's first render

    def options(self, method: str, table_: dict | None = None) -> dict:
        t = self.case.get("options", {}) if table_ is None else table_
        return dict(t.get("*", {}), **t.get(method, {}))

    def render(self, scene, method: str | None = None, options: dict | None = None) -> np.ndarray:
        m = method or self.method
        res = render(scene, m, **(self.options(m) if options is None else options))
        self.nonfinite += int(res.stats.get("nonfinite_pixels", 0))
        if not self.stats:  # of the case's own (first) render
            self.stats, self.features_used, self.left_out = res.stats, res.features_used, res.left_out
        return res.image


def _rmse(a, b) -> float:
    return float(np.sqrt(np.mean((np.asarray(a, np.float64) - np.asarray(b, np.float64)) ** 2)))


def check_finite(run: SceneRun) -> Outcome:
    """Invariant: no NaN or Inf anywhere in the image, values >= 0."""
    img = run.render(run.cat.scene(run.case))
    neg = int((img < 0).any(-1).sum())
    return Outcome("no NaN/Inf pixel, no negative value", f"max {img.max():.4g}, {neg} negative pixel(s)",
                   float(neg), run.nonfinite)


def check_analytic_spheres(run: SceneRun) -> Outcome:
    """RMSE against the exact local-model image of a spheres-only scene
    (:func:`workbench.compare.analytic.sphere_hits`: exact intersections, no shadows) over the
    pixels away from silhouettes (shading error; a tessellated outline moves by design), or over
    every pixel when the case says ``silhouettes = "include"`` for the method (exact ray casters);
    the whole-image RMSE is reported beside it."""
    scene = run.cat.scene(run.case)
    img = run.render(scene)
    ref, index = sphere_hits(scene)
    whole = per_method(run.case, "silhouettes", run.method, "exclude") == "include"
    inner = np.ones(index.shape, dtype=bool) if whole else interior(index)
    err = np.abs(img.astype(np.float64) - ref).max(-1)
    dev = _rmse(img[inner], ref[inner]) if inner.any() else 0.0
    return Outcome("analytic sphere image (RMSE 0" + (")" if whole else " away from silhouettes)"),
                   f"RMSE {dev:.4g} {'all' if whole else 'inside'}, {_rmse(img, ref):.4g} whole image; max |err| inside "
                   f"{err[inner].max() if inner.any() else 0.0:.3g}; {int((err > 0.05).sum())} px off by > 0.05",
                   dev, run.nonfinite)


def check_same_as(run: SceneRun) -> Outcome:
    """RMSE against the same method (or ``reference.method``) on a variant of the scene
    (``reference.set``, ``reference.remove``, ``reference.remove_lights``, ``reference.options``)
    that must give the same image by theory (an index-matched sphere is invisible, ...)."""
    ref_spec = run.case.get("reference", {})
    img = run.render(run.cat.scene(run.case))
    m = ref_spec.get("method", run.method)
    opts = run.options(m, ref_spec["options"]) if "options" in ref_spec else run.options(m)
    ref = run.render(run.cat.scene(run.case, ref_spec), m, opts)
    return Outcome(ref_spec.get("expected", "same image as the reference variant (RMSE 0)"),
                   f"RMSE {_rmse(img, ref):.4g}, max |err| {np.abs(img - ref).max():.3g}",
                   _rmse(img, ref), run.nonfinite)


def check_scale_invariance(run: SceneRun) -> Outcome:
    """RMSE between the scene and the same scene with every length times ``factor``: the
    image must not change (offsets and epsilons must scale with the scene)."""
    f = float(run.case["factor"])
    img = run.render(run.cat.scene(run.case))
    scaled = run.render(run.cat.scene(run.case, factor=f))
    return Outcome(f"same image at scale x{f:g} (RMSE 0)",
                   f"RMSE {_rmse(img, scaled):.4g}, {int((np.abs(img - scaled).max(-1) > 0.05).sum())} px off by > 0.05",
                   _rmse(img, scaled), run.nonfinite)


def check_uniform(run: SceneRun) -> Outcome:
    """Relative error of the image mean against ``value`` (furnace: B = E / (1 - rho))."""
    v = float(run.case["value"])
    img = run.render(run.cat.scene(run.case))
    mean = float(img.mean())
    return Outcome(f"uniform value {v:g}", f"mean {mean:.6g} (min {img.min():.4g}, max {img.max():.4g})",
                   abs(mean - v) / abs(v), run.nonfinite)


SCENE_CHECKS: dict[str, Callable[[SceneRun], Outcome]] = {
    "finite": check_finite, "analytic_spheres": check_analytic_spheres, "same_as": check_same_as,
    "scale_invariance": check_scale_invariance, "uniform": check_uniform}


# --------------------------------------------------------------------------- api checks
def _nonfinite(*arrays) -> int:
    return int(sum((~np.isfinite(np.asarray(a, dtype=np.float64))).sum() for a in arrays))


def _expected_ff(formula: dict, polygons) -> float:
    name = formula.get("name")
    if name == "parallel_rectangles":
        return formulas.ff_parallel_rectangles(formula["a"], formula["b"], formula["c"])
    if name == "perpendicular_rectangles":
        return formulas.ff_perpendicular_rectangles(formula["l"], formula["w"], formula["h"])
    if name == "quadrature":
        return formulas.ff_quadrature(polygons[0], polygons[1], formula.get("order", 16))
    raise WorkbenchError(f"unknown form-factor formula {name!r} (parallel_rectangles, "
                         "perpendicular_rectangles, quadrature)")


def api_ff_pair(fn, p: dict) -> Outcome:
    """``F[0, 1]`` of two polygons against a closed form (relative error); also reports the
    reciprocity error ``|A0 F01 - A1 F10| / max(A0 F01, A1 F10)`` (1 when one side is 0)."""
    polys = [np.asarray(q, dtype=np.float64) for q in p["polygons"]]
    exp = _expected_ff(p["formula"], polys)
    ff = fn(polys, **p.get("args", {}))
    F = np.asarray(ff)
    A = [0.5 * np.linalg.norm(np.cross(q[1:-1] - q[0], q[2:] - q[0]).sum(0)) for q in polys]
    a01, a10 = A[0] * F[0, 1], A[1] * F[1, 0]
    recip = abs(a01 - a10) / max(a01, a10) if max(a01, a10) > 0 else 0.0
    return Outcome(f"F01 = {exp:.6g} ({p['formula']['name']})",
                   f"F01 = {F[0, 1]:.6g}, F10 = {F[1, 0]:.6g}, reciprocity error {recip:.3g}",
                   abs(F[0, 1] - exp) / exp, _nonfinite(F))


def api_ff_reciprocity(fn, p: dict) -> Outcome:
    """Reciprocity ``A_i F_ij = A_j F_ji`` for the two polygons (relative error), e.g. patches
    of very different sizes."""
    polys = [np.asarray(q, dtype=np.float64) for q in p["polygons"]]
    F = np.asarray(fn(polys, **p.get("args", {})))
    A = [0.5 * np.linalg.norm(np.cross(q[1:-1] - q[0], q[2:] - q[0]).sum(0)) for q in polys]
    a, b = A[0] * F[0, 1], A[1] * F[1, 0]
    return Outcome("A0 F01 = A1 F10", f"A0 F01 = {a:.6g}, A1 F10 = {b:.6g}",
                   abs(a - b) / max(a, b, 1e-300), _nonfinite(F))


def api_ff_closed_rows(fn, p: dict) -> Outcome:
    """Rows of a closed cube's patches sum to 1 (largest |sum - 1|); the hemicube's proximity
    and aliasing errors at shared edges show here (DESIGN errata 6)."""
    F = np.asarray(fn(formulas.cube_faces(p.get("size", 1.0), p.get("subdivisions", 1)), **p.get("args", {})))
    rows = F.sum(1)
    return Outcome("every row sums to 1 (closed enclosure)",
                   f"row sums in [{rows.min():.5f}, {rows.max():.5f}] over {len(rows)} patches",
                   float(np.abs(rows - 1).max()), _nonfinite(F))


def api_ff_zero_area(fn, p: dict) -> Outcome:
    """A degenerate (zero-area) polygon among normal ones: everything finite, its row is 0
    and the other patches' form factors are unchanged (compared with the set without it)."""
    polys = [np.asarray(q, dtype=np.float64) for q in p["polygons"]]
    k = int(p["degenerate"])
    F = np.asarray(fn(polys, **p.get("args", {})))
    F0 = np.asarray(fn([q for i, q in enumerate(polys) if i != k], **p.get("args", {})))
    keep = [i for i in range(len(polys)) if i != k]
    dev = max(float(np.abs(F[k]).max()), float(np.abs(F[np.ix_(keep, keep)] - F0).max()))
    return Outcome("zero row for the degenerate patch, others unchanged",
                   f"|row| max {np.abs(F[k]).max():.3g}, |column| max {np.abs(F[:, k]).max():.3g}",
                   dev, _nonfinite(F, F0))


def api_solve_furnace(fn, p: dict) -> Outcome:
    """A closed cube (exact form factors, :func:`formulas.cube_form_factors`) with every face
    emitting E = 1 and reflectance rho: B = 1 / (1 - rho) everywhere.  Deviation: the true
    relative error, which the solver's stopping rule must keep below ``tol``."""
    rho = float(p["rho"])
    F = formulas.cube_form_factors()
    res = fn(F, np.ones(6), np.full(6, rho), **p.get("args", {}))
    B = np.asarray(res.radiosity, dtype=np.float64).reshape(6, -1)
    exp = 1.0 / (1.0 - rho)
    note = (f"{res.iterations} iterations, converged={res.converged}, claimed bound "
            f"{res.error_bound:.3g}{', ' + res.message if res.message else ''}")
    return Outcome(f"B = 1/(1 - rho) = {exp:.6g}", f"B in [{B.min():.8g}, {B.max():.8g}]",
                   float(np.abs(B - exp).max() / exp), _nonfinite(B), note)


def api_intersect_sphere(fn, p: dict) -> Outcome:
    """Hit distances of rays at impact parameters ``b = fraction * r`` from a sphere's centre
    against the exact value computed in extended precision (``np.longdouble``):
    ``t = d.(c - o) - sqrt(r^2 - b^2)``.  Deviation: largest relative error over rays that must
    hit (``fraction < 1``), infinite if one of them misses or one with ``fraction > 1`` hits
    (a false hit outside the silhouette); ``fraction == 1`` (tangent) may hit or miss."""
    c, r = np.asarray(p["center"], dtype=np.float64), float(p["radius"])
    o0 = np.asarray(p["origin"], dtype=np.float64)
    across = np.asarray(p["across"], dtype=np.float64)
    across /= np.linalg.norm(across)
    d = c - o0
    d -= (d @ across) * across
    d /= np.linalg.norm(d)
    fr = np.asarray(p["fractions"], dtype=np.float64)
    O = o0 + (fr * r)[:, None] * across
    D = np.broadcast_to(d, O.shape).copy()
    scene = scene_from_dict({
        "camera": {"position": list(o0 - d), "look_at": list(o0)},
        "materials": {"m": {}}, "objects": [{"type": "sphere", "material": "m", "center": list(c), "radius": r}]})
    t, normal, _ = fn(scene, O, D)
    ld = np.longdouble
    oc = c.astype(ld) - O.astype(ld)
    tca = (oc * D.astype(ld)).sum(-1)
    disc = ld(r) * ld(r) - ((oc * oc).sum(-1) - tca * tca)
    t_exp = (tca - np.sqrt(np.maximum(disc, 0))).astype(np.float64)
    must, never = fr < 1.0, fr > 1.0
    hit = np.isfinite(t)
    missed, false_hits = int((must & ~hit).sum()), int((never & hit).sum())
    both = must & hit
    rel = float((np.abs(t[both] - t_exp[both]) / np.abs(t_exp[both])).max()) if both.any() else 0.0
    tangent = ~must & ~never
    return Outcome("t = d.(c-o) - sqrt(r^2 - b^2) (long double); no hit beyond r",
                   f"max rel. error {rel:.3g}; {missed} missed, {false_hits} false hit(s) beyond r; "
                   f"tangent: {int((tangent & hit).sum())}/{int(tangent.sum())} hit",
                   float("inf") if missed or false_hits else rel, _nonfinite(np.where(hit, t, 0.0), normal))


def api_refraction_critical(fn, p: dict) -> Outcome:
    """``fn(D, N, n1, n2) -> (T, cos_i, cos_t)``, ``T = None`` on total internal reflection,
    at incidence angles ``theta_c * (1 + k)`` for the relative offsets ``k`` of ``offsets``
    (``theta_c = asin(n2 / n1)``).  Below: T unit and Snell's law ``n1 sin_i = n2 sin_t``
    (deviation: largest residual); at or above: TIR (or a grazing T).  Never NaN."""
    n1, n2 = float(p["n1"]), float(p["n2"])
    tc = np.arcsin(n2 / n1)
    N = np.array([0.0, 1.0, 0.0])
    worst, bad, nonfin, tir = 0.0, 0, 0, 0
    for k in p["offsets"]:
        th = tc * (1.0 + float(k))
        D = np.array([np.sin(th), -np.cos(th), 0.0])
        T, _, _ = fn(D, N, n1, n2)
        if T is None:
            tir += 1
            bad += int(th < tc * (1 - 1e-9))
            continue
        T = np.asarray(T, dtype=np.float64)
        nonfin += _nonfinite(T)
        sin_t = np.linalg.norm(np.cross(T, N))
        worst = max(worst, abs(n1 * np.sin(th) - n2 * sin_t), abs(np.linalg.norm(T) - 1))
    return Outcome(f"Snell below theta_c = {np.degrees(tc):.6f} deg, TIR above",
                   f"Snell residual {worst:.3g}; {tir} TIR of {len(p['offsets'])}; {bad} TIR below theta_c",
                   worst + bad, nonfin)


def api_texture_seams(fn, p: dict) -> Outcome:
    """Spherical mapping ``fn(texture, P) -> (u, v)`` at the exact poles, on both sides of the
    seam and at points rounding-close to the pole: finite, in [0, 1], and v equal to the polar
    angle / pi (computed in long double), and u the same on both sides of the seam (circular
    distance; u is free at the poles).  Deviation: largest error."""
    from ..scene.model import Texture
    tex = Texture("checker", projection="spherical", pole=(0.0, 1.0, 0.0), equator=(1.0, 0.0, 0.0))
    eps = [float(e) for e in p.get("epsilons", [0.0, 1e-300, 1e-17, 1e-9])]
    pts, pole = [], []
    for e in eps:
        for sgn in (1.0, -1.0):  # next to the north and south poles, on the seam side
            pts.append([e, sgn, 0.0]); pole.append(True)
        for s in (1.0, -1.0):  # either side of the seam on the equator
            pts.append([-1.0, 0.0, s * e]); pole.append(False)
    P = np.asarray(pts, dtype=np.float64)
    ld = P.astype(np.longdouble)
    h = ld[:, 1]
    rho = np.sqrt(ld[:, 0] ** 2 + ld[:, 2] ** 2)
    v_exp = np.arctan2(rho, -h) / np.pi
    uv = np.asarray(fn(tex, P), dtype=np.float64)
    nonfin = _nonfinite(uv)
    uvf = np.nan_to_num(uv, nan=-1.0)
    out_of_range = int(((uvf < 0) | (uvf > 1)).sum())
    dv = float(np.abs(uvf[:, 1] - v_exp.astype(np.float64)).max())
    seam = ~np.asarray(pole)
    u = uvf[seam, 0]
    du = float(np.abs((u - u[0] + 0.5) % 1.0 - 0.5).max())  # seam points: all the same longitude
    return Outcome("v = polar angle / pi; u continuous across the seam; all in [0, 1]",
                   f"max |dv| {dv:.3g}, seam |du| {du:.3g}, {out_of_range} out of [0, 1]",
                   max(dv, du) + out_of_range, nonfin)


API_CHECKS: dict[str, Callable[[Callable, dict], Outcome]] = {
    "ff_pair": api_ff_pair, "ff_reciprocity": api_ff_reciprocity, "ff_closed_rows": api_ff_closed_rows,
    "ff_zero_area": api_ff_zero_area, "solve_furnace": api_solve_furnace,
    "intersect_sphere": api_intersect_sphere, "refraction_critical": api_refraction_critical,
    "texture_seams": api_texture_seams}


# --------------------------------------------------------------------------- running
def resolve_callable(dotted: str) -> Callable:
    """``"workbench.radiosity.form_factors"`` -> the function (lazy package aliases work)."""
    mod, _, attr = dotted.rpartition(".")
    if not mod:
        raise ImportError(f"{dotted!r} is not a dotted name")
    try:
        obj = importlib.import_module(mod)
    except ImportError:
        parent, _, sub = mod.rpartition(".")
        obj = getattr(importlib.import_module(parent), sub)
    if not hasattr(obj, attr):
        raise ImportError(f"{mod} has no attribute {attr!r}")
    return getattr(obj, attr)


def _verdict(row: Row, out: Outcome) -> str:
    if out.nonfinite:
        return f"breaks: {out.nonfinite} NaN/Inf value(s) produced"
    if not np.isfinite(out.deviation) or out.deviation > row.tolerance:
        return f"inaccurate: by {out.deviation:.3g} (tolerance {row.tolerance:.3g})"
    return "ok"


def run_case(cat: Catalogue, case: dict, method: str) -> Row:
    """One row; never raises for a method's failure (the row says how it broke)."""
    row = Row(case["id"], case["title"], method, tolerance=float(per_method(case, "tolerance", method, 0.0)))
    t0 = time.perf_counter()
    try:
        if case["kind"] == "scene":
            if method not in available():
                row.verdict = f"unavailable: method {method} not registered"
                return row
            run = SceneRun(cat, case, method)
            out = SCENE_CHECKS[case["check"]](run)
            shown = [f"{k} = {run.stats[k]}" for k in case.get("note_stats", []) if k in run.stats]
            out.note = "; ".join(([out.note] if out.note else []) + shown)
            row.features_used, row.left_out = run.features_used, run.left_out
        else:
            try:
                fn = resolve_callable(case["call"])
            except (ImportError, AttributeError) as e:
                row.verdict = f"unavailable: {case['call']} not importable ({e}; method {method})"
                return row
            out = API_CHECKS[case["check"]](fn, case.get("params", {}))
        row.expected, row.measured, row.deviation = out.expected, out.measured, out.deviation
        row.nonfinite, row.note = out.nonfinite, out.note
        row.verdict = _verdict(row, out)
    except NotApplicable as e:
        row.verdict = f"unavailable: {method} does not apply: {e}"
    except ImportError as e:  # registered, but its module has not landed or does not import
        row.verdict = f"unavailable: method {method} cannot be loaded ({e})"
    except WorkbenchError as e:
        row.verdict = (f"ok: rejected with a clear error: {e}" if case.get("accept_error")
                       else f"breaks: {type(e).__name__}: {e}")
    except Exception as e:  # noqa: BLE001 -- the case reports where and how a method breaks
        row.verdict = f"breaks: {type(e).__name__}: {e}"
    finally:
        row.time_s = time.perf_counter() - t0
    return row


def select(cat: Catalogue, only: str | None) -> list[dict]:
    """Cases whose id matches the shell pattern ``only`` (all when None); none is an error."""
    if not only:
        return cat.cases
    pat = only if any(ch in only for ch in "*?[") else f"*{only}*"
    chosen = [c for c in cat.cases if fnmatch.fnmatch(c["id"], pat)]
    if not chosen:
        raise WorkbenchError(f"--only {only!r} matches no case (ids: {', '.join(c['id'] for c in cat.cases)})")
    return chosen


def _case_job(cat: Catalogue, job: tuple[dict, str]) -> Row:
    case, method = job
    return run_case(cat, case, method)


def stress(out_dir: str | Path, only: str | None = None, catalogue: str | Path = CATALOGUE,
           progress: bool = False, command: str = "", jobs: int = 1, cluster: str | None = None) -> dict:
    """Run the catalogue (or the cases matching ``only``) and write ``stress.csv``,
    ``stress.json``, ``stress.md`` and ``stress.html`` into ``out_dir``.

    The (case, method) rows run in this process (``jobs = 1``), in ``jobs`` local worker
    processes, or on the workers of the Dask scheduler at ``cluster`` (``tcp://HOST:8786``;
    needs ``workbench[cluster]``; a case's scene files must be readable there at the same
    path): :mod:`.executors`.  The rows come in the catalogue's order whichever ran them; their
    ``time_s`` is measured where they ran."""
    cat = Catalogue(catalogue)
    cases = select(cat, only)
    grid = [(c, m) for c in cases for m in cat.methods(c)]
    from tqdm import tqdm
    from .executors import open_executor
    with open_executor(jobs, cluster) as ex:
        with tqdm(total=len(grid), desc="stress", unit="case", disable=not progress, leave=False) as bar:
            rows = ex.map(_case_job, grid, shared=cat, done=lambda _: bar.update())
        executor = ex.describe()
    result = {"kind": "stress", "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
              "command": command, "catalogue": str(cat.path), "registered_methods": available(),
              "executor": executor,
              "cases": [{"id": c["id"], "title": c["title"], "kind": c["kind"], "check": c["check"],
                         "methods": cat.methods(c)} for c in cases],
              "rows": [asdict(r) for r in rows], "summary": summary(rows), "machine": machine_info()}
    with staged(out_dir, last=("stress.json", "stress.html")) as stage:
        (stage / "stress.csv").write_text(to_csv(rows))
        (stage / "stress.md").write_text(to_markdown(rows))
        (stage / "stress.json").write_text(dumps(result))
        (stage / "stress.html").write_text(to_html(result, rows))
    return jsonable(result, strict=False)


def summary(rows: list[Row]) -> dict:
    out: dict[str, int] = {}
    for r in rows:
        key = r.verdict.split(":", 1)[0]
        out[key] = out.get(key, 0) + 1
    return out


FIELDS = ["case", "method", "expected", "measured", "deviation", "tolerance", "nonfinite", "time_s",
          "verdict", "note", "title"]


def to_csv(rows: list[Row]) -> str:
    buf = io.StringIO()
    wr = csv.DictWriter(buf, FIELDS, lineterminator="\n")
    wr.writeheader()
    for r in rows:
        wr.writerow({k: getattr(r, k) for k in FIELDS})
    return buf.getvalue()


def _md(x) -> str:
    return (f"{x:.3g}" if isinstance(x, float) else str(x)).replace("|", "\\|")


def to_markdown(rows: list[Row]) -> str:
    head = ["case", "method", "expected", "measured", "deviation", "NaN/Inf", "time (s)", "verdict"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        lines.append("| " + " | ".join(_md(x) for x in (r.case, r.method, r.expected, r.measured, r.deviation,
                                                          r.nonfinite, r.time_s, r.verdict)) + " |")
    return "\n".join(lines) + "\n"


def to_html(result: dict, rows: list[Row]) -> str:
    cls = ["ok" if r.verdict.startswith("ok") else "muted" if r.verdict.startswith("unavailable")
           else "warn" if r.verdict.startswith("inaccurate") else "bad" for r in rows]
    body = [f"<h1>Stiff and extreme cases</h1><p>{esc(result['summary'])} · catalogue "
            f"{esc(result['catalogue'])} · {esc(result['created'])}</p>",
            table(["case", "what", "method", "expected", "measured", "deviation", "tol.", "NaN/Inf", "time (s)",
                   "verdict", "note"],
                  [[r.case, r.title, r.method, r.expected, r.measured, r.deviation, r.tolerance, r.nonfinite,
                    r.time_s, r.verdict, r.note] for r in rows], numeric={5, 6, 7, 8}, row_class=cls),
            "<h2>Machine</h2>", table(["key", "value"], [[k, v] for k, v in result["machine"].items()])]
    return page("stress report", "\n".join(body))
