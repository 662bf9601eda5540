"""Object kind ``csg``: constructive solid geometry, ``op`` (union, intersection, difference)
of two solids, each with its own transform applied after the node's.  The one composite kind:
its functions receive the registry's dispatch (``kind_of``, or the recursive function itself)
so that any solid kind can be a leaf without this module importing the registry.

Ray tracing by interval lists (Roth 1982; the course's ``intersect`` / ``composite_intersect``):
along a ray, a solid is a sorted list of boundary crossings that alternate entering / leaving.
Combining two solids sweeps both lists in order and keeps a crossing wherever the boolean of
"inside left" and "inside right" changes.  Crossings closer than ``eps`` are one event
(coincident surfaces: ``A - A`` is empty, ``A n A = A u A = A``), and intervals shorter than
``eps`` are dropped.  A difference turns the right solid inside out: its surfaces' normals are
flipped.  Readable version here (lists of :class:`Crossing`);
:func:`workbench.renderers.kernels.shapes.combine` is the numba twin, over the postfix
program :func:`flatten` writes.

Raster by real mesh booleans (manifold3d): each leaf is tessellated as a closed, welded solid
in world space and tagged with its index as an extra vertex property; manifold3d carries
properties through the booleans, so every output triangle knows the leaf it comes from.
Normals are then rebuilt from the leaf: analytic for spheres and quadrics (flipped when the
leaf bounds the result from its other side, i.e. the inside of a subtracted solid), the
triangle's own for boxes and meshes.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ...core import transform as tf
from ...core.columns import Columns, pack
from ...core.errors import WorkbenchError
from .. import model as m, readers as rd
from ..parts import Part, triangle_normals

TYPE = "csg"
MODEL = m.CSG
FEATURE = "csg"
PTYPE = CSGNODE = 5
SOLID = True
COMPOSITE = True
CONVEX = False
CLOSED_TESSELLATION = True
KERNELS = None
KEYS = frozenset({"op", "left", "right"})
REQUIRED = frozenset({"op", "left", "right"})
CSG_UNION, CSG_INTERSECTION, CSG_DIFFERENCE = -1, -2, -3
CSG_DEPTH = 16
"""Interval lists a CSG program may hold at once (the kernels' scratch stack; numba does not
check bounds, so deeper trees are refused when the scene is flattened)."""
_CSG_OPS = {"union": CSG_UNION, "intersection": CSG_INTERSECTION, "difference": CSG_DIFFERENCE}


def parse(ctx: rd.Ctx, t: dict, w: str, common: dict, child, kind_of) -> m.CSG:
    """``child(table, where, inherited_material)`` parses an operand (any kind)."""
    op = rd.string(ctx, t, w, "op", choices=("union", "intersection", "difference"))
    left = child(t["left"], f"{w}.left", common["material"])
    right = child(t["right"], f"{w}.right", common["material"])
    for side, c in (("left", left), ("right", right)):
        if getattr(kind_of(c), "MEDIUM", False):
            ctx.fail(f"{w}.{side}.type", f"CSG needs solid surfaces; a {c.kind} is a participating medium")
        if not is_solid(c, kind_of):
            ctx.fail(f"{w}.{side}.type", f"CSG needs solids; a {c.kind} has no inside"
                     + (" (an open lathe profile: end it where it starts, or on the axis)" if c.kind == "lathe" else ""))
    return m.CSG(**common, op=op, left=left, right=right)


def is_solid(obj: m.SceneObject, kind_of) -> bool:
    """Has an inside: its kind's ``SOLID``, or, for a kind whose objects differ (a lathe is a
    solid when its profile is closed), its ``solid(obj)``."""
    kind = kind_of(obj)
    return kind.solid(obj) if hasattr(kind, "solid") else kind.SOLID


def children(node: m.CSG) -> tuple:
    return (node.left, node.right)


# --------------------------------------------------------------------------- raster
def _leaf_manifold(leaf: m.SceneObject, M: np.ndarray, level: int, leaf_id: int, kind_of):
    """Closed manifold of one leaf in world space, vertex properties (x, y, z, leaf_id)."""
    import manifold3d
    if not is_solid(leaf, kind_of):
        raise WorkbenchError(f"CSG needs solids; a {leaf.kind} has no inside")
    P, F = kind_of(leaf).solid_mesh(leaf, level)
    Pw = tf.transform_points(M, P)
    if np.linalg.det(M[:3, :3]) < 0:  # a mirroring transform turns the winding inside out
        F = F[:, ::-1]
    props = np.concatenate([Pw, np.full((len(Pw), 1), float(leaf_id))], 1).astype(np.float32)
    man = manifold3d.Manifold(manifold3d.Mesh(vert_properties=np.ascontiguousarray(props),
                                              tri_verts=np.ascontiguousarray(F, dtype=np.uint32)))
    if man.status() != manifold3d.Error.NoError:
        raise WorkbenchError(f"CSG leaf {leaf.name or leaf.kind!r} is not a closed manifold ({man.status()})")
    return man


def _build(node: m.SceneObject, M: np.ndarray, level: int, leaves: list, kind_of):
    """Recursive boolean; ``leaves`` collects (leaf, world_from_leaf) by leaf id."""
    Mn = M @ node.world_from_object
    if not isinstance(node, m.CSG):
        leaves.append((node, Mn))
        return _leaf_manifold(node, Mn, int(node.tessellation or level), len(leaves) - 1, kind_of)
    a = _build(node.left, Mn, level, leaves, kind_of)
    b = _build(node.right, Mn, level, leaves, kind_of)
    return {"union": a + b, "intersection": a ^ b, "difference": a - b}[node.op]


def _leaf_normals(leaf: m.SceneObject, M: np.ndarray, Pw: np.ndarray, tri_n: np.ndarray, kind_of) -> np.ndarray:
    """Shading normals (3T, 3) for the unwelded triangles (T, 3, 3) ``Pw`` of one leaf:
    analytic where its kind has them (spheres and quadric surfaces), the triangle's own
    elsewhere (boxes, meshes, the caps that close a quadric at its bounds)."""
    flat = np.repeat(tri_n, 3, axis=0)
    P = Pw.reshape(-1, 3)
    P_obj = tf.transform_points(np.linalg.inv(M), P)
    analytic = kind_of(leaf).analytic_normals(leaf, P_obj)
    if analytic is None:
        return flat
    n_obj, cap = analytic
    N = tf.transform_normals(M, n_obj)
    # a leaf seen from its inside (subtracted): flip by the area-weighted majority
    if np.sum(N[~cap] * flat[~cap]) < 0:
        N = -N
    ok = (np.linalg.norm(N, axis=-1) > 0.5) & ~cap
    return np.where(ok[:, None], N, flat)


def _canonical_order(Pw: np.ndarray, Ml: np.ndarray) -> np.ndarray:
    """An order of triangles ``Pw`` (T, 3, 3) that does not depend on the scene's scale:
    manifold3d returns a boolean's triangles in an order of its own, which changes when the
    world is scaled (the radiosity patches cut from them, one per triangle, came out
    permuted); sorted by their centroids in the leaf's object space (unscaled), rounded to
    1e-9 of its size so that rounding does not reorder them."""
    c = tf.transform_points(np.linalg.inv(Ml), Pw.mean(1))
    size = max(float(np.abs(c).max(initial=0.0)), 1e-300)
    q = np.round(c / size * 1e9)
    return np.lexsort((q[:, 2], q[:, 1], q[:, 0]))


def tessellate(node: m.CSG, level: int, parent: np.ndarray, kind_of) -> list[Part]:
    """Parts of a CSG node (one per leaf whose surface survives the boolean).

    Parameters
    ----------
    node : the CSG node; level : tessellation level of its leaves;
    parent : (4, 4) transform applied after the node's own ``world_from_object`` (identity
        for a top-level object).
    """
    leaves: list = []
    result = _build(node, parent, level, leaves, kind_of)
    mesh = result.to_mesh()
    props = np.asarray(mesh.vert_properties, dtype=np.float64)
    F = np.asarray(mesh.tri_verts, dtype=np.int64)
    if len(F) == 0:
        return []
    leaf_of_tri = np.rint(props[F[:, 0], 3]).astype(np.int64)
    parts = []
    for i, (leaf, Ml) in enumerate(leaves):
        Fi = F[leaf_of_tri == i]
        if len(Fi) == 0:
            continue
        Pw = props[Fi][:, :, :3]  # (T, 3, 3), unwelded
        Pw = Pw[_canonical_order(Pw, Ml)]
        tri_n = triangle_normals(Pw.reshape(-1, 3), np.arange(3 * len(Fi)).reshape(-1, 3))
        N = _leaf_normals(leaf, Ml, Pw, tri_n, kind_of)
        P = Pw.reshape(-1, 3)
        faces = np.arange(len(P), dtype=np.int64).reshape(-1, 3)
        parts.append(Part(node.name or leaf.name, "csg", leaf.material, Ml, P, tf.normalize(N),
                          tf.transform_points(np.linalg.inv(Ml), P), None, faces, tri_n, Pw.mean(1)))
    return parts


def patch_surfaces(node: m.CSG, W: np.ndarray, h: float):
    """Curved: cut from its tessellation (None)."""
    return None


# --------------------------------------------------------------------------- ray tracing
class Par(Columns):
    """Its columns of the primitive table's ``par``: its postfix program in ``prog``."""

    START = 0
    LENGTH = 1


