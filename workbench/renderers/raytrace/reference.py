"""Readable reference of the ray tracer, one ray at a time, in the course's structure::

    raytrace(recurs, threshold, ray):            # "Module Trace"
        if intersect(ray, scene):                # "Module Intersection" (CSG recursion)
            shade(point, normal, ...)            # "Module shade": shadow feelers, then
        else: background(ray)                    #   reflection / transmission recursion

Whitted, "An improved illumination model for shaded display" (CACM 1980).  Same options and
the same numerics as the numba kernels (:mod:`.kernels`), which are tested against this on
small images; :func:`ray_tree` returns the tree of one pixel (for the UI).

Local shading is :func:`workbench.renderers.local_model.shade` itself, textures and bump are
:mod:`workbench.renderers.texturing`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ...core.tol import offset_scale, tol
from ...scene import model as m
from ...scene.features import scene_needs
from ...scene.kinds import MESH, crossings, kind_of
from ...scene.kinds.csg import is_solid
from ...scene.prepared import prepare
from .. import local_model
from . import shapes
from .flatten import MAX_CUTOUTS, OPACITY_CUT, SHADOW_CROSSINGS

DEFAULTS = dict(max_depth=5, threshold=1e-3, fresnel="none", transmissive_shadows=False,
                blinn=False, shadows=True)


@dataclass
class Item:
    """A top-level object: scene index, geometry, world_from_object, casts shadows."""

    index: int
    obj: m.SceneObject
    W: np.ndarray
    shadow: bool = True


@dataclass
class Hit:
    t: float
    P: np.ndarray
    Ng: np.ndarray          # unit outward geometric normal
    Ns: np.ndarray          # unit shading normal
    item: Item
    material: m.Material
    P_obj: np.ndarray
    W: np.ndarray           # world_from_object of the leaf that was hit
    uv: Any = None
    emission: Any = 0.0     # interpolated vertex emission (meshes)
    solid: bool = True


class Context:
    """The scene made ready for the reference tracer."""

    def __init__(self, scene: m.Scene, **options):
        self.scene = scene
        self.opts = {**DEFAULTS, **options}
        self.prepared = prepare(scene)
        self.extent = self.prepared.extent
        self.lights = scene.point_lights()
        self.items = [Item(i, o, np.asarray(o.world_from_object)) for i, o in enumerate(scene.objects)]
        self.materials = dict(scene.materials)
        for k, polygon, mat in self.prepared.area_lights:
            self.materials[mat.name] = mat
            self.items.append(Item(len(scene.objects) + k, polygon, np.eye(4), shadow=False))
        self.texturing = None
        if {"textures", "bump", "environment", "opacity"} & scene_needs(scene):
            from .. import texturing
            self.texturing = texturing

    def offset(self, P) -> float:
        return offset_scale(float(np.abs(P).max()), self.extent)


# ----------------------------------------------------------------------------- intersection
def _mesh_hit(ctx, item, O, D, tmin, tmax):
    mesh, W = item.obj, item.W
    V = np.asarray(mesh.vertices) @ W[:3, :3].T + W[:3, 3]
    F = np.asarray(mesh.faces)
    t, b1, b2 = shapes.triangles(V[F], O, D)
    t = np.where((t > tmin) & (t < tmax), t, np.inf)
    k = int(np.argmin(t))
    if not np.isfinite(t[k]):
        return None
    P = O + t[k] * D
    tri = V[F[k]]
    Ng = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    Ng /= np.linalg.norm(Ng)
    w = np.array([1 - b1[k] - b2[k], b1[k], b2[k]])
    Ns = Ng
    if mesh.normals is not None:
        nw = np.asarray(mesh.normals)[F[k]] @ np.linalg.inv(W[:3, :3])
        nw = nw / np.linalg.norm(nw, axis=1, keepdims=True)
        n = w @ nw
        Ns = n / np.linalg.norm(n) if np.linalg.norm(n) > tol.normal_cancel else Ng
    uv = w @ np.asarray(mesh.uvs)[F[k]] if mesh.uvs is not None else None
    em = w @ np.asarray(mesh.vertex_emission)[F[k]] if mesh.vertex_emission is not None else 0.0
    inv = np.linalg.inv(W)
    return Hit(t[k], P, Ng, Ns, item, ctx.materials[mesh.material], inv[:3, :3] @ P + inv[:3, 3], W,
               uv, em)


def closest(ctx: Context, O, D, tmin, tmax=np.inf, shadow=False) -> Hit | None:
    """The nearest hit in ``(tmin, tmax)`` over every object ("find_closest").  Surfaces
    closer along the ray than the secondary rays' offset are coincident: the object listed
    first wins (a later one must be nearer by more than that), as in the kernels' ``nearer``."""
    best = None
    eps = tol.ray_offset * max(float(np.abs(O).max()), ctx.extent)
    w = eps / float(np.linalg.norm(D))
    for item in ctx.items:
        if shadow and not item.shadow:
            continue
        if kind_of(item.obj).PTYPE == MESH:  # world triangles (a BVH in the kernels)
            h = _mesh_hit(ctx, item, O, D, tmin, best.t - w if best else tmax)
            best = h or best
            continue
        for c in crossings(item.obj, np.eye(4), O, D, eps):
            if tmin < c.t < (best.t - w if best else tmax):
                leaf, Wl = c.leaf
                P = O + c.t * D
                inv = np.linalg.inv(Wl)
                p_obj = inv[:3, :3] @ P + inv[:3, 3]
                kind = kind_of(leaf)
                n = inv[:3, :3].T @ kind.normal(leaf, c.face, p_obj)
                n = (-n if c.flip else n) / np.linalg.norm(n)
                solid = is_solid(leaf, kind_of)
                best = Hit(c.t, P, n, n, item, ctx.materials[leaf.material], p_obj, Wl, solid=solid)
                break
            if c.t >= tmin:
                break
    return best


