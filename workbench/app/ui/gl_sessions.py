"""How a GL panel's :class:`~workbench.renderers.raster.RasterSession` is built, and the
stand-in controls of the window (issue 15 item 4).

A panel's session is its renderer's (``Renderer.session``) with the panel's options, the
CLI's names and defaults (``state.options[method]``: the tessellation knob, and for Gouraud and
Phong the stand-ins, :data:`~workbench.renderers.raster_standins.OPTIONS`, on by default where
the scene needs them), so a panel draws what ``workbench render --method M --set ...`` draws.
Its memory estimate (the renderer's ``estimate_bytes`` at the panel's size, stand-ins' maps
included) is checked against the limit of ``workbench.render`` before anything is allocated:
over it, the renderer's one-line message is the panel's (and nothing is built).

The stand-ins' maps do not depend on the camera: a session draws them once (and after an edit
that changes them, ``RasterSession.update``), so a camera drag costs the main pass only.
"""
from __future__ import annotations

from .state import AppState

STANDIN_CHOICES = ("on", "off", "envmap", "blend", "shadows", "envmap,blend", "envmap,shadows",
                   "blend,shadows")
"""Values of the ``standins`` option offered in the window (the CLI also takes any order)."""
KNOB_VALUES = {"envmap_resolution": (16, 32, 64, 128, 256, 512),
               "shadow_resolution": (128, 256, 512, 1024, 2048),
               "shadow_bias": (0.0, 0.0005, 0.001, 0.003, 0.01, 0.03),
               "envmap_iterations": (0, 1, 2, 3, 5)}
"""The stand-ins' knobs offered in the window (the defaults among them; the CLI takes any
value in their ranges)."""


def build_session(state: AppState, method: str):
    """``method``'s session for the panels: the scene and camera size of ``state``, its options
    ``state.options[method]``, the window's context.  Raises WorkbenchError (one line) when the
    estimate exceeds the memory limit or a user's model does not compile."""
    from ...renderers.base import get_renderer
    cam = state.camera
    return get_renderer(method).session(state.scene, cam.width, cam.height, ctx=state.ctx,
                                        **state.options[method])


def session_status(session) -> str:
    """The panel's line under its image: triangles and the stand-ins drawn (or why none)."""
    drawn = [k for k, on in (("envmap", session.plan.envmap), ("blend", session.plan.blend),
                             ("shadows", session.plan.shadows)) if on]
    what = f"stand-ins {', '.join(drawn)}" if drawn else "bare local model"
    return f"{session.n_triangles} triangles, {what}"


def draws_standins(method: str) -> bool:
    """The method draws the raster's stand-ins (Gouraud, Phong)."""
    from ...renderers.base import get_renderer
    return bool(getattr(get_renderer(method), "draws_standins", False))