def flatten(b, node: m.CSG, index: int, W: np.ndarray, top: bool) -> int:
    """The tree as a postfix program over its leaves' rows (``b.leaf``, not intersected on
    their own) and one row ``par = (program start, program length)``."""
    start = len(b.prog)
    _program(b, node, index, W)
    depth = height = 0
    for code in b.prog[start:]:  # leaves push an interval list, operators pop two
        height += 1 if code >= 0 else -1
        depth = max(depth, height)
    if depth > CSG_DEPTH:
        raise WorkbenchError(f"CSG object {node.name or index + 1}: its tree needs {depth} interval lists "
                             f"at once, the ray tracer holds {CSG_DEPTH} (nest it more evenly)")
    return b.add(PTYPE, index, node, np.eye(4), pack(Par, start=start, length=len(b.prog) - start), top=True,
                 solid=SOLID)


def _program(b, node: m.CSG, index: int, W: np.ndarray):
    for child in (node.left, node.right):
        if isinstance(child, m.CSG):
            _program(b, child, index, W @ np.asarray(child.world_from_object))
        else:
            b.prog.append(b.leaf(child, index, W, top=False))
    b.prog.append(_CSG_OPS[node.op])


OPS = {
    "union": lambda a, b: a or b,
    "intersection": lambda a, b: a and b,
    "difference": lambda a, b: a and not b,
}