# ----------------------------------------------------------------------------- shading
def shadow_feeler(ctx, P, Ng, L, dist) -> float:
    """Visibility of a light from ``P`` (the course's shadow feeler): 1 or 0; a surface with an
    opacity map lets ``1 - alpha`` through (all of it where it is cut out, alpha < 0.5, as for
    the rays it cuts), and with ``transmissive_shadows`` a surface also lets ``alpha kt``
    through: the product over the surfaces crossed."""
    off = ctx.offset(P)
    side = 1.0 if Ng @ L >= 0 else -1.0
    Q = P + side * off * Ng
    tmax = dist - 2 * off if np.isfinite(dist) else np.inf
    tmin = tol.t_min * max(float(np.abs(P).max()), ctx.extent)
    v = 1.0
    for _ in range(SHADOW_CROSSINGS):
        h = closest(ctx, Q, L, tmin, tmax, shadow=True)
        if h is None:
            return v
        a = alpha(ctx, h)
        v *= 1.0 - a + (a * h.material.kt if ctx.opts["transmissive_shadows"] else 0.0)
        if v <= 0.0:
            return 0.0
        tmin = h.t + tol.ray_offset * max(float(np.abs(Q).max()), ctx.extent)
    return v


def _media_after_exit(media: list, mat: m.Material) -> list:
    out = list(media)
    for q in range(len(out) - 1, -1, -1):
        if out[q] is mat:
            del out[q]
            break
    return out


def refraction(D, Nf, n1, n2):
    """Snell-Descartes (course: ``T = [eta (N.L) - sqrt(1 - eta^2 (1 - (N.L)^2))] N - eta L``
    with ``L = -D``, ``N`` on the incident side, ``eta = n1 / n2``; errata 5).  Returns
    ``(T, cos_i, cos_t)``, ``T = None`` on total internal reflection (radicand <= 0; at exactly
    the critical angle the transmitted ray would graze the surface with no energy)."""
    eta = n1 / n2
    cosi = -(D @ Nf)
    k = 1.0 - eta * eta * (1.0 - cosi * cosi)
    if k <= 0.0:
        return None, cosi, 0.0
    cost = np.sqrt(k)
    T = eta * D + (eta * cosi - cost) * Nf
    return T / np.linalg.norm(T), cosi, cost


def fresnel(mode, n1, n2, cosi, cost) -> float:
    """Reflected fraction: Schlick (1994) or the exact dielectric Fresnel equations."""
    if mode == "schlick":
        r0 = ((n1 - n2) / (n1 + n2)) ** 2
        c = cosi if n1 <= n2 else cost
        return r0 + (1 - r0) * (1 - c) ** 5
    rs = (n1 * cosi - n2 * cost) / (n1 * cosi + n2 * cost)
    rp = (n2 * cosi - n1 * cost) / (n2 * cosi + n1 * cost)
    return 0.5 * (rs * rs + rp * rp)


