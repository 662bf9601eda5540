"""The classic radiosity image: patch radiosity interpolated to vertices (area-weighted mean
of the patches around each vertex of one surface) and drawn from the scene camera with
Gouraud shading through OpenGL (moderngl, FBO; shaders/radiosity_gouraud_*.glsl)."""
from __future__ import annotations

import time

import numpy as np

from ...core.resources import data_dir
from ...scene.clip_planes import auto_near_far
from ...scene.model import Camera
from .. import gl
from .patches import PatchSet

SHADERS = data_dir("shaders")


def clip_planes(camera: Camera, patches: PatchSet) -> tuple[float, float]:
    """(near, far): the raster's automatic rule (:func:`workbench.scene.clip_planes.auto_near_far`)
    over each surface's box of patch corners.  Boxes, not vertices: a surface can pass closer
    to the camera than any of its corners (a camera just above a floor cut into large patches)."""
    corners = patches.vertices[patches.vertex_ids]                   # (P, 4, 3)
    _, owner = np.unique(patches.surface, return_inverse=True)
    lo = np.full((owner.max(initial=-1) + 1, 3), np.inf)
    hi = np.full_like(lo, -np.inf)
    np.minimum.at(lo, owner, corners.min(1))
    np.maximum.at(hi, owner, corners.max(1))
    return auto_near_far(camera, np.stack([lo, hi], 1))


def draw(patches: PatchSet, radiance: np.ndarray, camera: Camera, background) -> tuple[np.ndarray, dict]:
    """Image (H, W, 3) float32 (top row first) of ``patches`` coloured by ``radiance`` (P, 3).

    Returns the image and timings ``{"compile": shader build, "display": the rest}``.
    """
    ctx = gl.context()
    t0 = time.perf_counter()
    src = [(SHADERS / f"radiosity_gouraud_{s}.glsl").read_text() for s in ("vs", "fs")]
    prog = ctx.program(vertex_shader=src[0], fragment_shader=src[1])
    t_compile = time.perf_counter() - t0
    vcol = patches.vertex_values(radiance)
    ids = patches.vertex_ids
    tris = np.concatenate([ids[:, [0, 1, 2]], ids[:, [0, 2, 3]]]).astype("u4")
    near, far = clip_planes(camera, patches)
    M = camera.clip_from_camera(near, far) @ camera.camera_from_world()
    data = np.concatenate([patches.vertices, vcol], 1).astype("f4")
    W, H = camera.width, camera.height
    vbo = ctx.buffer(data.tobytes())
    ibo = ctx.buffer(tris.tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "3f 3f", "in_pos", "in_radiance")], ibo, index_element_size=4)
    tex = ctx.texture((W, H), 4, dtype="f4")
    depth = ctx.depth_renderbuffer((W, H))
    fbo = ctx.framebuffer(color_attachments=[tex], depth_attachment=depth)
    previous = ctx.fbo     # rebound afterwards: releasing a bound FBO breaks the next one
    try:
        fbo.use()
        ctx.viewport = (0, 0, W, H)
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        bg = tuple(float(c) for c in background)
        fbo.clear(*bg, 1.0, depth=1.0)
        prog["clip_from_world"].write(M.T.astype("f4").tobytes())
        vao.render()
        img = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype="f4").reshape(H, W, 4)
        gl.check_errors(ctx)
    finally:
        if previous is not None:
            previous.use()
        gl.release_framebuffer(fbo)
        for o in (vao, vbo, ibo, tex, depth, prog):
            o.release()
    return np.ascontiguousarray(img[::-1, :, :3]), {"compile": t_compile,
                                                  "display": time.perf_counter() - t0 - t_compile}
