"""A panel shown through a display mode (:mod:`workbench.core.display`) without slowing a drag.

The exact modes cost the CPU 0.1 to 3 s for a 512 px image (a CLUT built by median cut or
k-means, Floyd-Steinberg's error diffusion, Knoll's pattern dithering), far too much for a
frame.  So a panel's display texture comes from one of three places:

* **on the GPU, exact**: direct modes without error diffusion (``direct16-555``,
  ``direct16-565``, their ``-bayer`` variants): the pass ``shaders/display_mode.frag`` rounds
  each channel of the 24-bit frame buffer to the mode's levels (Bayer's threshold added first),
  the numbers of ``core.display._show``;
* **on the GPU, approximate, while the image changes** (a camera drag, a slider, a job's new
  bands: the image changed less than :data:`DISPLAY_REST_SECONDS` ago): an indexed mode maps
  each pixel to the nearest entry of a fixed CLUT through a 3D table (:func:`clut_table`, cells
  of 2^:data:`LUT_SHIFT` levels per channel), the CLUT of the panel's last exact image (else one
  built from a subsample of the current image, :func:`drag_palette`), without dithering; a
  ``-fs`` direct mode is shown without its error diffusion;
* **on the CPU, exact, once the image rests**: ``core.display.apply_display_mode`` in a worker
  thread (the window keeps drawing the approximation meanwhile and wakes when the result comes);
  its result replaces the approximation if the image and the mode are still the same.

So a drag shows the mode's palette (the look of an indexed display) at the frame rate of
``direct24``, and the image at rest is exactly the CLI's (``workbench render --display``).
"""
from __future__ import annotations

import threading
import time

import numpy as np

from . import window_quad

DISPLAY_REST_SECONDS = 0.25
"""How long a panel's image must stay unchanged before its exact display mode is computed."""
LUT_SHIFT = 3
"""Cells of the indexed modes' GPU table: 2^LUT_SHIFT 8-bit levels per channel (a 32^3 table:
about 45 ms to build for a 256-entry CLUT)."""
DRAG_SAMPLES = 16384
"""Pixels (a regular subsample) from which a CLUT is built when a drag starts before any exact
image of the mode exists."""


def gpu_exact(mode) -> bool:
    """The mode (a :class:`~workbench.core.display.DisplayMode`) is computed exactly by the GPU
    pass: a direct mode without error diffusion."""
    return mode.kind == "direct" and mode.dither != "floyd_steinberg"


def encoded8(image: np.ndarray) -> np.ndarray:
    """(..., 3) linear -> the 24-bit frame buffer's levels / 255 (float64 in [0, 1])."""
    from ...core.imageio import srgb_encode
    return np.round(srgb_encode(np.asarray(image, np.float64)) * 255.0) / 255.0


def clut_table(palette: np.ndarray, shift: int = LUT_SHIFT) -> np.ndarray:
    """(n, n, n, 3) uint8 table, n = 256 >> shift, indexed [blue, green, red] cell (the layout
    of a 3D texture with red along x): the CLUT entry nearest (Euclidean, encoded RGB, as
    :func:`workbench.core.display.nearest`) to the centre of each cell of 2^shift levels.

    ``palette``: (K, 3) encoded colours in [0, 1]."""
    from ...core.display import nearest
    n, step = 256 >> shift, 1 << shift
    c = (np.arange(n) * step + (step - 1) / 2.0) / 255.0
    b, g, r = np.meshgrid(c, c, c, indexing="ij")
    centres = np.stack([r, g, b], -1).reshape(-1, 3)
    pal = np.asarray(palette, np.float64)
    table = pal[nearest(centres, pal)]
    return np.round(table * 255.0).astype(np.uint8).reshape(n, n, n, 3)


