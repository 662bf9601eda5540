"""Hemicube form factors on the GPU path (Cohen & Greenberg 1985), drawn with moderngl.

Around the centre of patch i, with z along its normal, a half-width-1 hemicube: the top face
z = 1 (res x res pixels) and four half side faces (res x res/2).  Every patch is drawn into an
item buffer (R32UI, patch number + 1, nearest surface kept by the depth test) and each pixel
adds its delta form factor to the patch it shows:

    top:   dF = dA / (pi (x^2 + y^2 + 1)^2)          (x, y in [-1, 1])
    sides: dF = z dA / (pi (y^2 + z^2 + 1)^2)        (y in [-1, 1], z in [0, 1])

with dA = (2/res)^2.  Their sum is 1 + O(1/res^2) (DESIGN errata 6: the midpoint rule on
the pixels), reported as ``weight_sum_raw``; by default they are scaled to sum to exactly 1
(``normalize``), so that a closed scene's rows sum to 1 and a furnace with rho near 1 is not
biased by 1 / (1 - rho (1 + O(1/res^2))).  Aliasing (small or distant patches falling between pixel centres) and
proximity (the hemicube sees from the centre only) are inherent errors.

Speed on llvmpipe (whose vertex/primitive front end is single-threaded, ~2.5 M triangles/s):
the scene's vertices are uploaded once per face slot; for ``batch`` patches at a time the
CPU keeps, for each face, only the triangles not wholly outside one of its frustum planes
(outcodes), and ONE draw call (llvmpipe pays ~0.5 ms per draw) renders the 5 x batch lists
into one framebuffer (each face mapped into its own rectangle, ``gl_ClipDistance`` clipping
it there), read back once, and summed into rows by a numba loop.

Triangles are what llvmpipe pays for, so a quadrilateral surface cut into a bilinear grid of
patches is not drawn patch by patch: it is drawn as one quad (or a few, if it is warped),
and the fragment shader finds the patch under each pixel by inverting the grid's bilinear
map (:func:`grid_regions`).  The Cornell box at 2,120 patches is then ~100 triangles
instead of 4,240; its item buffers agree with the per-patch triangles' (``regions=False``,
the readable reference) on >= 99.9 % of the pixels (the rest are ties on cell boundaries).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core import transform as tf
from ...core.errors import WorkbenchError
from ...core.resources import data_dir
from ...core.tol import tol
from .. import gl
from .geometry import Geometry

SHADERS = data_dir("shaders")
MAX_FACES = 80          # must match MAX_FACES in radiosity_item_vs.glsl
FACES = 5
TRI_ROW = 4096          # must match TRI_ROW in radiosity_item_vs.glsl and radiosity_item_fs.glsl
NO_BLOCK = 0xFFFFFFFF   # vertex tag of a patch's own triangle, as in radiosity_item_vs.glsl
GL_CLIP_DISTANCE0 = 0x3000


def delta_form_factors(res: int) -> np.ndarray:
    """Delta form factors (res, 3 res) laid out as the item buffer of one patch, rows bottom-up:
    the top face in columns [0, res), the sides in [res, 3 res) as four res x res/2 blocks."""
    d = 2.0 / res
    c = -1.0 + (np.arange(res) + 0.5) * d
    x, y = np.meshgrid(c, c, indexing="xy")
    top = d * d / (np.pi * (x * x + y * y + 1.0) ** 2)
    z = (np.arange(res // 2) + 0.5) * d
    yy, zz = np.meshgrid(c, z, indexing="xy")
    side = zz * d * d / (np.pi * (yy * yy + zz * zz + 1.0) ** 2)
    w = np.zeros((res, 3 * res))
    w[:, :res] = top
    h = res // 2
    for k, (x0, y0) in enumerate(_side_origins(res)):
        w[y0:y0 + h, x0:x0 + res] = side
    return w


def _side_origins(res: int) -> list[tuple[int, int]]:
    h = res // 2
    return [(res, 0), (res, h), (2 * res, 0), (2 * res, h)]


def _frustum(l, r, b, t, n, f) -> np.ndarray:
    """OpenGL glFrustum matrix (4, 4)."""
    return np.array([[2 * n / (r - l), 0, (r + l) / (r - l), 0],
                     [0, 2 * n / (t - b), (t + b) / (t - b), 0],
                     [0, 0, -(f + n) / (f - n), -2 * f * n / (f - n)],
                     [0, 0, -1, 0]])


class Hemicube:
    """Item-buffer hemicubes for the patches of ``geom`` (scene uploaded once).

    Parameters
    ----------
    geom : the patches.
    resolution : pixels across the top face (even, >= 2).
    rotate : turn each hemicube by a random angle about the normal (against aliasing).
    seed : seed of those angles.
    batch : patches per draw call and read-back (<= 16).
    normalize : scale the delta form factors to sum to exactly 1.
    regions : draw the bilinear grids of ``geom.grids`` as a few large quads, the patch found
        per pixel (:func:`grid_regions`); ``False`` draws two triangles per patch (the readable
        reference it is tested against).
    """

    def __init__(self, geom: Geometry, resolution: int = 128, *, rotate: bool = False,
                 seed: int = 0, batch: int = 16, normalize: bool = True, regions: bool = True):
        if resolution < 2 or resolution % 2:
            raise WorkbenchError(f"hemicube resolution must be an even number >= 2, got {resolution}")
        if resolution > 2048:
            raise WorkbenchError(f"hemicube resolution must be <= 2048, got {resolution}")
        self.geom, self.res = geom, int(resolution)
        self.ctx = ctx = gl.context()
        max_size = min(ctx.info["GL_MAX_TEXTURE_SIZE"], ctx.info["GL_MAX_RENDERBUFFER_SIZE"])
        if 3 * self.res > max_size:
            raise WorkbenchError(f"hemicube resolution {resolution} needs a {3 * self.res}-pixel item "
                                 f"buffer; this OpenGL allows {max_size} (use <= {max_size // 3})")
        # patches per read-back: their faces are stacked in one item buffer, within GL's limits
        self.batch = max(1, min(int(batch), MAX_FACES // FACES, max_size // self.res))
        self.rng = np.random.default_rng(seed)
        self.rotate = rotate
        self.weights = delta_form_factors(self.res)
        self.weight_sum_raw = float(self.weights.sum())
        if normalize:
            self.weights /= self.weight_sum_raw
        self.P = len(geom)
        self.extent = ext = geom.extent
        self.origin = geom.tris.reshape(-1, 3).mean(0) if len(geom.tris) else np.zeros(3)
        self.near = tol.hemicube_near * ext
        self.far = 2.0 * ext
        src = [(SHADERS / f"radiosity_item_{s}.glsl").read_text() for s in ("vs", "fs")]
        self.prog = ctx.program(vertex_shader=src[0], fragment_shader=src[1])
        # vertices: the patches' own triangles share theirs (each shaded once per face); the
        # bilinear blocks have four each, tagged block * 4 + corner (NO_BLOCK for the others)
        ptris, ptri_patch, blocks = grid_regions(geom) if regions else \
            (geom.tris, geom.tri_patch, GridBlocks.empty())
        self.blocks = len(blocks.cells)
        pos, index = np.unique(ptris.reshape(-1, 3), axis=0, return_inverse=True)
        Up = len(pos)
        pos = np.concatenate([pos, blocks.corners.reshape(-1, 3)])
        tag = np.concatenate([np.full(Up, NO_BLOCK, dtype="u4"),
                              np.arange(4 * self.blocks, dtype="u4")])
        quads = Up + 4 * np.arange(self.blocks)[:, None, None] + np.array([[0, 1, 2], [0, 2, 3]])
        self.index = np.concatenate([index.reshape(-1, 3), quads.reshape(-1, 3)]).astype("u4")
        # the patch of each triangle (unused for a block's, whose fragments find theirs), the
        # block of each triangle and of each patch (-1: none)
        self.tri_patch = np.concatenate([ptri_patch, np.zeros(2 * self.blocks)]).astype("u4")
        self.tri_block = np.concatenate([np.full(len(ptri_patch), -1),
                                         np.repeat(np.arange(self.blocks), 2)])
        self.patch_block = blocks.patch_block(self.P)
        self.pos_h = np.concatenate([pos - self.origin, np.ones((len(pos), 1))], 1)
        self.U = U = len(pos)
        slots = FACES * self.batch
        verts = np.empty((slots, U), dtype=[("p", "f4", 3), ("f", "u4"), ("t", "u4")])
        verts["p"] = (pos - self.origin).astype("f4")[None]
        verts["f"] = np.arange(slots, dtype="u4")[:, None]
        verts["t"] = tag[None]
        self.vbo = ctx.buffer(verts.tobytes())
        max_tris = slots * len(self.index)
        self.ibo = ctx.buffer(reserve=max(12, 12 * max_tris))
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, "3f 1u 1u", "in_pos", "in_face", "in_tag")],
                                    self.ibo, index_element_size=4)
        self.lut_rows = max(1, -(-max_tris // TRI_ROW))
        self.lut = ctx.texture((TRI_ROW, self.lut_rows), 1, dtype="u4")
        self.block_cells = _table(ctx, blocks.cells.astype("u4"), "u4")
        self.block_map = _table(ctx, blocks.maps.reshape(-1, 4).astype("f4"), "f4")
        self.textures = (self.lut, self.block_cells, self.block_map)
        for k, (tex, name) in enumerate(zip(self.textures, ("tri_patch", "block_cells", "block_map"))):
            tex.filter = (ctx.NEAREST, ctx.NEAREST)
            self.prog[name].value = k
        W, H = 3 * self.res, self.batch * self.res
        self.item = ctx.texture((W, H), 1, dtype="u4")
        self.depth = ctx.depth_renderbuffer((W, H))
        self.fbo = ctx.framebuffer(color_attachments=[self.item], depth_attachment=self.depth)
        self.prog["far_plane"].value = float(self.far)
        self.rects = self._rects()
        self._proj_top = _frustum(-self.near, self.near, -self.near, self.near, self.near, self.far)
        self._proj_side = _frustum(-self.near, self.near, 0.0, self.near, self.near, self.far)
        self.u, self.v, self.n = self._frames()
        self.drawn = 0

    def _rects(self) -> np.ndarray:
        """(batch * 5, 4) NDC (scale x, offset x, scale y, offset y) of every face's rectangle."""
        W, H, res = 3 * self.res, self.batch * self.res, self.res
        out = []
        for b in range(self.batch):
            for k, (x0, y0, w, h) in enumerate([(0, 0, res, res)] + [
                    (x, y, res, res // 2) for x, y in _side_origins(res)]):
                y0 += b * res
                out.append((w / W, w / W + 2 * x0 / W - 1, h / H, h / H + 2 * y0 / H - 1))
        return np.array(out, dtype="f4")

    def _frames(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Hemicube axes (P, 3) each: u along each patch's first edge (turned by a random
        angle if ``rotate``), v = n x u, n the normal."""
        g = self.geom
        n = g.normals
        first = np.array([p[1] - p[0] for p in g.polygons]) if len(g) else np.zeros((0, 3))
        u = first - (first * n).sum(1, keepdims=True) * n
        bad = np.linalg.norm(u, axis=1) <= tol.zero * self.extent
        alt = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        u = tf.normalize(np.where(bad[:, None], np.cross(n, alt), u))
        v = np.cross(n, u)
        if self.rotate:
            a = self.rng.uniform(0.0, 2.0 * np.pi, len(g))[:, None]
            u, v = np.cos(a) * u + np.sin(a) * v, -np.sin(a) * u + np.cos(a) * v
        return u, v, n

    def _face_matrices(self, patches: np.ndarray) -> np.ndarray:
        """clip_from_world (len(patches) * 5, 4, 4) of the hemicube faces (world relative to
        ``origin``): the top looks along n (up v), the sides along +-u, +-v (up n)."""
        u, v, n = self.u[patches], self.v[patches], self.n[patches]
        # eye lifted by the near distance: coplanar neighbours fall below the side faces
        eye = self.geom.centres[patches] - self.origin + self.near * n
        looks = np.stack([n, u, -u, v, -v], 1)               # (B, 5, 3) view directions
        ups = np.stack([v, n, n, n, n], 1)
        f = looks
        r = np.cross(f, ups)
        up = np.cross(r, f)
        view = np.zeros(looks.shape[:2] + (4, 4))
        view[..., 0, :3], view[..., 1, :3], view[..., 2, :3] = r, up, -f
        view[..., :3, 3] = -np.einsum("bfij,bj->bfi", view[..., :3, :3], eye)
        view[..., 3, 3] = 1.0
        proj = np.stack([self._proj_top] + [self._proj_side] * 4)   # (5, 4, 4)
        return (proj[None] @ view).reshape(-1, 4, 4)

    def _cull(self, mats: np.ndarray, own: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Triangles each face keeps: those not wholly outside one plane of its clip volume,
        and not of the block holding the face's own patch (that block is (nearly) the
        patch's plane, which it cannot see; drawn, its deviation from the patches'
        own triangles could pass above the eye and hide everything).

        mats : (S, 4, 4) clip_from_world of face slots 0..S-1; own : (S,) their block, -1.
        Returns the vertex indices (K, 3) into the per-slot vertex buffer, and the patch of
        each kept triangle (K,) (0 for a block's)."""
        c = self.pos_h @ mats.transpose(0, 2, 1)            # (S, U, 4)
        x, y, z, w = c[..., 0], c[..., 1], c[..., 2], c[..., 3]
        code = ((x < -w).astype(np.uint8) | ((x > w) << 1) | ((y < -w) << 2) | ((y > w) << 3)
                | ((z < -w) << 4) | ((z > w) << 5)).astype(np.uint8)
        t = code[:, self.index]                              # (S, T, 3)
        mine = (self.tri_block[None] == own[:, None]) & (own[:, None] >= 0)
        keep = ((t[..., 0] & t[..., 1] & t[..., 2]) == 0) & ~mine
        slot, tri = np.nonzero(keep)
        return self.index[tri] + (slot * self.U).astype("u4")[:, None], self.tri_patch[tri]

    def _draw(self, chunk: np.ndarray) -> np.ndarray:
        """Item buffers (len(chunk), res, 3 res) of up to ``batch`` patches, one draw call and
        one read-back; a zero-area patch's is left empty (all 0)."""
        live = np.nonzero(self.geom.areas[chunk] > 0)[0]
        if len(live):
            mats = self._face_matrices(chunk[live])
            rects = self.rects.reshape(self.batch, FACES, 4)[live].reshape(-1, 4)
            nf = FACES * len(live)
            tri_idx, tri_patch = self._cull(mats, np.repeat(self.patch_block[chunk[live]], FACES))
            # GLSL matrices are column-major
            pad_m = np.zeros((MAX_FACES, 4, 4), dtype="f4")
            pad_m[:nf] = mats.transpose(0, 2, 1)
            pad_r = np.zeros((MAX_FACES, 4), dtype="f4")
            pad_r[:nf] = rects
            self.prog["clip_from_world"].write(pad_m.tobytes())
            self.prog["rect"].write(pad_r.tobytes())
        used = (0, 0, 3 * self.res, len(chunk) * self.res)    # the chunk's rows only
        self.fbo.clear(depth=1.0, viewport=used)              # the item buffer (integer) to 0 too
        if len(live) and len(tri_idx):
            self.ibo.write(tri_idx.tobytes())
            lut = np.zeros(-(-len(tri_patch) // TRI_ROW) * TRI_ROW, dtype="u4")
            lut[:len(tri_patch)] = tri_patch
            self.lut.write(lut.tobytes(), viewport=(0, 0, TRI_ROW, len(lut) // TRI_ROW))
            self.vao.render(vertices=3 * len(tri_idx))
        self.drawn += len(live)
        ids = np.frombuffer(self.fbo.read(viewport=used, components=1, dtype="u4"), dtype="u4")
        return ids.reshape(len(chunk), self.res, 3 * self.res)

    def _each_batch(self, patches):
        """Draw the item buffers of ``patches`` batch by batch: yields (start, ids)."""
        patches = np.asarray(patches, dtype=np.int64).ravel()
        ctx = self.ctx
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        for k in range(4):
            ctx.enable_direct(GL_CLIP_DISTANCE0 + k)
        previous = ctx.fbo     # rebound afterwards: releasing a bound FBO breaks the next one
        try:
            self.fbo.use()
            for k, tex in enumerate(self.textures):
                tex.use(k)
            for s in range(0, len(patches), self.batch):
                yield s, self._draw(patches[s:s + self.batch])
        finally:
            for k in range(4):
                ctx.disable_direct(GL_CLIP_DISTANCE0 + k)
            if previous is not None:
                previous.use()
            gl.check_errors(ctx)

    def item_buffers(self, patches) -> np.ndarray:
        """Item buffers (len(patches), res, 3 res) uint32, laid out as
        :func:`delta_form_factors` (top face, then the four half sides; rows bottom-up):
        patch number + 1 of the nearest front face seen by each pixel, 0 for nothing (or a
        back face)."""
        patches = np.asarray(patches, dtype=np.int64).ravel()
        out = np.zeros((len(patches), self.res, 3 * self.res), dtype=np.uint32)
        for s, ids in self._each_batch(patches):
            out[s:s + len(ids)] = ids
        return out

    def rows(self, patches, on_rows=None) -> np.ndarray:
        """Rows F[i, :] (len(patches), P) of the patches listed: each item buffer's delta
        form factors summed per patch (numba, :func:`.kernels.accumulate_items`);
        ``on_rows(done, total)`` after each batch, if given."""
        from .kernels import accumulate_items
        patches = np.asarray(patches, dtype=np.int64).ravel()
        out = np.zeros((len(patches), self.P))
        for s, ids in self._each_batch(patches):
            accumulate_items(ids, self.weights, out[s:s + len(ids)])
            if on_rows is not None:
                on_rows(s + len(ids), len(patches))
        return out

    def matrix(self, on_rows=None) -> np.ndarray:
        """The full matrix F (P, P) (``on_rows`` as :meth:`rows`)."""
        return self.rows(np.arange(self.P), on_rows)

    def info(self) -> dict:
        return {"hemicube_resolution": self.res, "weight_sum": float(self.weights.sum()),
                "weight_sum_raw": self.weight_sum_raw,
                "rotate": self.rotate, "gl_renderer": gl.renderer_name(self.ctx),
                "grid_blocks_drawn": self.blocks,
                "hemicubes_drawn": self.drawn}

    def release(self) -> None:
        gl.release_framebuffer(self.fbo)
        for o in (self.vao, self.vbo, self.ibo, *self.textures, self.item, self.depth, self.prog):
            o.release()


def _table(ctx, rows: np.ndarray, dtype: str):
    """A (TRI_ROW, n) four-component texture holding ``rows`` (K, 4), row-major."""
    n = max(1, -(-len(rows) // TRI_ROW))
    flat = np.zeros((n * TRI_ROW, 4), dtype=dtype)
    flat[:len(rows)] = rows
    return ctx.texture((TRI_ROW, n), 4, flat.tobytes(), dtype=dtype)


@dataclass(frozen=True)
class GridBlocks:
    """Blocks of bilinear-grid cells the hemicube draws as one quad each (K blocks).

    corners : (K, 4, 3) counter-clockwise from the front.
    cells : (K, 4) (first patch, cells along a, cells along b, patch stride along a): cell
        (i, j) of the block is patch ``first + i * stride + j``.
    maps : (K, 8) the block's bilinear map in its plane, h = a e + b f + a b g:
        (e.x, e.y, f.x, f.y, g.x, g.y, 0, 0), in units of the block's size.
    """

    corners: np.ndarray
    cells: np.ndarray
    maps: np.ndarray

    def patch_block(self, P: int) -> np.ndarray:
        """(P,) the block holding each patch, -1 for none."""
        out = np.full(P, -1, dtype=np.int64)
        for k, (first, nu, nv, stride) in enumerate(self.cells):
            out[first + np.arange(nu)[:, None] * stride + np.arange(nv)[None, :]] = k
        return out

    @staticmethod
    def empty() -> "GridBlocks":
        return GridBlocks(np.zeros((0, 4, 3)), np.zeros((0, 4), np.int64), np.zeros((0, 8)))


def _newell(c: np.ndarray) -> np.ndarray:
    """Newell's (area-weighted) normal of the polygon ``c`` (k, 3), not normalised."""
    d = np.roll(c, -1, axis=0)
    return np.array([((c[:, 1] - d[:, 1]) * (c[:, 2] + d[:, 2])).sum(),
                     ((c[:, 2] - d[:, 2]) * (c[:, 0] + d[:, 0])).sum(),
                     ((c[:, 0] - d[:, 0]) * (c[:, 1] + d[:, 1])).sum()])


def _block_map(c: np.ndarray) -> np.ndarray | None:
    """The bilinear map (8,) of the quad ``c`` (4, 3) in its plane (see :class:`GridBlocks`),
    or None if ``c`` is degenerate or not strictly convex."""
    n = _newell(c)
    L = float(np.linalg.norm(c - c[0], axis=1).max())
    if L <= 0 or np.linalg.norm(n) <= tol.zero * L * L:
        return None
    n = n / np.linalg.norm(n)
    edges = np.roll(c, -1, axis=0) - c
    if (np.cross(edges, np.roll(edges, -1, axis=0)) @ n <= tol.zero * L * L).any():
        return None
    X = edges[0] - (edges[0] @ n) * n
    X /= np.linalg.norm(X)
    Y = np.cross(n, X)
    to2 = np.stack([X, Y], 1) / L                            # (3, 2)
    e, f, g = (c[1] - c[0]) @ to2, (c[3] - c[0]) @ to2, (c[0] - c[1] + c[2] - c[3]) @ to2
    return np.concatenate([e, f, g, [0.0, 0.0]])


def _split(n: int, k: int) -> np.ndarray:
    """Cut points of [0, n] into min(n, k) nearly equal integer ranges."""
    return np.unique(np.linspace(0, n, min(n, k) + 1).round().astype(int))


def grid_regions(geom: Geometry, flat: float = tol.hemicube_flat) -> tuple[np.ndarray, np.ndarray, GridBlocks]:
    """What the hemicube draws: each bilinear grid of ``geom.grids`` as a few quads (blocks)
    in which the fragment shader finds the patch by inverting the bilinear map; every other
    patch as its own triangles.

    A grid is cut into blocks whose corners lie within ``flat`` times a patch edge of their
    plane (the published Cornell box's red wall is 0.2 % off plane: it is drawn in 6 x 6
    blocks); a block that is not convex is drawn as its patches' own triangles.  Drawing 32 triangles for the Cornell box's 16 quads
    instead of 4,240 is what makes a hemicube cheap on llvmpipe.

    Returns the patches' own triangles (T, 3, 3), the patch of each (T,), and the blocks.
    """
    by_block = np.zeros(len(geom), bool)
    corners, cells, maps = [], [], []
    for g in geom.grids:
        q = g.quad
        n = _newell(q)
        nn = np.linalg.norm(n)
        if g.nu * g.nv == 1 or nn == 0:
            continue
        twist = abs((q[0] - q[1] + q[2] - q[3]) @ n) / (4 * nn)   # corners off the plane
        edge = min(np.linalg.norm(q[1] - q[0]) / g.nu, np.linalg.norm(q[3] - q[0]) / g.nv)
        k = 1 if twist <= flat * edge else int(np.ceil(np.sqrt(twist / (flat * edge))))
        cuts_u, cuts_v = _split(g.nu, k), _split(g.nv, k)
        for i0, i1 in zip(cuts_u[:-1], cuts_u[1:]):
            for j0, j1 in zip(cuts_v[:-1], cuts_v[1:]):
                c = g.corners(i0 / g.nu, i1 / g.nu, j0 / g.nv, j1 / g.nv)
                m = _block_map(c)
                if m is None:
                    continue
                corners.append(c)
                cells.append((g.first + i0 * g.nv + j0, i1 - i0, j1 - j0, g.nv))
                maps.append(m)
                ids = g.first + np.arange(i0, i1)[:, None] * g.nv + np.arange(j0, j1)[None, :]
                by_block[ids.ravel()] = True
    own = ~by_block[geom.tri_patch]
    blocks = GridBlocks(np.reshape(corners, (-1, 4, 3)), np.reshape(cells, (-1, 4)).astype(np.int64),
                        np.reshape(maps, (-1, 8))) if corners else GridBlocks.empty()
    return geom.tris[own], geom.tri_patch[own], blocks
