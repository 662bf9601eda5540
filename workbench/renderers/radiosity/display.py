"""The classic radiosity image: patch radiosity interpolated to vertices (area-weighted mean
of the patches around each vertex of one surface) and drawn from the scene camera with
Gouraud shading through OpenGL (moderngl, FBO; shaders/radiosity_gouraud_*.glsl)."""
from __future__ import annotations

import time

import numpy as np

from ...core.resources import data_dir
from ...core.tol import tol
from ...scene.model import Camera
from .. import gl
from .patches import PatchSet

SHADERS = data_dir("shaders")
NEAR_FRACTION = 1e-3    # near plane as a fraction of the farthest vertex depth


def clip_planes(camera: Camera, points: np.ndarray) -> tuple[float, float]:
    """(near, far): the camera's own, else from the depths of ``points`` (N, 3)."""
    if camera.near is not None and camera.far is not None:
        return camera.near, camera.far
    _, depth = camera.project(points)
    far = float(max(depth.max(), tol.zero)) * 1.01 if len(depth) else 1.0
    near = max(float(depth[depth > 0].min()) * 0.5 if (depth > 0).any() else far, far * NEAR_FRACTION)
    return (camera.near or min(near, far * 0.5)), (camera.far or far)


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
    near, far = clip_planes(camera, patches.vertices)
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
