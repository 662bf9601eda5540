"""The window passes draw an image's texel window into its rectangle of the window as a
nearest ``glBlitFramebuffer`` would (``workbench.app.ui.window_quad``): the same texel at every
pixel, whatever the scale (up, down, a texel window cut mid-image, a rectangle off the
window's corner), in a headless context with a framebuffer in the window's role."""
from __future__ import annotations

import ctypes

import numpy as np
import pytest

pytestmark = pytest.mark.gl

W, H = 160, 120
CASES = [((0, 0, 37, 23), (5, 100, 117, 31)),    # magnified, uneven ratios
         ((0, 0, 37, 23), (10, 30, 30, 18)),     # minified
         ((7, 3, 29, 20), (0, 119, 160, 0)),     # a texel window inside the image, whole target
         ((0, 0, 37, 23), (-20, 140, 90, 60)),   # partly outside the target
         ((11, 5, 12, 6), (40, 80, 73, 47))]     # one texel, 33 x 33 pixels


def _blit():
    egl = ctypes.CDLL("libEGL.so.1")
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    u, i = ctypes.c_uint, ctypes.c_int
    bind = ctypes.CFUNCTYPE(None, u, u)(egl.eglGetProcAddress(b"glBindFramebuffer"))
    blit = ctypes.CFUNCTYPE(None, i, i, i, i, i, i, i, i, u, u)(egl.eglGetProcAddress(b"glBlitFramebuffer"))
    return bind, blit


@pytest.mark.parametrize("src, dst", CASES)
def test_a_window_pass_shows_what_a_nearest_blit_shows(gl_ctx, src, dst):
    from workbench.app.ui import window_quad
    from workbench.renderers import gl
    ctx = gl_ctx
    rng = np.random.default_rng(5)
    image = rng.integers(0, 256, (23, 37, 4), dtype=np.uint8)  # row 0 on top, as display textures
    image[..., 3] = 255
    texture = ctx.texture((37, 23), 4, image.tobytes())
    prog, vao = window_quad.program(ctx, "display_copy.frag")
    prog["u_image"].value = 0
    drawn, blitted = (ctx.framebuffer([ctx.texture((W, H), 4)]) for _ in range(2))
    source = ctx.framebuffer([texture])
    try:
        drawn.use()
        drawn.clear(0.0, 0.0, 0.0, 0.0)
        texture.use(0)
        window_quad.draw(ctx, prog, vao, src, dst)
        blitted.use()
        blitted.clear(0.0, 0.0, 0.0, 0.0)
        bind, blit = _blit()
        bind(0x8CA8, source.glo)  # GL_READ_FRAMEBUFFER
        bind(0x8CA9, blitted.glo)  # GL_DRAW_FRAMEBUFFER
        blit(*src, *dst, 0x4000, 0x2600)  # GL_COLOR_BUFFER_BIT, GL_NEAREST
        bind(0x8D40, blitted.glo)  # as moderngl believes
        got = np.frombuffer(drawn.read(components=4), np.uint8).reshape(H, W, 4)
        want = np.frombuffer(blitted.read(components=4), np.uint8).reshape(H, W, 4)
        assert want[..., 3].sum() > 0  # the blit drew
        assert np.array_equal(got, want)
    finally:
        for obj in (drawn, blitted, source):
            gl.release_framebuffer(obj)
        texture.release()
        vao.release()
        prog.release()


def test_the_linear_pass_into_an_srgb_framebuffer_shows_the_srgb_levels(gl_ctx):
    """During a drag a direct24 panel is drawn linear into the window and encoded by the
    window's sRGB framebuffer (``display_linear.frag``, ``ScreenBlits.linear``): every level
    within one of ``to_srgb8``'s (the rasteriser's encoding rounds some ties the other way),
    row 0 of a framebuffer image on top."""
    from workbench.app.ui import window_quad
    from workbench.app.ui.screen_blits import GL_FRAMEBUFFER_SRGB
    from workbench.core.imageio import to_srgb8
    from workbench.renderers import gl
    ctx = gl_ctx
    rng = np.random.default_rng(7)
    image = (rng.random((48, 64, 3)) ** 2).astype(np.float32)  # row 0 on top
    image[0, :3] = [np.nan, -1.0, 2.0]  # NaN -> 0 and clipping, as to_srgb8
    source = ctx.texture((64, 48), 3, np.ascontiguousarray(image[::-1]).tobytes(), dtype="f4")  # a framebuffer's order
    target = ctx.texture((64, 48), 4, internal_format=0x8C43)  # GL_SRGB8_ALPHA8, as the window's
    fbo = ctx.framebuffer([target])
    prog, vao = window_quad.program(ctx, "display_linear.frag")
    prog["u_linear"].value, prog["u_flip"].value = 0, 1
    try:
        fbo.use()
        source.use(0)
        ctx.enable_direct(GL_FRAMEBUFFER_SRGB)
        window_quad.draw(ctx, prog, vao, (0, 0, 64, 48), (0, 48, 64, 0))
        ctx.disable_direct(GL_FRAMEBUFFER_SRGB)
        shown = np.frombuffer(fbo.read(components=3), np.uint8).reshape(48, 64, 3)[::-1]
        want = to_srgb8(np.nan_to_num(image, nan=0.0)).astype(int)
        diff = np.abs(shown.astype(int) - want)
        assert diff.max() <= 1
        assert (diff == 0).mean() > 0.8
    finally:
        gl.release_framebuffer(fbo)
        for obj in (source, target, vao, prog):
            obj.release()