@dataclass(frozen=True)
class Crossing:
    """A boundary crossing at ``t`` of surface ``face`` of leaf ``leaf``; ``flip`` when the
    leaf's outward normal points into the composite solid (right side of a difference)."""

    t: float
    leaf: Any
    face: int = 0
    flip: bool = False


def combine(op: str, left: list[Crossing], right: list[Crossing], eps: float) -> list[Crossing]:
    """``composite_intersect``: the interval list of ``left op right``."""
    if op == "difference":
        right = [replace(c, flip=not c.flip) for c in right]
    inside = OPS[op]
    i = j = 0
    in_l = in_r = state = False
    out: list[Crossing] = []
    while i < len(left) or j < len(right):
        t = min(left[i].t if i < len(left) else float("inf"), right[j].t if j < len(right) else float("inf"))
        event = None
        while i < len(left) and left[i].t <= t + eps:  # every crossing of this instant
            in_l, event = not in_l, left[i]
            i += 1
        while j < len(right) and right[j].t <= t + eps:
            in_r = not in_r
            event = event or right[j]
            j += 1
        new = inside(in_l, in_r)
        if new != state:
            state = new
            if not new and out and event.t - out[-1].t <= eps:
                out.pop()  # an interval of zero length is no solid
            else:
                out.append(event)
    return out


def crossings(node: m.CSG, W: np.ndarray, O, D, eps: float, crossings_of) -> list[Crossing]:
    """Crossings of the world line ``O + t D`` with the node whose world_from_object is ``W``:
    the operands' interval lists (``crossings_of(child, W, O, D, eps, True)``) combined."""
    left = crossings_of(node.left, W, O, D, eps, True)
    if not left and node.op != "union":
        return []
    right = crossings_of(node.right, W, O, D, eps, True)
    return combine(node.op, left, right, eps)


def containing(node: m.CSG, W: np.ndarray, p, containing_of):
    """The material of the operand leaf whose inside holds world point ``p`` and is part of
    the solid (not subtracted), None if ``p`` is not inside (``containing_of(child, W, p)``)."""
    left, right = containing_of(node.left, W, p), containing_of(node.right, W, p)
    if node.op == "union":
        return left or right
    if node.op == "intersection":
        return left if left and right else None
    return left if left and not right else None


def world_bounds(node: m.CSG, W: np.ndarray, bounds_of) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned world box of the operands' boxes (``bounds_of(child, W)``)."""
    boxes = [bounds_of(c, W) for c in (node.left, node.right)]
    return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)


# --------------------------------------------------------------------------- exporters
_POVRAY_OPS = {"union": "merge", "intersection": "intersection", "difference": "difference"}


def povray(node: m.CSG, w, in_csg: bool) -> str:
    """POV-Ray's ``merge`` (the boundary of the union: no inner surfaces), ``intersection`` or
    ``difference`` of its operands, each written by the SDL writer's dispatch ``w.shape``."""
    return (f"{_POVRAY_OPS[node.op]} {{\n  {w.shape(node.left, True)}\n  {w.shape(node.right, True)}\n"
            f"  {w.matrix(node.world_from_object)} }}")


def mitsuba(node: m.CSG, x) -> list[dict]:
    """The raster's mesh booleans at the export's level, smooth normals."""
    return x.tessellated(node, x.level)
