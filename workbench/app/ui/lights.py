"""Light controls: each light's position (a directional light's direction, an area light's
centre), colour and intensity, edited live through :func:`~.state.set_light_value` (a new
frozen scene: GL panels redraw with it, CPU jobs restart)."""
from __future__ import annotations

from imgui_bundle import imgui

from ...core.errors import WorkbenchError
from .camera import orbit_parameters
from .state import AppState, light_fields, light_value, reset_lights, set_light_value

DRAG_FRACTION = 0.005
"""Position drag speed: this fraction of the camera's distance to its target per pixel."""


def light_controls(state: AppState) -> None:
    """One collapsible group per light of the scene."""
    lights = state.scene.lights
    if not lights:
        imgui.text_disabled("the scene has no light (emissive materials only)")
        return
    speed = orbit_parameters(state.camera)[3] * DRAG_FRACTION
    for k, light in enumerate(lights):
        kind = type(light).__name__.removesuffix("Light").lower()
        imgui.set_next_item_open(True, imgui.Cond_.once)
        if not imgui.collapsing_header(f"light {k} ({kind})##light{k}"):
            continue
        for name in light_fields(light):
            value = light_value(light, name)
            label = f"{name}##{k}"
            if name == "color":
                changed, v = imgui.color_edit3(label, list(value),
                                               imgui.ColorEditFlags_.hdr | imgui.ColorEditFlags_.float)
            elif name == "intensity":
                changed, v = imgui.drag_float(label, float(value), 0.01, 0.0, 1e6)
            else:
                changed, v = imgui.drag_float3(label, list(value),
                                               0.01 if name == "direction" else speed)
            if changed:
                try:
                    set_light_value(state, k, name, v)
                except WorkbenchError as e:  # e.g. a zero direction: kept as it was
                    state.status["lights"] = str(e)
    if state.light_overrides and imgui.button("reset lights"):
        reset_lights(state)
        state.status.pop("lights", None)
    if "lights" in state.status:
        imgui.text_disabled(state.status["lights"])