def drag_palette(image: np.ndarray, mode) -> np.ndarray:
    """(K, 3) encoded CLUT of an indexed ``mode`` built from at most :data:`DRAG_SAMPLES`
    pixels of ``image`` (a regular subsample), by the mode's palette method."""
    from ...core.display import build_palette
    flat = np.asarray(image).reshape(-1, 3)
    step = max(1, len(flat) // DRAG_SAMPLES)
    return build_palette(encoded8(flat[::step]), mode.entries, mode.palette)


def shown_palette(shown: np.ndarray) -> np.ndarray:
    """(K, 3) encoded colours an exactly displayed image uses (its CLUT's entries in use)."""
    return np.unique(encoded8(shown.reshape(-1, 3)), axis=0)


class ModeDisplay:
    """The display-mode pass and each panel's state (made in the window's GL context).

    ``changed[panel]``: (image version, when it was first seen); ``tables[(panel, mode)]``:
    the panel's CLUT table texture; ``exact[panel]``: (version, mode, linear image shown
    exactly) from the worker; ``workers[panel]``: (version, mode, thread) of the exact
    computation running; ``shown[panel]``: (version, mode, "gpu" | "fast" | "exact") of what
    its texture holds; ``approximate``: panels showing an approximation now (the window stays
    awake until they are exact: :meth:`busy`); ``notify`` wakes the window."""

    def __init__(self, ctx, notify=None):
        from ...renderers.raster_shaders import SHADER_DIR, build_source
        self.ctx, self.notify = ctx, notify
        self.progs = {"texture": ctx.program(
            vertex_shader=(SHADER_DIR / "display.vert").read_text(encoding="utf-8"),
            fragment_shader=build_source("display_mode.frag", {}))}
        self.vaos = {"texture": ctx.vertex_array(self.progs["texture"], [])}
        self.progs["window"], self.vaos["window"] = window_quad.program(ctx, "display_mode.frag")
        for prog in self.progs.values():
            prog["u_linear"].value, prog["u_lut"].value = 0, 1
        self.changed: dict[str, tuple] = {}
        self.tables: dict[tuple, object] = {}
        self.exact: dict[str, tuple] = {}
        self.workers: dict[str, tuple] = {}
        self.approximate: set[str] = set()
        self.shown: dict[str, tuple] = {}
        self.lock = threading.Lock()
        self.dummy_table = None
        self.started = 0
        """Exact computations started so far (tests: none during a drag)."""

    def run(self, source, flip: bool, target, mode, table=None) -> None:
        """Fill ``target`` (RGBA8) with ``source`` (linear float texture) through ``mode``:
        its levels (direct; Bayer for ``-bayer``) or the CLUT ``table`` (3D texture)."""
        from ...renderers import gl
        fbo = self.ctx.framebuffer(color_attachments=[target])
        fbo.use()
        self._draw("texture", source, flip, mode, table)
        gl.release_framebuffer(fbo)
        if self.ctx.screen is not None:  # back to the window's framebuffer for imgui
            self.ctx.screen.use()

    def to_window(self, source, flip: bool, mode, table, src: tuple, dst: tuple) -> None:
        """Draw ``source`` through ``mode`` as :meth:`run` does, straight into the bound
        window framebuffer: its texel window ``src`` into the window rectangle ``dst``
        (:func:`.window_quad.draw`), within the scissor."""
        self._draw("window", source, flip, mode, table, src, dst)

    def _draw(self, where: str, source, flip: bool, mode, table, src=None, dst=None) -> None:
        import moderngl
        if table is None:
            if self.dummy_table is None:
                self.dummy_table = self.ctx.texture3d((1, 1, 1), 3, bytes(3))
            table = self.dummy_table
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        source.use(0)
        table.use(1)
        p = self.progs[where]
        p["u_flip"].value = int(flip)
        p["u_indexed"].value = int(mode.kind == "indexed")
        p["u_shift"].value = LUT_SHIFT
        p["u_bayer"].value = int(mode.kind == "direct" and mode.dither == "ordered")
        p["u_levels"].value = tuple(float(2 ** b - 1) for b in mode.bits)
        if where == "window":
            window_quad.draw(self.ctx, p, self.vaos[where], src, dst)
        else:
            self.vaos[where].render(moderngl.TRIANGLES, vertices=3)

    def table(self, key: tuple, palette: np.ndarray):
        """The 3D texture of ``palette``'s :func:`clut_table`, kept under ``key``."""
        import moderngl
        old = self.tables.pop(key, None)
        if old is not None:
            old.release()
        data = clut_table(palette)
        n = data.shape[0]
        tex = self.ctx.texture3d((n, n, n), 3, np.ascontiguousarray(data).tobytes(), alignment=1)
        tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.tables[key] = tex
        return tex

    def start_exact(self, panel: str, version: int, mode: str, image: np.ndarray) -> None:
        """Compute ``image`` through ``mode`` exactly in a worker thread (one per panel at a
        time; a request for another version waits for the running one to end)."""
        running = self.workers.get(panel)
        if running is not None:
            if running[2].is_alive() or running[:2] == (version, mode):
                return
        self.started += 1
        thread = threading.Thread(target=self._exact, args=(panel, version, mode, image),
                                  name=f"ui-display-{panel}", daemon=False)
        self.workers[panel] = (version, mode, thread)
        thread.start()

    def _exact(self, panel: str, version: int, mode: str, image: np.ndarray) -> None:
        from ...core.display import apply_display_mode
        shown = apply_display_mode(image, mode)
        with self.lock:
            self.exact[panel] = (version, mode, shown)
        if self.notify is not None:
            self.notify()

    def forget(self, panel: str) -> None:
        """The panel is shown in direct24 again: what it showed through a mode is void."""
        self.approximate.discard(panel)
        self.shown.pop(panel, None)

    def busy(self) -> bool:
        """A panel shows an approximation or an exact computation runs."""
        return bool(self.approximate) or any(t.is_alive() for _, _, t in self.workers.values())

    def step(self, panel: str, version: int, mode_name: str, image, has_texture: bool,
             now: float | None = None):
        """What ``panel``'s display texture must become this frame for image ``version``
        through ``mode_name`` (not ``direct24``); ``image()`` gives the linear image (a GPU
        read-back for a GL panel: called only when a CLUT or the exact mode needs it), and
        ``has_texture`` says whether the texture exists.  Returns None (keep it), ``("pass",
        mode, table)`` (run :meth:`run` with that CLUT table or None) or ``("upload",
        linear)`` (the exact image: show it as is).  See the module docstring."""
        from ...core.display import display_mode
        now = time.perf_counter() if now is None else now
        mode = display_mode(mode_name)
        seen = self.changed.get(panel)
        if seen is None or seen[0] != version:
            seen = self.changed[panel] = (version, now)

        def wanted(kind):
            return self.shown.get(panel) != (version, mode_name, kind) or not has_texture

        if gpu_exact(mode):
            self.approximate.discard(panel)
            if wanted("gpu"):
                self.shown[panel] = (version, mode_name, "gpu")
                return ("pass", mode, None)
            return None
        with self.lock:
            exact = self.exact.get(panel)
        if exact is not None and exact[:2] == (version, mode_name):
            self.approximate.discard(panel)
            if wanted("exact"):
                self.shown[panel] = (version, mode_name, "exact")
                if mode.kind == "indexed":  # the next drag maps to this image's CLUT
                    self.table((panel, mode_name), shown_palette(exact[2]))
                return ("upload", exact[2])
            return None
        if now - seen[1] >= DISPLAY_REST_SECONDS:
            self.start_exact(panel, version, mode_name, image())
        self.approximate.add(panel)
        if not wanted("fast"):
            return None
        self.shown[panel] = (version, mode_name, "fast")
        table = None
        if mode.kind == "indexed":
            table = self.tables.get((panel, mode_name))
            if table is None:
                table = self.table((panel, mode_name), drag_palette(image(), mode))
        return ("pass", mode, table)

    def release(self) -> None:
        """Join the workers, free the GL objects."""
        for _, _, t in self.workers.values():
            t.join()
        self.workers.clear()
        for tex in self.tables.values():
            tex.release()
        self.tables.clear()
        for obj in (self.dummy_table, *self.vaos.values(), *self.progs.values()):
            if obj is not None:
                obj.release()
