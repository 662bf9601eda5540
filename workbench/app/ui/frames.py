"""Each panel's picture, kept on the GPU and redrawn only when what it shows changes.

* GL methods (``ui_kind`` ``"gl"``: flat, Gouraud, Phong, a user's shading model) draw through a cached
  :class:`~workbench.renderers.raster.RasterSession` (one per scene, method and options,
  built by :func:`.gl_sessions.build_session`; replaced sessions are released) into the
  session's float framebuffer, in the window's own moderngl context, and only when the
  panel's inputs change: the scene version (materials, lights), the panel's options
  (tessellation, stand-ins) and the shared camera (which carries the panel size).  A frame in which nothing changed draws nothing.  A material or light slider keeps
  the session (``RasterSession.update``): the edited values are drawn by live programs that
  read them from uniforms (compiled once, no geometry upload), and once the values have
  rested for :data:`LIVE_REST_SECONDS` they are compiled back in (``settle``: the literal
  programs, the fast static variant), one program per frame.
* Every panel's linear image has a GPU copy (:func:`linear_source`: a raster panel's
  framebuffer, else a float texture uploaded once per change of the image) and reaches the
  screen through GPU passes (:class:`DisplayPasses`, ``shaders/display*``): sRGB encoding
  (IEC 61966-2-1, the numbers of :func:`workbench.core.imageio.to_srgb8`; during a drag the
  window's sRGB framebuffer encodes, within one level of them), and the
  difference view's ``"abs"`` map, its maximum and mean reduced on the GPU, and colour
  scale.  They draw into the window's framebuffer under imgui's drawing
  (:class:`ScreenBlits`), not drawn by imgui as quads: straight from the linear image while
  it changes, from an RGBA8 display texture made once when it stays.
* During a drag (a panel drawn in consecutive frames) the frame does not wait for the GPU
  where it need not: no ``glFinish`` after a panel's draw (it is timed once the camera
  rests, by one more draw of the same image: :func:`timed_draw`) and no read-back for the
  difference view's colour scale (its numbers are read one frame later:
  :func:`take_gpu_stats`).  llvmpipe itself still waits where a pass reads a panel whose
  draw is not done.
* Pixels come back to the CPU only when asked for: ``state.images[m]`` of a raster panel is a
  pending read (:class:`~.images.PanelImages`), resolved once per draw by the probe, the
  difference view, the export or a script.
* CPU and progressive methods are requested from the :class:`~.jobs.JobBoard`; their texture is refreshed when
  the job reports new tiles (``Job.version``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from . import window_quad
from .state import AppState, method_kind

LIVE_REST_SECONDS = 0.5
"""How long edited material or light values must stay unchanged before a GL panel compiles
them back into its programs (until then it draws them from uniforms)."""
SCALE_FLOOR = 1e-6
"""The difference view's colour scale runs from 0 to the map's maximum, or to this if the
maximum is smaller (two equal images show the scale's first colour)."""
GL_FRAMEBUFFER_SRGB = 0x8DB9
STATS_BLOCK = 8
"""Texels along each side of the blocks one step of :meth:`DisplayPasses.statistics` reduces."""


def tiled(method: str) -> bool:
    """The method accepts ``on_tile`` (it reports partial images band by band)."""
    from ...renderers.base import get_renderer
    return "on_tile" in get_renderer(method).options


class DisplayPasses:
    """The GPU passes between the panels' linear images and the screen, reading their inputs
    with ``texelFetch`` (no filtering), each a full-screen triangle (``shaders/display.vert``)
    into a texture or a quad over the image's rectangle of the window (:mod:`.window_quad`):

    * :meth:`encode` (``display_srgb.frag``): linear float -> RGBA8 sRGB;
    * :meth:`difference` (``display_difference.frag``): two linear images -> their per-pixel
      mean absolute difference (R32F), the ``"abs"`` error map;
    * :meth:`statistics` (``display_stats.frag``): a value image -> its maximum and sum,
      reduced on the GPU by steps of :data:`STATS_BLOCK` x :data:`STATS_BLOCK` texels;
    * :meth:`colour_map` (``display_colour_map.frag``): a value image -> RGBA8 colours of a
      table (the difference view's colour scale) up to the maximum :meth:`statistics` left
      on the GPU (no read-back between them).

    :meth:`to_window` draws ``srgb``, ``colour_map``, ``copy`` (``display_copy.frag``: a
    display texture as it is) or ``linear`` (``display_linear.frag``: the linear image, for a
    window that encodes sRGB itself) straight into the window, scaled to the image's rectangle.

    Also one float scratch texture per image size for :meth:`upload` and one chain of
    reduction textures per image size for :meth:`statistics`."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.programs = {name: self._program(name)
                         for name in ("srgb", "difference", "colour_map", "stats")}
        self.vaos = {name: ctx.vertex_array(prog, []) for name, prog in self.programs.items()}
        for name in ("srgb", "linear", "colour_map", "copy"):
            key = f"{name} to window"
            self.programs[key], self.vaos[key] = window_quad.program(ctx, f"display_{name}.frag")
            self._bind_samplers(self.programs[key])
        self.scratch: dict[tuple[int, int], object] = {}
        self.chains: dict[tuple[int, int], list] = {}

    @staticmethod
    def _bind_samplers(prog) -> None:
        for unit, sampler in enumerate(("u_linear", "u_a", "u_b", "u_value", "u_table", "u_stats",
                                        "u_image")):
            if sampler in prog:
                prog[sampler].value = unit

    def _program(self, name: str):
        from ...renderers.raster_shaders import SHADER_DIR, build_source
        prog = self.ctx.program(
            vertex_shader=(SHADER_DIR / "display.vert").read_text(encoding="utf-8"),
            fragment_shader=build_source(f"display_{name}.frag", {}))
        self._bind_samplers(prog)
        return prog

    def to_window(self, name: str, inputs: dict, src: tuple, dst: tuple, **uniforms) -> None:
        """Draw pass ``name`` (``"srgb"``, ``"linear"``, ``"colour_map"`` or ``"copy"``) with
        ``inputs`` {sampler: texture} into the bound window framebuffer, within its scissor:
        the texel window ``src`` of its image into the window rectangle ``dst``
        (:func:`.window_quad.draw`).  ``"linear"`` writes linear values: the caller enables
        the window's own sRGB encoding around it (:attr:`ScreenBlits.srgb`)."""
        import moderngl
        ctx, prog = self.ctx, self.programs[f"{name} to window"]
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        for sampler, tex in inputs.items():
            tex.use(prog[sampler].value)
        for k, v in uniforms.items():
            prog[k].value = v
        window_quad.draw(ctx, prog, self.vaos[f"{name} to window"], src, dst)

    def upload(self, image: np.ndarray, texture=None):
        """(H, W, 3) linear image (row 0 on top) -> ``texture`` (a float RGB texture of its
        size), by default the scratch texture of that size."""
        h, w = image.shape[:2]
        if texture is None:
            texture = self.scratch.get((w, h))
            if texture is None:
                texture = self.scratch[(w, h)] = self.ctx.texture((w, h), 3, dtype="f4")
        texture.write(np.ascontiguousarray(image, dtype=np.float32).tobytes())
        return texture

    def _run(self, name: str, target, inputs: dict, **uniforms) -> None:
        """Draw pass ``name`` into ``target`` with ``inputs`` {sampler: texture}."""
        import moderngl

        from ...renderers import gl
        ctx, prog = self.ctx, self.programs[name]
        fbo = ctx.framebuffer(color_attachments=[target])
        fbo.use()
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        for sampler, tex in inputs.items():
            tex.use(prog[sampler].value)
        for k, v in uniforms.items():
            prog[k].value = v
        self.vaos[name].render(moderngl.TRIANGLES, vertices=3)
        gl.release_framebuffer(fbo)
        ctx.screen.use()  # back to the window's framebuffer for imgui

    def encode(self, source, target, flip: bool) -> None:
        """Fill ``target`` (RGBA8, the size of ``source``) with ``source`` sRGB-encoded, row 0
        on top; ``flip`` when ``source`` has row 0 at the bottom (a framebuffer)."""
        self._run("srgb", target, {"u_linear": source}, u_flip=int(flip))

    def difference(self, a, b, target) -> None:
        """Fill ``target`` (R32F) with the ``"abs"`` error map of ``a`` and ``b``, each given as
        (texture, flip)."""
        self._run("difference", target, {"u_a": a[0], "u_b": b[0]},
                  u_flip_a=int(a[1]), u_flip_b=int(b[1]))

    def statistics(self, values):
        """The maximum (r) and sum (g) of ``values`` (R32F, values >= 0) in a 1 x 1 RG32F
        texture, left on the GPU: each step sums and takes the maximum of blocks of at most
        :data:`STATS_BLOCK` x :data:`STATS_BLOCK` texels of the previous one (a 512 x 384 map:
        64 x 48, 8 x 6, 1 x 1)."""
        chain = self.chains.get(values.size)
        if chain is None:
            chain, (w, h) = [], values.size
            while not chain or (w, h) != (1, 1):
                w, h = -(-w // STATS_BLOCK), -(-h // STATS_BLOCK)
                chain.append(self.ctx.texture((w, h), 2, dtype="f4"))
            self.chains[values.size] = chain
        source, first = values, 1
        for target in chain:
            block = tuple(-(-n // m) for n, m in zip(source.size, target.size))
            self._run("stats", target, {"u_value": source}, u_block=block, u_first=first)
            source, first = target, 0
        return chain[-1]

    def colour_map(self, values, table, stats, target) -> None:
        """Fill ``target`` (RGBA8) with the colours of ``table`` ((n, 1) texture) for
        ``values`` (R32F) in [0, vmax], vmax the maximum in ``stats`` (:meth:`statistics`)
        or :data:`SCALE_FLOOR` if larger."""
        self._run("colour_map", target, {"u_value": values, "u_table": table, "u_stats": stats},
                  u_floor=SCALE_FLOOR)

    def release(self) -> None:
        chains = [t for chain in self.chains.values() for t in chain]
        for obj in [*self.scratch.values(), *chains, *self.vaos.values(), *self.programs.values()]:
            obj.release()
        self.scratch.clear()
        self.chains.clear()


class ScreenBlits:
    """Big images (the panels, the difference view) put straight into the window's
    framebuffer under imgui's drawing, scaled to their item's rectangle as a nearest blit:

    * while an image changes (a drag), drawn by the display pass that makes it
      (:meth:`DisplayPasses.to_window`: a linear image sRGB-encoded, by the window's own
      framebuffer where it is sRGB-capable (:meth:`linear`), a display mode's GPU view, the
      difference's colour map): one pass where encoding into an RGBA8 display texture and
      blitting that were two;
    * an image that stays is encoded once into its display texture, which is then copied by
      ``glBlitFramebuffer`` each frame (3 panels: 8.5 ms of CPU against 10.2 for a copying
      pass, ``display_copy.frag``, used where the window's GLFW gives no
      ``glBlitFramebuffer``; ``bench/ui_frame_gpu.py``'s context at a load of 10).

    Not imgui's textured, blended quads: on llvmpipe a shaded and blended fragment per pixel
    (4 panels: ~5.5 ms against ~0.4 ms for blits, measured in a standalone context).
    Scripts and tests read display textures through :func:`shown_texture`.

    :meth:`show` stands in for ``imgui.image`` (an empty item of the same size, so hovering,
    the probe and the mouse work as before) and queues the image, clipped to what imgui would
    show of the item (its window's clip rectangle); :meth:`flush` draws the queue once the
    gui is done (``before_imgui_render``), so imgui's popups and floating windows still draw
    over the panels.  ``last`` lists (name, item rectangle) drawn by the last flush (tests
    compare them with screenshots)."""

    def __init__(self, ctx, passes: DisplayPasses):
        import ctypes
        from pathlib import Path

        import imgui_bundle
        self.ctx, self.passes = ctx, passes
        self.queue: list[tuple] = []
        self.last: list[tuple[str, tuple]] = []
        self.read_fbos: dict[int, object] = {}
        try:
            glfw = ctypes.CDLL(str(Path(imgui_bundle.__file__).parent / "libglfw.so.3"))
            glfw.glfwGetProcAddress.restype = ctypes.c_void_p
            glfw.glfwGetProcAddress.argtypes = [ctypes.c_char_p]
            bind = glfw.glfwGetProcAddress(b"glBindFramebuffer")
            blit = glfw.glfwGetProcAddress(b"glBlitFramebuffer")
            query = glfw.glfwGetProcAddress(b"glGetFramebufferAttachmentParameteriv")
        except (OSError, AttributeError):
            bind = blit = query = None
        u, i = ctypes.c_uint, ctypes.c_int
        self.bind = ctypes.CFUNCTYPE(None, u, u)(bind) if bind else None
        self.blit = ctypes.CFUNCTYPE(None, i, i, i, i, i, i, i, i, u, u)(blit) if blit else None
        self.srgb = bool(query) and self._window_encodes_srgb(query)
        """The window's framebuffer is sRGB-capable: with ``GL_FRAMEBUFFER_SRGB`` enabled it
        encodes what a pass writes (:meth:`linear`)."""

    @staticmethod
    def drawn(draw, size: tuple[int, int]) -> tuple:
        """An image (for :meth:`show`) of ``size`` (w, h) drawn by ``draw(src, dst)``, a pass
        into the bound window framebuffer as :meth:`DisplayPasses.to_window` takes them."""
        return draw, size

    def copied(self, texture) -> tuple:
        """An image (for :meth:`show`) that is ``texture`` (a display texture, row 0 on top)
        as it is."""
        if self.blit is None:
            return self.drawn(lambda src, dst: self.passes.to_window("copy", {"u_image": texture}, src, dst),
                              texture.size)

        def run(src, dst):
            self.bind(0x8CA8, self._read_fbo(texture).glo)  # GL_READ_FRAMEBUFFER
            self.bind(0x8CA9, 0)  # GL_DRAW_FRAMEBUFFER: the window's
            self.blit(*src, *dst, 0x4000, 0x2600)  # GL_COLOR_BUFFER_BIT, GL_NEAREST
            self.blitted.add(texture.glo)
        return run, texture.size

    def linear(self, source, flip: bool) -> tuple:
        """An image (for :meth:`show`) that is the linear float texture ``source`` (row 0 at
        the bottom with ``flip``) sRGB-encoded: by the window's framebuffer where it encodes
        sRGB itself (:attr:`srgb`; the encoding may round a level the other way, see
        ``display_linear.frag``), else by the exact pass ``display_srgb.frag``."""
        passes = self.passes
        if not self.srgb:
            return self.drawn(lambda src, dst: passes.to_window(
                "srgb", {"u_linear": source}, src, dst, u_flip=int(flip)), source.size)

        def run(src, dst):
            self.ctx.enable_direct(GL_FRAMEBUFFER_SRGB)
            try:
                passes.to_window("linear", {"u_linear": source}, src, dst, u_flip=int(flip))
            finally:  # imgui draws in display space: never with the encoding on
                self.ctx.disable_direct(GL_FRAMEBUFFER_SRGB)
        return run, source.size

    def _window_encodes_srgb(self, address: int) -> bool:
        """Whether the window's back buffer stores sRGB (``GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING``
        of ``GL_BACK_LEFT`` is ``GL_SRGB``; Mesa's GLX visuals are, GLFW does not promise it)."""
        import ctypes
        if self.ctx.screen is None or self.bind is None:
            return False
        get = ctypes.CFUNCTYPE(None, ctypes.c_uint, ctypes.c_uint, ctypes.c_uint,
                               ctypes.POINTER(ctypes.c_int))(address)
        value = ctypes.c_int(0)
        self.bind(0x8D40, 0)  # GL_FRAMEBUFFER: the window's
        get(0x8D40, 0x0402, 0x8210, ctypes.byref(value))  # GL_BACK_LEFT, ..._COLOR_ENCODING
        return value.value == 0x8C40 and self.ctx.error == "GL_NO_ERROR"  # GL_SRGB

    def _read_fbo(self, texture):
        from ...renderers import gl
        fbo = self.read_fbos.get(texture.glo)
        if fbo is None or fbo.color_attachments[0] is not texture:  # new, or a reused name
            if fbo is not None:
                gl.release_framebuffer(fbo)
            fbo = self.read_fbos[texture.glo] = self.ctx.framebuffer(color_attachments=[texture])
        return fbo

    def show(self, name: str, image: tuple, size, uv0, uv1) -> None:
        """An item of ``size`` showing the (u, v) window [uv0, uv1] of ``image`` (row 0 on
        top: :meth:`drawn` or :meth:`copied`)."""
        from imgui_bundle import imgui
        imgui.dummy(size)
        if imgui.is_item_visible():
            dl = imgui.get_window_draw_list()
            lo, hi = imgui.get_item_rect_min(), imgui.get_item_rect_max()
            clo, chi = dl.get_clip_rect_min(), dl.get_clip_rect_max()
            self.queue.append((name, image, (lo.x, lo.y, hi.x, hi.y), tuple(uv0), tuple(uv1),
                               (max(lo.x, clo.x), max(lo.y, clo.y), min(hi.x, chi.x),
                                min(hi.y, chi.y))))

    def flush(self) -> None:
        """Draw the queued images into the window's framebuffer (window coordinates times the
        framebuffer scale, y up; the source window rounded out to whole texels and the
        destination stretched to match, then clipped by the scissor)."""
        import math

        from imgui_bundle import imgui

        from ...renderers import gl
        io = imgui.get_io()
        sx, sy = io.display_framebuffer_scale.x, io.display_framebuffer_scale.y
        fb_h = io.display_size.y * sy
        self.last, self.blitted = [], set()
        self.ctx.screen.use()  # moderngl sets the scissor of the bound framebuffer
        for name, image, (x0, y0, x1, y1), (u0, v0), (u1, v1), (cx0, cy0, cx1, cy1) in self.queue:
            if cx1 <= cx0 or cy1 <= cy0:
                continue
            run, (w, h) = image
            a0, a1, b0, b1 = u0 * w, u1 * w, v0 * h, v1 * h
            ia0, ia1, ib0, ib1 = math.floor(a0), math.ceil(a1), math.floor(b0), math.ceil(b1)
            kx, ky = (x1 - x0) / (a1 - a0), (y1 - y0) / (b1 - b0)  # window pixels per texel
            dx0, dx1 = x0 - (a0 - ia0) * kx, x1 + (ia1 - a1) * kx
            dy0, dy1 = y0 - (b0 - ib0) * ky, y1 + (ib1 - b1) * ky
            # texel row ib0 (the top) goes to the top of the item: destination y reversed
            dst = (round(dx0 * sx), round(fb_h - dy0 * sy), round(dx1 * sx), round(fb_h - dy1 * sy))
            if dst[0] == dst[2] or dst[1] == dst[3]:
                continue
            self.ctx.scissor = (round(cx0 * sx), round(fb_h - cy1 * sy),
                                round((cx1 - cx0) * sx), round((cy1 - cy0) * sy))
            run((ia0, ib0, ia1, ib1), dst)
            self.last.append((name, (x0, y0, x1, y1)))
        # a display texture re-made at another size (a scene of another aspect) gets a new
        # name: the read framebuffers of textures not copied this frame are released (they
        # piled up, one per re-made texture)
        for glo in [g for g in self.read_fbos if g not in self.blitted]:
            gl.release_framebuffer(self.read_fbos.pop(glo))
        self.queue = []
        self.ctx.scissor = None
        if self.bind is not None:
            self.bind(0x8D40, 0)  # GL_FRAMEBUFFER: the window's, as moderngl believes

    def release(self) -> None:
        for fbo in self.read_fbos.values():
            fbo.release()
        self.read_fbos.clear()


@dataclass
class RasterPanel:
    """A raster panel's session and what it last drew.

    ``session_key`` is (scene version, the panel's options); ``drawn`` the camera of the last draw
    (None: never drawn or values changed); ``draws`` counts draws (tests and the benchmark
    read it); ``edited`` when values last changed in place (:data:`LIVE_REST_SECONDS`);
    ``drawn_frame`` the frame of the last draw; ``timed`` whether ``state.timings`` holds the
    time of the image shown (False after a draw of a drag: :func:`refresh_raster`)."""

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
    """image name -> (version, maximum, mean) (:func:`image_stats`)."""
    gpu_stats: dict[str, tuple] = field(default_factory=dict)
    """image name -> (version, 1 x 1 texture of its maximum and sum, frame it was queued in,
    pixel count): statistics reduced on the GPU (:func:`difference_on_gpu`), read back by
    :func:`take_gpu_stats`."""
    compiled: int = 0
    """GL programs compiled by raster sessions since released (tests count compiles)."""
    settle_frame: int = -1
    """The frame of the last ``RasterSession.settle`` step (one per frame)."""
    near_far: dict = field(default_factory=dict)
    """{"camera": the camera, boxes bytes: (near, far)}: :func:`shared_near_far`."""
    backdrops: dict[str, tuple] = field(default_factory=dict)
    """CPU panel -> (id of its current job, the image shown before that job): :func:`over_stale`."""
    modes: object = None
    """:class:`.display_modes.ModeDisplay`: panels shown through another mode than direct24."""
    shown_versions: dict[str, int] = field(default_factory=dict)
    """image name -> ``state.images`` version shown last frame (:func:`changing`)."""
    difference_inputs: tuple | None = None
    """(``state.images.version("difference")``, its value texture, the colour table, its
    statistics texture) of the difference view computed on the GPU (:func:`show_difference`)."""


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


def _float_texture(state: AppState, name: str, size: tuple[int, int], components: int):
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
        tex = _float_texture(state, method, (image.shape[1], image.shape[0]), 3)
        held = g.linear[method] = (g.passes.upload(image, tex), False, version)
    return held[0], held[1]


def refresh_raster(state: AppState, method: str) -> bool:
    """Redraw ``method``'s panel if its inputs changed; returns whether it drew."""
    from ...core.errors import WorkbenchError
    from ...renderers.raster import RasterSession
    from .gl_sessions import build_session, session_status
    g = gpu(state)
    key = (state.scene_version, tuple(sorted(state.options[method].items())))
    panel = g.raster.get(method)
    if (panel is not None and panel.session_key != key and panel.session_key[1] == key[1]
            and panel.session.update(state.scene)):
        # only material or light values changed: same session, live programs
        panel.session_key, panel.drawn, panel.edited = key, None, time.perf_counter()
    elif panel is None or panel.session_key != key:
        if state.panel_errors.get(method, (None,))[0] == key:
            return False  # did not build for these inputs: its message stays shown
        if panel is not None:
            g.compiled += panel.session.programs.compiles
            panel.session.release()
            del g.raster[method]
            g.linear.pop(method, None)
        try:
            session = build_session(state, method)
        except WorkbenchError as e:  # over the memory limit, a model that does not compile: one line
            state.panel_errors[method] = (key, str(e))
            state.status[method] = str(e)
            if method in state.images:  # del, not pop: a pending read of a released session
                del state.images[method]
            state.ctx.screen.use()
            return False
        state.panel_errors.pop(method, None)
        panel = g.raster[method] = RasterPanel(session, key)
        state.status[method] = session_status(panel.session)
    if (panel.session.live and time.perf_counter() - panel.edited > LIVE_REST_SECONDS
            and g.settle_frame != state.frame):
        # the values rested: compiled back in (the static variant), one program per frame
        # over all panels (each costs llvmpipe ~0.1 s, most of it at its first draw)
        g.settle_frame = state.frame
        panel.session.settle(budget=1)
        panel.drawn = None
    cam = state.camera
    if panel.drawn == cam and method in state.images:
        if not panel.timed:  # the drag has ended: time a draw of the image shown
            timed_draw(state, panel, method)
            panel.draws += 1
        return False
    fbo = panel.session.framebuffer(cam.width, cam.height)
    if panel.drawn_frame == state.frame - 1:
        # drawn last frame too (a drag): no wait for the draw to end, so that llvmpipe's
        # threads rasterise it while this thread goes on with the frame; it is timed once
        # the camera rests
        panel.session.draw_to(fbo, cam, *shared_near_far(g, panel.session, cam))
        state.ctx.screen.use()  # back to the window's framebuffer for imgui
        panel.timed = False
    else:
        timed_draw(state, panel, method, fbo)
    state.images.set_pending(method, lambda: RasterSession.read_image(fbo),
                             pixel=lambda i, j, shape: read_pixel(fbo, i, j, shape),
                             shape=(cam.height, cam.width))
    g.linear[method] = (fbo.color_attachments[0], True, state.images.version(method))
    panel.drawn, panel.draws, panel.drawn_frame = cam, panel.draws + 1, state.frame
    return True


def timed_draw(state: AppState, panel: RasterPanel, method: str, fbo=None) -> None:
    """Draw ``panel`` at ``state.camera`` into ``fbo`` (by default its framebuffer of the
    camera's size, redrawing the image it holds: the same image) and wait for the draw to end:
    ``state.timings[method]`` is the draw's time, not just its submission."""
    cam = state.camera
    if fbo is None:
        fbo = panel.session.framebuffer(cam.width, cam.height)
    t0 = time.perf_counter()
    panel.session.draw_to(fbo, cam, *shared_near_far(gpu(state), panel.session, cam))
    state.ctx.finish()
    state.ctx.screen.use()  # back to the window's framebuffer for imgui
    state.timings[method] = time.perf_counter() - t0
    panel.timed = True


def shared_near_far(g: PanelGPU, session, cam) -> tuple[float, float]:
    """The automatic clip planes of ``session`` for ``cam``, computed once per camera for
    sessions with the same parts' boxes (the GL panels of one scene and tessellation share
    them: 3-10 ms of Python each on a loaded machine, every frame of a drag)."""
    key = session.part_boxes.tobytes()
    if g.near_far.get("camera") != cam:
        g.near_far = {"camera": cam}
    if key not in g.near_far:
        g.near_far[key] = session.near_far(cam)
    return g.near_far[key]


def read_pixel(fbo, i: int, j: int, shape: tuple[int, int]) -> np.ndarray | None:
    """Pixel (row ``i`` from the top, column ``j``) of a raster panel's framebuffer as (3,)
    float32, or None unless the framebuffer is ``shape`` (H, W): the probe's read of one
    pixel instead of the whole image."""
    if tuple(shape) != (fbo.height, fbo.width):
        return None
    raw = fbo.read(viewport=(j, fbo.height - 1 - i, 1, 1), components=3, dtype="f4")
    return np.frombuffer(raw, np.float32).copy()


def refresh_cpu(state: AppState, method: str) -> None:
    """Ask for ``method``'s background job; take its image when it has new tiles."""
    job = state.jobs.request(state.scene, state.camera, method, state.options[method],
                             tiled=tiled(method))
    if job.cancelled.is_set():
        state.status[method] = "restarting (stale image)"
    elif job.error:
        state.status[method] = job.error
    elif job.done:
        state.timings[method] = job.seconds
        state.status[method] = (f"done: {job.spp} spp, noise {job.noise:.3g}"
                                if job.progressive and job.noise is not None else "done")
    elif job.progressive:
        from ...renderers.base import get_renderer
        target = state.options[method][get_renderer(method).knob.name]
        state.status[method] = (f"refining: {job.spp}/{target} spp" +
                                ("" if job.noise is None else f", noise {job.noise:.3g}"))
    else:
        state.status[method] = (f"rendering: {job.rows_done}/{state.camera.height} rows"
                                if tiled(method) else "rendering...")
    shape = (state.camera.height, state.camera.width, 3)
    if stale(state, f"{method} job", (id(job), job.version, shape)) or method not in state.images:
        image = job.snapshot()
        # the previous job's image is kept while its successor waits, unless it has another
        # size (a scene switch changed the panels' aspect): then black until the new one comes
        state.images[method] = (over_stale(state, method, job, image)
                                if image.shape == shape else np.zeros(shape, np.float32))


def over_stale(state: AppState, method: str, job, image: np.ndarray) -> np.ndarray:
    """What a CPU panel shows of ``job``'s ``image`` (H, W, 3): the image once done; before,
    its rendered bands (rows ``0 .. job.rows_done``; a progressive job's image once it has a
    sample) over the panel's previous image (its *backdrop*, taken when the job first shows),
    so a restarted render never blanks the panel (it used to show black until its bands came)."""
    g = gpu(state)
    held = g.backdrops.get(method)
    if held is None or held[0] != id(job):
        prev = state.images[method] if method in state.images else None
        held = g.backdrops[method] = (id(job), prev)
    back = held[1]
    if job.done or back is None or back.shape != image.shape:
        return image
    if job.progressive:
        return image if job.spp > 0 else back
    out = back.copy()
    out[:job.rows_done] = image[:job.rows_done]
    return out


def update_images(state: AppState) -> None:
    """Bring every selected panel up to date (called once per frame, before the widgets)."""
    from .pyrender_proc import refresh_pyrender
    if state.gpu is not None:
        take_gpu_stats(state, "difference")
    state.jobs.keep_only(state.methods)
    if state.gpu is not None:  # a removed panel's approximation keeps nothing awake
        state.gpu.modes.approximate &= set(state.methods)
    for m in state.methods:
        kind = method_kind(state, m)
        if kind == "gl":
            refresh_raster(state, m)
        elif kind == "child":
            refresh_pyrender(state)
        else:
            refresh_cpu(state, m)


def in_progress(state: AppState) -> bool:
    """Something on screen changes by itself this frame: a background job or the pyrender child
    is working, the error plot waits for its reference or evaluations, or a GL panel has edited
    values still to compile back in.  The loop then runs at full rate (capped while a job runs,
    :func:`.main.frame_rest`); otherwise it idles."""
    proc = state.pyrender
    g = state.gpu
    return (state.jobs.busy() or (proc is not None and proc.busy) or state.errors.busy(state.frame)
            or (g is not None and (any(p.session.live or not p.timed for p in g.raster.values())
                                   or g.modes.busy()
                                   or any(g.stats.get(k, (None,))[0] != v[0]
                                          for k, v in g.gpu_stats.items()))))


def panel_texture(state: AppState, method: str):
    """The RGBA8 texture showing ``method``'s panel through its display mode; rebuilt only
    when the image or the mode changed (another mode than direct24:
    :meth:`.display_modes.ModeDisplay.step`, cheap while the image changes)."""
    mode = state.display.get(method, "direct24")
    if mode != "direct24":
        g = gpu(state)
        g.shown.pop(method, None)
        todo = g.modes.step(method, state.images.version(method), mode,
                            lambda: state.images[method], method in state.textures)
        if todo is not None and todo[0] == "pass":
            source, flip = linear_source(state, method)
            g.modes.run(source, flip, display_texture(state, method, source.size), *todo[1:])
        elif todo is not None:
            upload_linear(state, method, todo[1])
        return state.textures[method]
    gpu(state).modes.forget(method)
    key = (state.images.version(method), mode)
    if stale(state, method, key) or method not in state.textures:
        source, flip = linear_source(state, method)
        gpu(state).passes.encode(source, display_texture(state, method, source.size), flip)
    return state.textures[method]


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


def image_stats(state: AppState, name: str) -> tuple[float, float]:
    """(maximum, mean) of ``state.images[name]``, computed once per change of the image.

    An image whose statistics were reduced on the GPU this frame (the difference view during
    a drag) gives the previous image's until the next frame (:func:`take_gpu_stats`): reading
    them now would wait for everything the frame has drawn so far."""
    g = gpu(state)
    key = state.images.version(name)
    queued = g.gpu_stats.get(name)
    if queued is not None and queued[0] == key:
        take_gpu_stats(state, name, now=name not in g.stats)
        held = g.stats[name]
        return held[1], held[2]
    held = g.stats.get(name)
    if held is None or held[0] != key:
        image = state.images[name]
        held = g.stats[name] = (key, float(image.max()), float(image.mean()))
    return held[1], held[2]


def difference_on_gpu(state: AppState, a: str, b: str, table: np.ndarray) -> bool:
    """The ``"abs"`` error map of panels ``a`` and ``b`` computed on the GPU from their
    linear copies, to be shown through ``table`` ((n, 3) uint8 colour scale from 0 to the
    map's maximum, uploaded once per window: :func:`show_difference`), with nothing read back:
    the maximum is reduced on the GPU (:meth:`DisplayPasses.statistics`, with the sum for the
    mean: :func:`image_stats`) and the (H, W) float32 map becomes ``state.images["difference"]``
    as a pending read (the probe reads one pixel of it, the export all).  Returns False when
    the two images differ in size (the caller's CPU path then reports it)."""
    g = gpu(state)
    (ta, fa), (tb, fb) = linear_source(state, a), linear_source(state, b)
    if ta.size != tb.size:
        return False
    held = g.uploads.get("difference values")
    if held is not None and held.size != ta.size and "difference" in state.images:
        state.images["difference"]  # a pending map of the old size: read before its texture goes
    values = _float_texture(state, "difference values", ta.size, 1)
    g.passes.difference((ta, fa), (tb, fb), values)
    stats = g.passes.statistics(values)
    if "colour table" not in g.uploads:
        g.uploads["colour table"] = state.ctx.texture((len(table), 1), 3,
                                                      np.ascontiguousarray(table, np.uint8).tobytes(),
                                                      alignment=1)
    w, h = ta.size
    state.images.set_pending("difference", lambda: read_values(values),
                             pixel=lambda i, j, shape: read_value(values, i, j, shape),
                             shape=(h, w))
    version = state.images.version("difference")
    g.gpu_stats["difference"] = (version, stats, state.frame, w * h)
    g.difference_inputs = (version, values, g.uploads["colour table"], stats)
    return True


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


def changing(state: AppState, name: str) -> bool:
    """``state.images[name]`` is not the image shown last frame (a drag redraws it every
    frame); records the version shown."""
    g = gpu(state)
    version = state.images.version(name)
    changed = g.shown_versions.get(name) != version
    g.shown_versions[name] = version
    return changed


def show_panel(state: AppState, method: str, size, uv0=(0.0, 0.0), uv1=(1.0, 1.0)) -> None:
    """``imgui.image`` of ``method``'s panel, drawn into the window by a GPU pass instead
    (:class:`ScreenBlits`; :func:`draw_shown_images` draws once the gui is done).  A direct24
    panel whose image changed since last frame is sRGB-encoded straight into the window from
    its linear image (no display texture made: one pass where encoding into the texture and
    copying it were two); an image that stays is encoded once into its display texture
    (:func:`panel_texture`), which is then copied (cheaper than encoding every frame), as is
    the display texture of any other mode."""
    g = gpu(state)
    mode = state.display.get(method, "direct24")
    image = None
    if changing(state, method):
        source, flip = linear_source(state, method)
        if mode == "direct24":
            g.modes.forget(method)
            image = g.blits.linear(source, flip)
        else:
            todo = g.modes.step(method, state.images.version(method), mode,
                                lambda: state.images[method], method in state.textures)
            if todo is not None and todo[0] == "pass":
                # the mode's GPU view drawn into the window; its display texture is made once
                # the image stays (the next frame that shows the same image)
                g.modes.shown.pop(method, None)
                image = g.blits.drawn(lambda src, dst: g.modes.to_window(source, flip, *todo[1:], src, dst),
                                      source.size)
            elif todo is not None:
                upload_linear(state, method, todo[1])
    if image is None:
        image = g.blits.copied(panel_texture(state, method))
    g.blits.show(method, image, size, uv0, uv1)


def show_difference(state: AppState, size, uv0=(0.0, 0.0), uv1=(1.0, 1.0)) -> None:
    """``imgui.image`` of the difference view, drawn as :func:`show_panel` draws panels: the
    ``"abs"`` map computed on the GPU colour-mapped straight into the window while it changes
    every frame, else (and for a map computed on the CPU: FLIP) its display texture copied."""
    g = gpu(state)
    held = g.difference_inputs
    if (changing(state, "difference") and held is not None
            and held[0] == state.images.version("difference")):
        values, table, stats = held[1:]
        inputs = {"u_value": values, "u_table": table, "u_stats": stats}
        image = g.blits.drawn(lambda src, dst: g.passes.to_window(
            "colour_map", inputs, src, dst, u_floor=SCALE_FLOOR), values.size)
    else:
        image = g.blits.copied(shown_texture(state, "difference"))
    g.blits.show("difference", image, size, uv0, uv1)


def shown_texture(state: AppState, name: str):
    """The display texture (RGBA8 or RGB8, row 0 on top) of what panel or view ``name``
    (``"difference"``) shows, made if the window draws it without one (scripts and tests
    read it; the window itself does not need it)."""
    g = gpu(state)
    held = g.difference_inputs
    if name != "difference":
        return panel_texture(state, name)
    if held is not None and held[0] == state.images.version("difference"):
        values, table, stats = held[1:]
        if stale(state, "difference texture", held[0]) or "difference" not in state.textures:
            g.passes.colour_map(values, table, stats,
                                display_texture(state, "difference", values.size))
    return state.textures["difference"]


def draw_shown_images(state: AppState) -> None:
    """Draw this frame's panel images into the window (call before imgui renders)."""
    if state.gpu is not None:
        state.gpu.blits.flush()


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
