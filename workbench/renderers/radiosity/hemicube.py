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
it there), read back once.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...core import transform as tf
from ...core.errors import WorkbenchError
from ...core.tol import tol
from .. import gl
from .formfactors import Geometry

SHADERS = Path(__file__).resolve().parents[3] / "shaders"
MAX_FACES = 80          # must match MAX_FACES in radiosity_item_vs.glsl
FACES = 5
TRI_ROW = 4096          # must match TRI_ROW in radiosity_item_fs.glsl
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
    """

    def __init__(self, geom: Geometry, resolution: int = 128, *, rotate: bool = False,
                 seed: int = 0, batch: int = 16, normalize: bool = True):
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
        # shared vertices + index buffer (each vertex shaded once per face, not per triangle);
        # the patch comes from gl_PrimitiveID through a texture
        pos, index = np.unique(geom.tris.reshape(-1, 3), axis=0, return_inverse=True)
        self.pos_h = np.concatenate([pos - self.origin, np.ones((len(pos), 1))], 1)
        self.index = index.reshape(-1, 3).astype("u4")
        self.U = U = len(pos)
        slots = FACES * self.batch
        verts = np.empty((slots, U), dtype=[("p", "f4", 3), ("f", "u4")])
        verts["p"] = (pos - self.origin).astype("f4")[None]
        verts["f"] = np.arange(slots, dtype="u4")[:, None]
        self.vbo = ctx.buffer(verts.tobytes())
        max_tris = slots * len(self.index)
        self.ibo = ctx.buffer(reserve=max(12, 12 * max_tris))
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, "3f 1u", "in_pos", "in_face")],
                                    self.ibo, index_element_size=4)
        self.lut_rows = max(1, -(-max_tris // TRI_ROW))
        self.lut = ctx.texture((TRI_ROW, self.lut_rows), 1, dtype="u4")
        self.lut.filter = (ctx.NEAREST, ctx.NEAREST)
        self.prog["tri_patch"].value = 0
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

    def _cull(self, mats: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Triangles each face keeps: those not wholly outside one plane of its clip volume.

        mats : (S, 4, 4) clip_from_world of face slots 0..S-1.
        Returns the vertex indices (K, 3) into the per-slot vertex buffer, and the patch of
        each kept triangle (K,)."""
        c = self.pos_h @ mats.transpose(0, 2, 1)            # (S, U, 4)
        x, y, z, w = c[..., 0], c[..., 1], c[..., 2], c[..., 3]
        code = ((x < -w).astype(np.uint8) | ((x > w) << 1) | ((y < -w) << 2) | ((y > w) << 3)
                | ((z < -w) << 4) | ((z > w) << 5)).astype(np.uint8)
        t = code[:, self.index]                              # (S, T, 3)
        slot, tri = np.nonzero((t[..., 0] & t[..., 1] & t[..., 2]) == 0)
        return (self.index[tri] + (slot * self.U).astype("u4")[:, None],
                self.geom.tri_patch[tri].astype("u4"))

    def rows(self, patches) -> np.ndarray:
        """Rows F[i, :] (len(patches), P) of the patches listed."""
        patches = np.asarray(patches, dtype=np.int64).ravel()
        out = np.zeros((len(patches), self.P))
        ctx = self.ctx
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        for k in range(4):
            ctx.enable_direct(GL_CLIP_DISTANCE0 + k)
        previous = ctx.fbo     # rebound afterwards: releasing a bound FBO breaks the next one
        try:
            self.fbo.use()
            self.lut.use(0)
            for s in range(0, len(patches), self.batch):
                chunk = patches[s:s + self.batch]
                live = np.nonzero(self.geom.areas[chunk] > 0)[0]
                if len(live) == 0:
                    continue
                live_p = chunk[live]
                mats = self._face_matrices(live_p)
                rects = self.rects.reshape(self.batch, FACES, 4)[live].reshape(-1, 4)
                nf = FACES * len(live)
                tri_idx, tri_patch = self._cull(mats[:nf])
                if len(tri_idx):
                    self.ibo.write(tri_idx.astype("u4").tobytes())
                    lut = np.zeros(-(-len(tri_patch) // TRI_ROW) * TRI_ROW, dtype="u4")
                    lut[:len(tri_patch)] = tri_patch
                    self.lut.write(lut.tobytes(), viewport=(0, 0, TRI_ROW, len(lut) // TRI_ROW))
                # GLSL matrices are column-major
                pad_m = np.zeros((MAX_FACES, 4, 4), dtype="f4")
                pad_m[:nf] = mats.transpose(0, 2, 1)
                pad_r = np.zeros((MAX_FACES, 4), dtype="f4")
                pad_r[:nf] = rects
                self.prog["clip_from_world"].write(pad_m.tobytes())
                self.prog["rect"].write(pad_r.tobytes())
                self.fbo.clear(depth=1.0)
                self.item.write(np.zeros(self.item.size[::-1], dtype="u4").tobytes())
                if len(tri_idx):
                    self.vao.render(vertices=3 * len(tri_idx))
                ids = np.frombuffer(self.fbo.read(components=1, dtype="u4"), dtype="u4")
                ids = ids.reshape(self.batch, self.res, 3 * self.res)[:len(chunk)]
                shift = (np.arange(len(chunk)) * (self.P + 1))[:, None, None]
                acc = np.bincount((ids.astype(np.int64) + shift).ravel(),
                                  weights=np.broadcast_to(self.weights, ids.shape).ravel(),
                                  minlength=len(chunk) * (self.P + 1))
                acc = acc.reshape(len(chunk), self.P + 1)[:, 1:]
                for b in live:
                    out[s + b] = acc[b]
                self.drawn += len(live)
        finally:
            for k in range(4):
                ctx.disable_direct(GL_CLIP_DISTANCE0 + k)
            if previous is not None:
                previous.use()
        gl.check_errors(ctx)
        return out

    def matrix(self) -> np.ndarray:
        """The full matrix F (P, P)."""
        return self.rows(np.arange(self.P))

    def info(self) -> dict:
        return {"hemicube_resolution": self.res, "weight_sum": float(self.weights.sum()),
                "weight_sum_raw": self.weight_sum_raw,
                "rotate": self.rotate, "gl_renderer": gl.renderer_name(self.ctx),
                "hemicubes_drawn": self.drawn}

    def release(self) -> None:
        gl.release_framebuffer(self.fbo)
        for o in (self.vao, self.vbo, self.ibo, self.lut, self.item, self.depth, self.prog):
            o.release()
