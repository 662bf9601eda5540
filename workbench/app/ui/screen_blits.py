"""Big images (the panels, the difference view) put straight into the window's framebuffer.

The display passes (:mod:`.display_passes`) draw into the window's framebuffer under imgui's
drawing (:class:`ScreenBlits`), not drawn by imgui as quads: straight from the linear image
while it changes, from an RGBA8 display texture made once when it stays.  During a drag a
direct24 panel is sRGB-encoded by the window's framebuffer where it is sRGB-capable
(``GL_FRAMEBUFFER_SRGB``, ARB_framebuffer_sRGB), within one level of the IEC 61966-2-1
numbers of :func:`workbench.core.imageio.to_srgb8`.
"""
from __future__ import annotations

from .display_passes import DisplayPasses

GL_FRAMEBUFFER_SRGB = 0x8DB9


class ScreenBlits:
    """Big images (the panels, the difference view) put straight into the window's
    framebuffer under imgui's drawing, scaled to their item's rectangle as a nearest blit:

    * while an image changes (a drag), drawn by the display pass that makes it
      (:meth:`.display_passes.DisplayPasses.to_window`: a linear image sRGB-encoded, by the window's own
      framebuffer where it is sRGB-capable (:meth:`linear`), a display mode's GPU view, the
      difference's colour map): one pass where encoding into an RGBA8 display texture and
      blitting that were two;
    * an image that stays is encoded once into its display texture, which is then copied by
      ``glBlitFramebuffer`` each frame (3 panels: 8.5 ms of CPU against 10.2 for a copying
      pass, ``display_copy.frag``, used where the window's GLFW gives no
      ``glBlitFramebuffer``; ``bench/ui_frame_gpu.py``'s context at a load of 10).

    Not imgui's textured, blended quads: on llvmpipe a shaded and blended fragment per pixel
    (4 panels: ~5.5 ms against ~0.4 ms for blits, measured in a standalone context).
    Scripts and tests read display textures through :func:`.panel_show.shown_texture`.

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
        into the bound window framebuffer as :meth:`.display_passes.DisplayPasses.to_window`
        takes them."""
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
