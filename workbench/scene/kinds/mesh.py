"""Object kind ``mesh``: a triangle mesh read by trimesh (``path``), generated (``generate``) or
inline (``vertices`` + ``faces``), with crease-angle normals.  Ray traced in world space
through one BVH over every mesh's triangles (not a CSG leaf there); a CSG leaf by mesh
booleans in the raster when it is watertight."""
from __future__ import annotations

import numpy as np

from ...core import transform as tf
from ...core.errors import NotApplicable, WorkbenchError
from .. import model as m, readers as rd
from ..parts import make_part

TYPE = "mesh"
MODEL = m.Mesh
FEATURE = "meshes"
PTYPE = MESH = 6
SOLID = True
COMPOSITE = False
CONVEX = False
CLOSED_TESSELLATION = False
KERNELS = None
KEYS = frozenset({"path", "generate", "vertices", "faces", "crease_angle"})
REQUIRED = frozenset()


def parse(ctx: rd.Ctx, t: dict, w: str, common: dict) -> m.Mesh:
    import trimesh  # heavy: only when a scene has meshes
    sources = [k for k in ("path", "generate", "vertices") if k in t]
    if len(sources) != 1:
        ctx.fail(w, "a mesh needs exactly one of path, generate or vertices (+ faces)")
    if "path" in t:
        p = rd.file_path(ctx, t, w, "path")
        try:
            tm = trimesh.load(p, force="mesh", process=False)
        except Exception as e:  # trimesh raises many kinds
            ctx.fail(f"{w}.path", f"cannot read mesh {p}: {e}")
        source = p
    elif "generate" in t:
        g = t["generate"]
        rd.check_keys(ctx, g, f"{w}.generate", {"kind", "subdivisions", "seed", "amplitude", "radius"}, {"kind"})
        kind = rd.string(ctx, g, f"{w}.generate", "kind", choices=("icosphere", "blob", "torus"))
        from ..generate import generate_mesh
        tm = generate_mesh(kind, subdivisions=rd.num(ctx, g, f"{w}.generate", "subdivisions", 4, lo=0, hi=8, integer=True),
                           seed=rd.num(ctx, g, f"{w}.generate", "seed", 0, lo=0, hi=2 ** 32 - 1, integer=True),
                           amplitude=rd.num(ctx, g, f"{w}.generate", "amplitude", 0.15, lo=0.0),
                           radius=rd.num(ctx, g, f"{w}.generate", "radius", 1.0, lo=0.0, lo_open=True))
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
    if np.abs(tm.vertices).max() > rd.FLOAT32_MAX:
        ctx.fail(f"{w}", f"mesh from {source} has vertices outside the float32 range "
                         f"|x| <= {rd.FLOAT32_MAX:.8g} (the GPU is float32)")
    uvs = None
    vis = getattr(tm, "visual", None)
    if vis is not None and getattr(vis, "uv", None) is not None and len(vis.uv) == len(tm.vertices):
        uvs = m._ro(vis.uv)
    from ..mesh_normals import DEFAULT_CREASE_ANGLE, crease_normals
    crease = rd.num(ctx, t, w, "crease_angle", DEFAULT_CREASE_ANGLE, lo=0.0, hi=180.0)
    V, F, N, uvs = crease_normals(tm.vertices, tm.faces, crease, uvs)
    return m.Mesh(**common, vertices=m._ro(V), faces=np.asarray(F, dtype=np.int64),
                  normals=m._ro(N), uvs=None if uvs is None else m._ro(uvs), source=source)


def bound_points(mesh: m.Mesh) -> np.ndarray:
    return np.asarray(mesh.vertices)


def tessellate(mesh: m.Mesh, level: int, M: np.ndarray) -> list:
    """As given (the level does not apply); its normals, or the face normal."""
    P, F = np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64)
    N = np.asarray(mesh.normals) if mesh.normals is not None else np.zeros_like(P)
    return [make_part(mesh, M, P, N, F, None, None,
                      None if mesh.uvs is None else np.asarray(mesh.uvs, dtype=np.float64))]


def solid_mesh(mesh: m.Mesh, level: int) -> tuple[np.ndarray, np.ndarray]:
    """The mesh welded (trimesh ``process``); it must be watertight."""
    import trimesh
    tm = trimesh.Trimesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), process=True)
    if not tm.is_watertight:
        raise WorkbenchError(f"CSG leaf mesh {mesh.name or mesh.source!r} is not watertight: "
                             "mesh booleans need closed solids")
    return np.asarray(tm.vertices), np.asarray(tm.faces, dtype=np.int64)