def background(ctx, D):
    if ctx.scene.environment is not None and ctx.texturing is not None:
        return ctx.texturing.environment(ctx.scene.environment, D[None])[0]
    return np.asarray(ctx.scene.background, dtype=np.float64)


def raytrace(ctx: Context, O, D, recurs=0, weight=np.ones(3), media=(), tmin=0.0, tree=None):
    """Radiance along a ray (the course's ``raytrace``); appends a node to ``tree`` if given."""
    node = dict(origin=O.tolist(), direction=D.tolist(), depth=recurs, weight=weight.tolist(),
                children=[], shadow_feelers=[])
    if tree is not None:
        tree.append(node)
    hit, a = visible_hit(ctx, O, D, tmin)
    if hit is None:
        node.update(object=None, stop="left the scene")
        return background(ctx, D)
    node.update(t=float(hit.t), object=hit.item.index)
    if tree is not None:  # names for the ray tree only, not on every ray of an image
        obj = hit.item.obj
        node.update(object_name=obj.name or f"{obj.kind} {hit.item.index}", material=obj.material)
    att = np.ones(3)
    if media:
        att = np.exp(-np.asarray(media[-1].absorption) * hit.t)
    color = a * att * shade(ctx, hit, D, recurs, weight * att * a, list(media), node)
    if a < 1.0:  # alpha blending: the ray also goes on, straight through
        sub: list = []
        color = color + (1 - a) * raytrace(ctx, O, D, recurs, weight * (1 - a), media, past(ctx, hit), sub)
        node["children"].append(dict(kind="transparency", coefficient=1 - a, ray=sub[0]))
    return color


def past(ctx, hit) -> float:
    """``tmin`` just beyond a hit (offset scaled with the hit point)."""
    return hit.t + tol.ray_offset * max(float(np.abs(hit.P).max()), ctx.extent)


def alpha(ctx, hit) -> float:
    """Opacity of the surface at a hit: its opacity map's alpha, 0 where below 0.5 (cut out),
    1 without a map."""
    if hit.material.opacity is None or ctx.texturing is None:
        return 1.0
    uv = None if hit.uv is None else hit.uv[None]
    a = float(ctx.texturing.alpha(hit.material, hit.P_obj[None], (hit.Ns @ hit.W[:3, :3])[None], uv)[0])
    return a if a >= OPACITY_CUT else 0.0


def visible_hit(ctx, O, D, tmin):
    """The closest hit not cut out by an opacity map (alpha < 0.5), and its alpha."""
    for _ in range(MAX_CUTOUTS):
        hit = closest(ctx, O, D, tmin)
        if hit is None:
            return None, 1.0
        a = alpha(ctx, hit)
        if a > 0.0:
            return hit, a
        tmin = past(ctx, hit)
    return None, 1.0


