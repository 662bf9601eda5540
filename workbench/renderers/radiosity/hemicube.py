"""Hemicube form factors on the GPU path (Cohen & Greenberg 1985), drawn with moderngl.

Around the centre of patch i, with z along its normal, a half-width-1 hemicube: the top face
z = 1 (res x res pixels) and four half side faces (res x res/2).  Every patch is drawn into an
item buffer (R32UI, patch number + 1, nearest surface kept by the depth test) and each pixel
adds its delta form factor to the patch it shows:

    top:   dF = dA / (pi (x^2 + y^2 + 1)^2)          (x, y in [-1, 1])
    sides: dF = z dA / (pi (y^2 + z^2 + 1)^2)        (y in [-1, 1], z in [0, 1])

with dA = (2/res)^2.  Their sum is 1 + O(1/res^2) (DESIGN errata 6), reported as
``weight_sum``.  Aliasing (small or distant patches falling between pixel centres) and
proximity (the hemicube sees from the centre only) are inherent errors.

Speed on llvmpipe: the scene is uploaded once; the five faces of ``batch`` patches are drawn
by ONE instanced draw call into one framebuffer (each instance maps its face into its own
rectangle, ``gl_ClipDistance`` clipping it there) and read back once.
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
    """

    def __init__(self, geom: Geometry, resolution: int = 128, *, rotate: bool = False,
                 seed: int = 0, batch: int = 16):
        if resolution < 2 or resolution % 2:
            raise WorkbenchError(f"hemicube resolution must be an even number >= 2, got {resolution}")
        if resolution > 2048:
            raise WorkbenchError(f"hemicube resolution must be <= 2048, got {resolution}")
        self.geom, self.res = geom, int(resolution)
        self.batch = max(1, min(int(batch), MAX_FACES // FACES))
        self.rng = np.random.default_rng(seed)
        self.rotate = rotate
        self.weights = delta_form_factors(self.res)
        self.P = len(geom)
        ext = geom.extent
        self.origin = geom.tris.reshape(-1, 3).mean(0) if len(geom.tris) else np.zeros(3)
        self.near = tol.hemicube_near * ext
        self.far = 2.0 * ext
        self.ctx = ctx = gl.context()
        src = [(SHADERS / f"radiosity_item_{s}.glsl").read_text() for s in ("vs", "fs")]
        self.prog = ctx.program(vertex_shader=src[0], fragment_shader=src[1])
        pos = (geom.tris.reshape(-1, 3) - self.origin).astype("f4")
        ids = np.repeat(geom.tri_patch.astype("u4"), 3)
        data = np.empty(len(pos), dtype=[("p", "f4", 3), ("i", "u4")])
        data["p"], data["i"] = pos, ids
        self.vbo = ctx.buffer(data.tobytes())
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, "3f 1u", "in_pos", "in_id")])
        W, H = 3 * self.res, self.batch * self.res
        self.item = ctx.texture((W, H), 1, dtype="u4")
        self.depth = ctx.depth_renderbuffer((W, H))
        self.fbo = ctx.framebuffer(color_attachments=[self.item], depth_attachment=self.depth)
        self.prog["far_plane"].value = float(self.far)
        self.rects = self._rects()
        self._proj_top = _frustum(-self.near, self.near, -self.near, self.near, self.near, self.far)
        self._proj_side = _frustum(-self.near, self.near, 0.0, self.near, self.near, self.far)
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

    def _frame(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = self.geom.normals[i]
        poly = self.geom.polygons[i]
        u = poly[1] - poly[0]
        u = u - (u @ n) * n
        if np.linalg.norm(u) <= tol.zero * self.geom.extent:
            u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
        u = tf.normalize(u)
        v = np.cross(n, u)
        if self.rotate:
            a = self.rng.uniform(0.0, 2.0 * np.pi)
            u, v = np.cos(a) * u + np.sin(a) * v, -np.sin(a) * u + np.cos(a) * v
        return u, v, n

    def _face_matrices(self, i: int) -> list[np.ndarray]:
        """clip_from_world (4, 4) of the five faces of patch i's hemicube (world relative to
        ``origin``)."""
        u, v, n = self._frame(i)
        # eye lifted by the near distance: coplanar neighbours fall below the side faces
        c = self.geom.centres[i] - self.origin + self.near * n
        mats = [self._proj_top @ tf.look_at(c, c + n, v)]
        for axis in (u, -u, v, -v):
            mats.append(self._proj_side @ tf.look_at(c, c + axis, n))
        return mats

    def rows(self, patches) -> np.ndarray:
        """Rows F[i, :] (len(patches), P) of the patches listed."""
        patches = np.asarray(patches, dtype=np.int64).ravel()
        out = np.zeros((len(patches), self.P))
        ctx = self.ctx
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        for k in range(4):
            ctx.enable_direct(GL_CLIP_DISTANCE0 + k)
        try:
            self.fbo.use()
            for s in range(0, len(patches), self.batch):
                chunk = patches[s:s + self.batch]
                live = [b for b, i in enumerate(chunk) if self.geom.areas[i] > 0 and
                        np.linalg.norm(self.geom.normals[i]) > 0]
                if not live:
                    continue
                mats = np.zeros((MAX_FACES, 4, 4), dtype="f4")
                rects = np.zeros((MAX_FACES, 4), dtype="f4")
                for slot, b in enumerate(live):
                    for f, M in enumerate(self._face_matrices(int(chunk[b]))):
                        mats[FACES * slot + f] = M.T  # GLSL matrices are column-major
                        rects[FACES * slot + f] = self.rects[FACES * b + f]
                self.prog["clip_from_world"].write(mats.tobytes())
                self.prog["rect"].write(rects.tobytes())
                self.fbo.clear(depth=1.0)
                self.item.write(np.zeros(self.item.size[::-1], dtype="u4").tobytes())
                self.vao.render(instances=FACES * len(live))
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
        gl.check_errors(ctx)
        return out

    def matrix(self) -> np.ndarray:
        """The full matrix F (P, P)."""
        return self.rows(np.arange(self.P))

    def info(self) -> dict:
        return {"hemicube_resolution": self.res, "weight_sum": float(self.weights.sum()),
                "rotate": self.rotate, "gl_renderer": gl.renderer_name(self.ctx),
                "hemicubes_drawn": self.drawn}

    def release(self) -> None:
        for o in (self.vao, self.vbo, self.fbo, self.item, self.depth, self.prog):
            o.release()
