"""The window passes' geometry: a display pass (``shaders/display_*.frag`` built with
``TO_WINDOW``) drawn as a quad over the image's rectangle of the window (the viewport),
reading the texel window it shows from its corners (``shaders/display_window.vert``,
``shaders/include/display_texel.glsl``).

A quad over the rectangle, not a full-window triangle cut by the scissor: llvmpipe bins a
triangle over every tile of the window it covers and shades per fragment an address computed
from ``gl_FragCoord``; the quad covers only the rectangle's tiles and interpolates the address.
"""
from __future__ import annotations


def program(ctx, fragment: str, defines: dict | None = None):
    """The window variant of display pass ``fragment`` (a file name under ``shaders/``) and
    its vertex array (no buffers): ``(program, vao)``."""
    from ...renderers.raster_shaders import SHADER_DIR, build_source
    prog = ctx.program(vertex_shader=(SHADER_DIR / "display_window.vert").read_text(encoding="utf-8"),
                       fragment_shader=build_source(fragment, {**(defines or {}), "TO_WINDOW": ""}))
    return prog, ctx.vertex_array(prog, [])


def draw(ctx, prog, vao, src: tuple, dst: tuple) -> None:
    """Draw ``prog`` (uniforms and textures already set) into the bound window framebuffer:
    the texel window ``src`` = (left, top, right, bottom) edges of the image (texel units, rows
    from the image's top row) into ``dst`` = (x0, y_top, x1, y_bottom) (framebuffer pixels,
    y up, so y_top > y_bottom), as ``glBlitFramebuffer(src, dst, NEAREST)`` maps them.  The
    scissor, if set, still clips.  Leaves the viewport on ``dst``."""
    import moderngl
    (s0, t0, s1, t1), (x0, y_top, x1, y_bottom) = src, dst
    ctx.viewport = (int(x0), int(y_bottom), int(x1 - x0), int(y_top - y_bottom))
    prog["u_src"].value = (float(s0), float(t1), float(s1), float(t0))
    vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