def shade(ctx, hit: Hit, D, recurs, weight, media, node):
    """Local model with shadow feelers, then reflection / transmission (the course's ``shade``)."""
    opts, mat = ctx.opts, hit.material
    S = -D
    front = hit.Ng @ S > 0
    Nf = hit.Ng if front else -hit.Ng
    Ns, C = hit.Ns, np.asarray(mat.color, dtype=np.float64)
    tx = ctx.texturing
    if tx is not None and mat.texture is not None:
        C = tx.surface_color(mat, hit.P_obj[None], (Ns @ hit.W[:3, :3])[None], None if hit.uv is None else hit.uv[None])[0]
    if tx is not None and mat.bump is not None:
        Ns = tx.bump_normal(mat, hit.P_obj[None], (Ns @ hit.W[:3, :3])[None], Ns[None], hit.W,
                            None if hit.uv is None else hit.uv[None])[0]
    if mat.name.startswith(m.AREA_LIGHT_PREFIX) and not front:
        mat = replace(mat, emission=(0.0, 0.0, 0.0))
    emitted = hit.emission if front else 0.0  # vertex emission: front side only (Mesh.vertex_emission)
    vis = np.ones((len(ctx.lights), 1))
    if opts["shadows"]:
        Nv = Ns if Ns @ S >= 0 else -Ns
        for li, light in enumerate(ctx.lights):
            L, I, dist = local_model.light_incidence(light, hit.P[None])
            if Nv @ L[0] <= 0 or not I[0].any():
                continue
            vis[li, 0] = shadow_feeler(ctx, hit.P, hit.Ng, L[0], dist[0])
            node["shadow_feelers"].append(dict(light=li, visibility=float(vis[li, 0])))
    color = local_model.shade(hit.P[None], Ns[None], S[None], C, mat, ctx.lights, ctx.scene.ambient,
                              vis, opts["blinn"])[0] + emitted
    kr, kt = mat.kr, mat.kt
    if kr <= 0 and kt <= 0:
        node["stop"] = "no reflection or transmission"
        return color
    wr, wt, T, new_media = kr, kt, D, media
    if kt > 0 and hit.solid:
        if front:
            n1 = media[-1].ior if media else 1.0
            n2, new_media = mat.ior, media + [mat]
        else:
            n1, new_media = mat.ior, _media_after_exit(media, mat)
            n2 = new_media[-1].ior if new_media else 1.0
        T, cosi, cost = refraction(D, Nf, n1, n2)
        if T is None:
            wr, wt = kr + kt, 0.0
            node["total_internal_reflection"] = True
        elif opts["fresnel"] != "none":
            F = fresnel(opts["fresnel"], n1, n2, cosi, cost)
            wr, wt = kr + kt * F, kt * (1 - F)
    off = ctx.offset(hit.P)
    for kind, k in (("reflection", wr), ("refraction", wt)):
        if k <= 0:
            continue
        child = dict(kind=kind, coefficient=float(k))
        node["children"].append(child)
        if recurs + 1 >= opts["max_depth"]:
            child["stop"] = "max depth"
            continue
        if (weight * k).max() <= opts["threshold"]:
            child["stop"] = "threshold"
            continue
        sub: list = []
        if kind == "reflection":
            Nr = Ns if Ns @ S >= 0 else -Ns
            R = D - 2 * (D @ Nr) * Nr
            if R @ Nf <= 0:
                R = D - 2 * (D @ Nf) * Nf
            R = R / np.linalg.norm(R)
            origin, direction, md = hit.P + off * Nf, R, media
        else:
            origin, direction, md = hit.P - off * Nf, T, new_media if hit.solid else media
        tmin = tol.t_min * max(float(np.abs(origin).max()), ctx.extent)
        color = color + k * raytrace(ctx, origin, direction, recurs + 1, weight * k, tuple(md), tmin, sub)
        child["ray"] = sub[0]
    return color


# ----------------------------------------------------------------------------- entry points
def render(scene: m.Scene, width: int, height: int, **options) -> np.ndarray:
    """The reference image (H, W, 3) float64, one ray per pixel centre (slow: small images)."""
    ctx = Context(scene.with_camera(scene.camera.with_resolution(width, height)), **options)
    O, D = ctx.scene.camera.rays()
    media = ctx.prepared.camera_media
    img = np.zeros((height, width, 3))
    for i in range(height):
        for j in range(width):
            img[i, j] = raytrace(ctx, O[i, j], D[i, j], media=media)
    return img


def ray_tree(scene: m.Scene, i: int, j: int, **options) -> dict:
    """The ray tree of pixel (row ``i``, column ``j``) at the camera's resolution.

    Returns a nested dict: ``origin``, ``direction``, ``depth``, ``weight`` (accumulated RGB),
    ``t``, ``object`` (scene index or None), ``object_name`` (its ``name`` in the scene file, else
    its kind and index, e.g. ``"sphere 2"``), ``material`` (its material's name), ``shadow_feelers`` (light index and visibility),
    ``children`` (each ``kind`` reflection / refraction, its ``coefficient`` and either a
    ``ray`` node or a ``stop`` reason: max depth / threshold), ``stop`` (why this ray did not
    continue: left the scene, no reflection or transmission), ``total_internal_reflection``,
    and ``color``, the pixel's radiance.
    """
    ctx = Context(scene, **options)
    O, D = scene.camera.rays()
    tree: list = []
    color = raytrace(ctx, O[i, j], D[i, j], media=ctx.prepared.camera_media, tree=tree)
    root = tree[0]
    root["color"] = color.tolist()
    return root