def analytic_normals(mesh: m.Mesh, P: np.ndarray):
    """The triangles' own normals (None)."""
    return None


def edge_max(P: np.ndarray, F: np.ndarray) -> float:
    """Longest edge of the triangles ``F`` (F, 3) of points ``P`` (V, 3), 0 for none."""
    t = P[F]
    return float(np.linalg.norm(t - np.roll(t, 1, axis=1), axis=-1).max()) if len(F) else 0.0


def patch_surfaces(mesh: m.Mesh, W: np.ndarray, h: float):
    """One patch per triangle (shared vertices) when no edge is longer than ``h``, else every
    triangle as a polygon (cut further)."""
    Pw = tf.transform_points(W, np.asarray(mesh.vertices))
    F = np.asarray(mesh.faces, dtype=np.int64)
    if edge_max(Pw, F) <= h:
        return [("mesh", (Pw, F))]
    return [("polygon", tf.transform_points(W, np.asarray(p))) for p in np.asarray(mesh.vertices)[F]]


def flatten(b, mesh: m.Mesh, index: int, W: np.ndarray, top: bool) -> int:
    """A row that owns the mesh's triangles (moved to world space into the BVH by the builder);
    never intersected as a row itself."""
    if not top:
        raise NotApplicable(f"object {mesh.name or index}: a mesh inside a CSG tree is not "
                            "supported by the ray tracer (use spheres, boxes or quadrics)")
    k = b.add(PTYPE, index, mesh, W, (), top=False, solid=SOLID)
    b.rows[k]["has_uv"] = mesh.uvs is not None
    b.meshes.append((k, mesh, W))
    return k


def inside(mesh: m.Mesh, q) -> bool:
    """Generalised winding number above 1/2 (Jacobson et al. 2013: open patches and stray
    triangles count for about 0), from the solid angle of each triangle seen from ``q`` (Van
    Oosterom & Strackee 1983)."""
    a, b, c = (np.asarray(mesh.vertices)[np.asarray(mesh.faces)[:, k]] - q for k in range(3))
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la \
        + np.einsum("ij,ij->i", c, a) * lb
    return bool(abs(np.sum(2.0 * np.arctan2(num, den))) / (4.0 * np.pi) > 0.5)


# --------------------------------------------------------------------------- exporters
def povray(o: m.Mesh, w, in_csg: bool) -> str:
    """POV-Ray's ``mesh2`` in world space: vertices ``W v``, unit normals ``n W^-1`` (row
    vectors), as the ray tracer interpolates them (POV-Ray would interpolate object-space
    normals before its transform: not the same under a non-uniform scale); the texture
    carries ``W``.  Per-vertex emission is left out (noted)."""
    if o.vertex_emission is not None:
        w.leave("emitters", f"per-vertex emission of mesh {o.name or o.source!r} not exported")
    W = np.asarray(o.world_from_object, dtype=np.float64)
    V = np.asarray(o.vertices, dtype=np.float64) @ W[:3, :3].T + W[:3, 3]
    F = np.asarray(o.faces)
    out = [f"mesh2 {{\n vertex_vectors {{ {len(V)},\n" + ",\n".join(w.vec(p) for p in V) + " }"]
    if o.normals is not None:
        N = np.asarray(o.normals, dtype=np.float64) @ np.linalg.inv(W[:3, :3])
        N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)
        out.append(f" normal_vectors {{ {len(N)},\n" + ",\n".join(w.vec(n) for n in N) + " }")
    if o.uvs is not None:
        out.append(f" uv_vectors {{ {len(V)},\n" + ",\n".join(w.vec(t) for t in np.asarray(o.uvs)) + " }")
    out.append(f" face_indices {{ {len(F)},\n" + ",\n".join(f"<{a}, {b}, {c}>" for a, b, c in F) + " }")
    out.append(f" {w.texture(o.material, w.matrix(W) + ' ')} }}")
    return "\n".join(out)


def mitsuba(o: m.Mesh, x) -> list[dict]:
    """Its triangles with its own vertex normals (flat without them); per-vertex emission
    (hybrid's radiosity hand-over) is left out (noted)."""
    if o.vertex_emission is not None:
        x.leave("emitters", "mesh vertex emission (hybrid's radiosity hand-over) not exported")
    return x.tessellated(o, x.level, flat=o.normals is None)
