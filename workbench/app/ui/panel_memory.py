"""What each panel holds in memory, and the hidden panels' share of it bounded (issue #29,
item 3: the window's resident size must not grow with the length of a session).

A panel unticked in the Methods window keeps, for a quick return, what it showed: its image
(and the backdrop of its CPU job), its GL session (buffers, programs, framebuffers, the
stand-ins' maps), its textures, its display mode's state, and for pyrender the child process.
Only the :data:`HIDDEN_PANELS_KEPT` panels hidden last keep them, within the window's cache
budget (:class:`.bounded.LruCache`, ``state.hidden_panels``); an older one's are freed
(:func:`forget_panel`): ticked again, it is built and rendered anew.  :func:`window_bytes`
sums what the window holds, by kind, for the scripted sessions' logs.
"""
from __future__ import annotations

from pathlib import Path

from .bounded import LruCache
from .state import AppState

HIDDEN_PANELS_KEPT = 2
"""Hidden panels whose resources are kept (the ones hidden last)."""


def process_rss(pid: int) -> int:
    """Resident bytes of process ``pid`` (``VmRSS`` of /proc/PID/status; 0 if unknown)."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def panel_bytes(state: AppState, method: str) -> int:
    """Bytes ``method``'s panel holds: its images on the CPU (the image, its job's backdrop,
    its exact display mode), its textures and GL session (:func:`workbench.renderers.gl.object_bytes`),
    and the pyrender child's resident size."""
    from ...renderers import gl
    from .pyrender_proc import METHOD as PYRENDER
    total = state.images.nbytes(method)
    total += gl.object_bytes(state.textures.get(method))
    g = state.gpu
    if g is not None:
        total += gl.object_bytes(g.uploads.get(method))
        panel = g.raster.get(method)
        if panel is not None:
            total += panel.session.gl_bytes()
        back = g.backdrops.get(method, (None, None))[1]
        total += 0 if back is None else back.nbytes
        exact = g.modes.exact.get(method)
        total += 0 if exact is None else exact[2].nbytes
        total += sum(gl.object_bytes(t) for (m, _), t in g.modes.tables.items() if m == method)
    if method == PYRENDER and state.pyrender is not None:
        total += process_rss(state.pyrender.process.pid)
    return total


def forget_panel(state: AppState, method: str) -> None:
    """Free everything ``method``'s (hidden) panel holds (see :func:`panel_bytes`); shown
    again, it starts from nothing."""
    from .pyrender_proc import METHOD as PYRENDER
    if method in state.images:  # before its session goes: a pending read of its framebuffer
        del state.images[method]
    tex = state.textures.pop(method, None)
    if tex is not None:
        tex.release()
    g = state.gpu
    if g is not None:
        panel = g.raster.pop(method, None)
        if panel is not None:
            g.compiled += panel.session.programs.compiles
            panel.session.release()
        tex = g.uploads.pop(method, None)
        if tex is not None:
            tex.release()
        for held in (g.linear, g.backdrops, g.stats, g.shown, g.shown_versions):
            held.pop(method, None)
        g.shown.pop(f"{method} job", None)
        g.modes.forget(method)
        g.modes.exact.pop(method, None)
        g.modes.changed.pop(method, None)
        for key in [k for k in g.modes.tables if k[0] == method]:
            g.modes.tables.pop(key).release()
    state.image_requests.pop(method, None)
    state.progress.pop(method, None)
    if method == PYRENDER and state.pyrender is not None:
        state.pyrender.close()
        state.pyrender = None


def keep_hidden(state: AppState) -> None:
    """Per frame: a panel hidden since the last frame joins ``state.hidden_panels`` (with the
    bytes it holds), a shown one leaves it; beyond :data:`HIDDEN_PANELS_KEPT` or the cache
    budget, the panel hidden longest ago is forgotten (:func:`forget_panel`)."""
    if state.hidden_panels is None:
        state.hidden_panels = LruCache(HIDDEN_PANELS_KEPT, size_of=int,
                                       on_evict=lambda m, _: forget_panel(state, m))
    hidden = state.hidden_panels
    shown = set(state.methods)
    for m in shown & set(hidden):
        hidden.pop(m)
    holding = set(state.images) | set(state.textures)
    if state.gpu is not None:
        holding |= set(state.gpu.raster)
    if state.pyrender is not None:
        holding.add("pyrender")
    for m in sorted((holding & set(state.options)) - shown - set(hidden)):
        hidden.put(m, panel_bytes(state, m))


def window_bytes(state: AppState) -> dict[str, int]:
    """Bytes the window holds, by kind: ``images`` (the panels' and the difference's on the
    CPU), ``jobs`` (the panels' current jobs' images), ``plot`` (the error plot's references
    and its boards' jobs), ``gl`` (textures and the raster sessions), ``hidden`` (the hidden
    panels kept, :func:`keep_hidden`: a part of the others), and ``total``."""
    from ...renderers import gl
    plot = state.errors
    out = {"images": state.images.nbytes(), "jobs": state.jobs.nbytes(),
           "plot": sum(b.nbytes() for b in plot.boards()) + (0 if plot.ref_image is None
                                                             else plot.ref_image.nbytes),
           "gl": sum(gl.object_bytes(t) for t in state.textures.values())}
    g = state.gpu
    if g is not None:
        out["gl"] += sum(gl.object_bytes(t) for t in g.uploads.values())
        out["gl"] += sum(p.session.gl_bytes() for p in g.raster.values())
    out["total"] = sum(out.values())
    out["hidden"] = 0 if state.hidden_panels is None else state.hidden_panels.nbytes()  # a part of it
    return out
