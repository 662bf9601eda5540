"""What each panel keeps on the GPU, and the moves of images between the CPU and the GPU.

* :class:`PanelGPU` (``state.gpu``, made by :func:`gpu` in the window's context) holds the
  display passes (:mod:`.display_passes`), the screen blits (:mod:`.screen_blits`), the
  raster panels (:class:`RasterPanel`), every panel's linear image on the GPU
  (:func:`linear_source`: a raster panel's framebuffer, else a float texture uploaded once
  per change of the image) and the keys of what is derived from images (:func:`stale`).
* Pixels come back to the CPU only when asked for: ``state.images[m]`` of a raster panel is a
  pending read (:class:`~.images.PanelImages`), resolved once per draw by the probe, the
  difference view, the export or a script (:func:`read_pixel`, :func:`read_values`,
  :func:`read_value`).  Statistics reduced on the GPU are read back one frame later
  (:func:`take_gpu_stats`).
* :func:`release_gl` frees all of it while the window's context still exists.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .display_passes import DisplayPasses
from .screen_blits import ScreenBlits
from .state import AppState

@dataclass
class RasterPanel:
    """A raster panel's session and what it last drew.

    ``session_key`` is (scene version, the panel's options); ``drawn`` the camera of the last draw
    (None: never drawn or values changed); ``draws`` counts draws (tests and the benchmark
    read it); ``edited`` when values last changed in place (:data:`.panel_refresh.LIVE_REST_SECONDS`);
    ``drawn_frame`` the frame of the last draw; ``timed`` whether ``state.timings`` holds the
    time of the image shown (False after a draw of a drag: :func:`.panel_refresh.refresh_raster`)."""

    session: object
    session_key: tuple
    drawn: object = None
    draws: int = 0
    edited: float = 0.0
    drawn_frame: int = -2
    timed: bool = True


@dataclass
class PanelGPU:
    """The GPU side of the panels, created with the window's context: the display passes,
    the raster panels, each panel's linear image on the GPU and the cache keys of what is
    derived from images."""

    passes: DisplayPasses
    blits: ScreenBlits
    raster: dict[str, RasterPanel] = field(default_factory=dict)
    linear: dict[str, tuple] = field(default_factory=dict)
    """panel -> (float texture, flip, ``state.images.version`` it holds)."""
    uploads: dict[str, object] = field(default_factory=dict)
    """panel -> its float texture (CPU images uploaded), value images (R32F) and tables."""
    shown: dict[str, tuple] = field(default_factory=dict)
    """texture name -> key of the image it was last made from."""
    stats: dict[str, tuple] = field(default_factory=dict)
    """image name -> (version, maximum, mean) (:func:`.panel_show.image_stats`)."""
    gpu_stats: dict[str, tuple] = field(default_factory=dict)
    """image name -> (version, 1 x 1 texture of its maximum and sum, frame it was queued in,
    pixel count): statistics reduced on the GPU (:func:`.panel_show.difference_on_gpu`), read back by
    :func:`take_gpu_stats`."""
    compiled: int = 0
    """GL programs compiled by raster sessions since released (tests count compiles)."""
    settle_frame: int = -1
    """The frame of the last ``RasterSession.settle`` step (one per frame)."""
    near_far: dict = field(default_factory=dict)
    """{"camera": the camera, boxes bytes: (near, far)}: :func:`.panel_refresh.shared_near_far`."""
    backdrops: dict[str, tuple] = field(default_factory=dict)
    """CPU panel -> (id of its current job, the image shown before that job):
    :func:`.panel_refresh.over_stale`."""
    modes: object = None
    """:class:`.display_modes.ModeDisplay`: panels shown through another mode than direct24."""
    shown_versions: dict[str, int] = field(default_factory=dict)
    """image name -> ``state.images`` version shown last frame (:func:`.panel_show.changing`)."""
    difference_inputs: tuple | None = None
    """(``state.images.version("difference")``, its value texture, the colour table, its
    statistics texture) of the difference view computed on the GPU
    (:func:`.panel_show.show_difference`)."""


def gpu(state: AppState) -> PanelGPU:
    """``state.gpu``, created on first use in the window's context."""
    if state.gpu is None:
        from .display_modes import ModeDisplay
        passes = DisplayPasses(state.ctx)
        state.gpu = PanelGPU(passes, ScreenBlits(state.ctx, passes),
                             modes=ModeDisplay(state.ctx, getattr(state.jobs, "notify", None)))
    return state.gpu


def stale(state: AppState, name: str, key) -> bool:
    """True if ``key`` differs from the one last recorded under ``name``; records it.  What is
    derived from images (textures, the difference view) is rebuilt only then."""
    g = gpu(state)
    if g.shown.get(name) == key:
        return False
    g.shown[name] = key
    return True


def _new_texture(state: AppState, size: tuple[int, int], components: int, **kw):
    """A display texture sampled nearest: a zoomed panel shows its pixels as squares (what a
    pixel probe needs), and llvmpipe samples it faster than with bilinear filtering."""
    import moderngl
    tex = state.ctx.texture(size, components, **kw)
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return tex


def display_texture(state: AppState, key: str, size: tuple[int, int]):
    """The RGBA8 texture ``key`` of ``size`` (w, h), created or resized as needed."""
    tex = state.textures.get(key)
    if tex is None or tex.size != size or tex.components != 4:
        if tex is not None:
            tex.release()
        tex = state.textures[key] = _new_texture(state, size, 4)
    return tex


def float_texture(state: AppState, name: str, size: tuple[int, int], components: int):
    """The float texture ``name`` of :attr:`PanelGPU.uploads`, created or resized."""
    g = gpu(state)
    tex = g.uploads.get(name)
    if tex is None or tex.size != size or tex.components != components:
        if tex is not None:
            tex.release()
        tex = g.uploads[name] = state.ctx.texture(size, components, dtype="f4")
    return tex


def linear_source(state: AppState, method: str) -> tuple[object, bool]:
    """(float texture, flip) holding ``state.images[method]`` on the GPU: a raster panel's
    framebuffer as drawn, otherwise the image uploaded (once per change of it)."""
    g = gpu(state)
    version = state.images.version(method)
    held = g.linear.get(method)
    if held is None or held[2] != version:
        image = state.images[method]
        tex = float_texture(state, method, (image.shape[1], image.shape[0]), 3)
        held = g.linear[method] = (g.passes.upload(image, tex), False, version)
    return held[0], held[1]


def upload(state: AppState, key: str, rgb8: np.ndarray):
    """Write an (H, W, 3) uint8 display-space image into the texture ``key`` (created or
    resized as needed)."""
    h, w = rgb8.shape[:2]
    tex = state.textures.get(key)
    if tex is None or tex.size != (w, h) or tex.components != 3:
        if tex is not None:
            tex.release()
        tex = state.textures[key] = _new_texture(state, (w, h), 3, alignment=1)
    tex.write(np.ascontiguousarray(rgb8).tobytes())
    return tex


def upload_linear(state: AppState, key: str, image: np.ndarray):
    """Show a linear (H, W, 3) image: upload it as floats and sRGB-encode it on the GPU into
    the RGBA8 texture ``key``."""
    h, w = image.shape[:2]
    passes = gpu(state).passes
    target = display_texture(state, key, (w, h))
    passes.encode(passes.upload(image), target, flip=False)
    return target


def read_values(texture) -> np.ndarray:
    """A value texture (R32F, row 0 on top) as an (H, W) float32 array."""
    w, h = texture.size
    return np.frombuffer(texture.read(), np.float32).reshape(h, w).copy()


def read_value(texture, i: int, j: int, shape: tuple[int, int]) -> np.ndarray | None:
    """Texel (row ``i`` from the top, column ``j``) of a value texture as a (1,) float32 array,
    or None unless the texture is ``shape`` (H, W)."""
    from ...renderers import gl
    w, h = texture.size
    if tuple(shape) != (h, w):
        return None
    fbo = texture.ctx.framebuffer(color_attachments=[texture])
    try:
        raw = fbo.read(viewport=(j, i, 1, 1), components=1, dtype="f4")
    finally:
        gl.release_framebuffer(fbo)
    return np.frombuffer(raw, np.float32).copy()


def read_pixel(fbo, i: int, j: int, shape: tuple[int, int]) -> np.ndarray | None:
    """Pixel (row ``i`` from the top, column ``j``) of a raster panel's framebuffer as (3,)
    float32, or None unless the framebuffer is ``shape`` (H, W): the probe's read of one
    pixel instead of the whole image."""
    if tuple(shape) != (fbo.height, fbo.width):
        return None
    raw = fbo.read(viewport=(j, fbo.height - 1 - i, 1, 1), components=3, dtype="f4")
    return np.frombuffer(raw, np.float32).copy()


def take_gpu_stats(state: AppState, name: str, now: bool = False) -> None:
    """Read back the statistics of ``name`` reduced on the GPU (:attr:`PanelGPU.gpu_stats`)
    into :attr:`PanelGPU.stats`, if not already there, once the frame that queued them has
    been shown (its buffer swap waited for them: the read waits for nothing), or at once with
    ``now``."""
    g = gpu(state)
    queued = g.gpu_stats.get(name)
    if queued is None or g.stats.get(name, (None,))[0] == queued[0]:
        return
    version, texture, frame, count = queued
    if frame == state.frame and not now:
        return
    vmax, total = np.frombuffer(texture.read(), np.float32)[:2]
    g.stats[name] = (version, float(vmax), float(total) / count)


def release_gl(state: AppState) -> None:
    """Free sessions, textures and the display pass while the context still exists."""
    if state.gpu is not None:
        for panel in state.gpu.raster.values():
            panel.session.release()
        for tex in state.gpu.uploads.values():
            tex.release()
        state.gpu.passes.release()
        state.gpu.blits.release()
        state.gpu.modes.release()
        state.gpu = None
    for tex in state.textures.values():
        tex.release()
    state.textures.clear()
