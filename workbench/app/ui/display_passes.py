"""The GPU passes between the panels' linear images and the screen.

Every panel's linear image has a GPU copy (:func:`.panel_gpu.linear_source`: a raster panel's
framebuffer, else a float texture uploaded once per change of the image) and reaches the
screen through the passes of :class:`DisplayPasses` (``shaders/display*``): sRGB encoding
(IEC 61966-2-1, the numbers of :func:`workbench.core.imageio.to_srgb8`), and the difference
view's ``"abs"`` map, its maximum and mean reduced on the GPU, and colour scale.  What they
make reaches the window through :class:`.screen_blits.ScreenBlits`.
"""
from __future__ import annotations

import numpy as np

from . import window_quad

SCALE_FLOOR = 1e-6
"""The difference view's colour scale runs from 0 to the map's maximum, or to this if the
maximum is smaller (two equal images show the scale's first colour)."""
STATS_BLOCK = 8
"""Texels along each side of the blocks one step of :meth:`DisplayPasses.statistics` reduces."""


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
        the window's own sRGB encoding around it (:attr:`.screen_blits.ScreenBlits.srgb`)."""
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
