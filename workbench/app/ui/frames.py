"""Each panel's picture, kept on the GPU and redrawn only when what it shows changes.

* Raster methods (flat, Gouraud, Phong) draw through a cached
  :class:`~workbench.renderers.raster.RasterSession` (one per scene version, method and
  tessellation; replaced sessions are released) into the session's float framebuffer, in the
  window's own moderngl context, and only when the panel's inputs change: the scene version
  (materials, lights), the tessellation knob and the shared camera (which carries the panel
  size).  A frame in which nothing changed draws nothing.
* Every linear image reaches the screen through one GPU pass (:class:`SrgbEncoder`,
  ``shaders/display_srgb.*``): sRGB encoding (IEC 61966-2-1, the numbers of
  :func:`workbench.core.imageio.to_srgb8`) into an RGBA8 texture that imgui shows.  Raster
  images are encoded straight from their framebuffer; CPU images (background jobs, display
  modes, the colour wheel) are uploaded as float textures first, once per change.
* Pixels come back to the CPU only when asked for: ``state.images[m]`` of a raster panel is a
  pending read (:class:`~.images.PanelImages`), resolved once per draw by the probe, the
  difference view, the export or a script.
* CPU methods are requested from the :class:`~.jobs.JobBoard`; their texture is refreshed when
  the job reports new tiles (``Job.version``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .state import CHILD, RASTER, AppState, shown_image

TILED = ("raycast", "raytrace")
"""CPU methods that accept ``on_tile`` (partial images)."""


class SrgbEncoder:
    """The display pass: a linear float texture -> an RGBA8 sRGB texture of the same size.

    One program (``shaders/display_srgb.vert|frag``, a full-screen triangle, ``texelFetch`` so
    nothing is filtered) and one float scratch texture per image size for uploads."""

    def __init__(self, ctx):
        from ...renderers.raster_shaders import SHADER_DIR
        self.ctx = ctx
        self.program = ctx.program(
            vertex_shader=(SHADER_DIR / "display_srgb.vert").read_text(encoding="utf-8"),
            fragment_shader=(SHADER_DIR / "display_srgb.frag").read_text(encoding="utf-8"))
        self.program["u_linear"].value = 0
        self.vao = ctx.vertex_array(self.program, [])
        self.scratch: dict[tuple[int, int], object] = {}

    def upload(self, image: np.ndarray):
        """(H, W, 3) linear image (row 0 on top) -> the float scratch texture of its size."""
        h, w = image.shape[:2]
        tex = self.scratch.get((w, h))
        if tex is None:
            tex = self.scratch[(w, h)] = self.ctx.texture((w, h), 3, dtype="f4")
        tex.write(np.ascontiguousarray(image, dtype=np.float32).tobytes())
        return tex

    def encode(self, source, target, flip: bool) -> None:
        """Fill ``target`` (RGBA8, the size of ``source``) with ``source`` sRGB-encoded, row 0
        on top; ``flip`` when ``source`` has row 0 at the bottom (a framebuffer)."""
        import moderngl

        from ...renderers import gl
        ctx = self.ctx
        fbo = ctx.framebuffer(color_attachments=[target])
        fbo.use()
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        source.use(0)
        self.program["u_flip"].value = int(flip)
        self.vao.render(moderngl.TRIANGLES, vertices=3)
        gl.release_framebuffer(fbo)
        ctx.screen.use()  # back to the window's framebuffer for imgui

    def release(self) -> None:
        for tex in self.scratch.values():
            tex.release()
        self.scratch.clear()
        self.vao.release()
        self.program.release()


@dataclass
class RasterPanel:
    """A raster panel's session and what it last drew.

    ``session_key`` is (scene version, tessellation); ``drawn`` the camera of the last draw
    (None: never drawn); ``draws`` counts draws (tests and the benchmark read it)."""

    session: object
    session_key: tuple
    drawn: object = None
    draws: int = 0


@dataclass
class PanelGPU:
    """The GPU side of the panels, created with the window's context: the display pass, the
    raster panels, and the cache keys of the textures derived from CPU images."""

    encoder: SrgbEncoder
    raster: dict[str, RasterPanel] = field(default_factory=dict)
    shown: dict[str, tuple] = field(default_factory=dict)
    """texture name -> key of the image it was last made from."""


def gpu(state: AppState) -> PanelGPU:
    """``state.gpu``, created on first use in the window's context."""
    if state.gpu is None:
        state.gpu = PanelGPU(SrgbEncoder(state.ctx))
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
    if tex is None or tex.size != size:
        if tex is not None:
            tex.release()
        tex = state.textures[key] = _new_texture(state, size, 4)
    return tex


def refresh_raster(state: AppState, method: str) -> bool:
    """Redraw ``method``'s panel if its inputs changed; returns whether it drew."""
    from ...renderers.raster import RasterSession
    g = gpu(state)
    tess = int(state.options[method]["tessellation"])
    key = (state.scene_version, tess)
    panel = g.raster.get(method)
    if panel is None or panel.session_key != key:
        if panel is not None:
            panel.session.release()
        panel = g.raster[method] = RasterPanel(
            RasterSession(state.scene, method, tessellation=tess, ctx=state.ctx), key)
        state.status[method] = f"{panel.session.n_triangles} triangles"
    cam = state.camera
    if panel.drawn == cam and method in state.images and method in state.textures:
        return False
    t0 = time.perf_counter()
    fbo = panel.session.framebuffer(cam.width, cam.height)
    panel.session.draw_to(fbo, cam)
    g.encoder.encode(fbo.color_attachments[0],
                     display_texture(state, method, (cam.width, cam.height)), flip=True)
    state.ctx.finish()  # the time shown is the draw's, not just its submission
    state.timings[method] = time.perf_counter() - t0
    state.images.set_pending(method, lambda: RasterSession.read_image(fbo))
    g.shown[method] = (state.images.version(method), "direct24")
    panel.drawn, panel.draws = cam, panel.draws + 1
    return True


def refresh_cpu(state: AppState, method: str) -> None:
    """Ask for ``method``'s background job; take its image when it has new tiles."""
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
    if stale(state, f"{method} job", (id(job), job.version)) or method not in state.images:
        state.images[method] = job.snapshot()


def update_images(state: AppState) -> None:
    """Bring every selected panel up to date (called once per frame, before the widgets)."""
    from .pyrender_proc import refresh_pyrender
    for m in state.methods:
        if m in RASTER:
            refresh_raster(state, m)
        elif m in CHILD:
            refresh_pyrender(state)
        else:
            refresh_cpu(state, m)


def panel_texture(state: AppState, method: str):
    """The RGBA8 texture showing ``method``'s panel through its display mode; rebuilt only
    when the image or the mode changed."""
    mode = state.display.get(method, "direct24")
    key = (state.images.version(method), mode)
    if stale(state, method, key) or method not in state.textures:
        upload_linear(state, method, shown_image(state, method))
    return state.textures[method]


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
    enc = gpu(state).encoder
    target = display_texture(state, key, (w, h))
    enc.encode(enc.upload(image), target, flip=False)
    return target


def release_gl(state: AppState) -> None:
    """Free sessions, textures and the display pass while the context still exists."""
    if state.gpu is not None:
        for panel in state.gpu.raster.values():
            panel.session.release()
        state.gpu.encoder.release()
        state.gpu = None
    for tex in state.textures.values():
        tex.release()
    state.textures.clear()
