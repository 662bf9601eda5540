"""Producing each panel's image for the current frame and uploading it to a GL texture.

Raster methods draw every frame into the window's own moderngl context through a cached
:class:`~workbench.renderers.raster.RasterSession` (one per scene version, method and
tessellation; replaced sessions are released).  CPU methods are requested from the
:class:`~.jobs.JobBoard`: the panel shows the finished image or the tiles so far.
"""
from __future__ import annotations

import time

import numpy as np

from ...core.imageio import to_srgb8
from .state import RASTER, AppState

TILED = ("raycast", "raytrace")
"""CPU methods that accept ``on_tile`` (partial images)."""
SRGB_LUT_SIZE = 1 << 14
"""Entries of the display table linear [0, 1] -> sRGB 8 bit (at most 1 level from
:func:`~workbench.core.imageio.to_srgb8`; about 3x faster per frame)."""


def srgb_lut() -> np.ndarray:
    """(SRGB_LUT_SIZE,) uint8 table of :func:`~workbench.core.imageio.to_srgb8` on a uniform
    grid of [0, 1]."""
    return to_srgb8(np.linspace(0.0, 1.0, SRGB_LUT_SIZE))


def to_display(lut: np.ndarray, image: np.ndarray) -> np.ndarray:
    """(H, W, 3) finite linear float -> (H, W, 3) uint8 sRGB through ``lut``."""
    idx = (np.clip(image, 0.0, 1.0) * (len(lut) - 1) + 0.5).astype(np.intp)
    return lut[idx]


def raster_image(state: AppState, method: str) -> np.ndarray:
    """Draw ``method`` with the shared camera; (H, W, 3) float32 linear."""
    from ...renderers.raster import RasterSession
    tess = int(state.options[method]["tessellation"])
    key = (state.scene_version, tess)
    held = state.sessions.get(method)
    if held is None or held[0] != key:
        if held is not None:
            held[1].release()
        held = (key, RasterSession(state.scene, method, tessellation=tess, ctx=state.ctx))
        state.sessions[method] = held
    t0 = time.perf_counter()
    img = held[1].draw(state.camera)
    state.ctx.screen.use()  # back to the window's framebuffer for imgui
    state.timings[method] = time.perf_counter() - t0
    state.status[method] = f"{held[1].n_triangles} triangles"
    return img


def cpu_image(state: AppState, method: str) -> np.ndarray:
    """The current background job's image (finished, or its tiles so far)."""
    job = state.jobs.request(state.scene, state.camera, method, state.options[method],
                             tiled=method in TILED)
    if job.cancelled.is_set():
        state.status[method] = "restarting (stale image)"
    elif job.error:
        state.status[method] = job.error
    elif job.done:
        state.timings[method] = job.seconds
        state.status[method] = "done"
    else:
        state.status[method] = (f"rendering: {job.rows_done}/{state.camera.height} rows"
                                if method in TILED else "rendering...")
    return job.snapshot()


def update_images(state: AppState) -> None:
    """Fill ``state.images`` for every selected method."""
    for m in state.methods:
        state.images[m] = raster_image(state, m) if m in RASTER else cpu_image(state, m)


def upload(state: AppState, key: str, rgb8: np.ndarray):
    """Write an (H, W, 3) uint8 image into the texture ``key`` (created or resized as needed)."""
    h, w = rgb8.shape[:2]
    tex = state.textures.get(key)
    if tex is None or tex.size != (w, h):
        if tex is not None:
            tex.release()
        tex = state.ctx.texture((w, h), 3, alignment=1)
        state.textures[key] = tex
    tex.write(np.ascontiguousarray(rgb8).tobytes())
    return tex


def upload_linear(state: AppState, key: str, image: np.ndarray):
    """sRGB-encode a linear image (table :func:`srgb_lut`) and upload it."""
    if state.srgb_lut is None:
        state.srgb_lut = srgb_lut()
    return upload(state, key, to_display(state.srgb_lut, image))


def release_gl(state: AppState) -> None:
    """Free sessions and textures while the context still exists."""
    for _, session in state.sessions.values():
        session.release()
    for tex in state.textures.values():
        tex.release()
    state.sessions.clear()
    state.textures.clear()
