"""Looking closely: the pixel probe and the ray tree of a clicked pixel (the export is in
:mod:`.export`)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
from imgui_bundle import imgui

from .section import section
from .state import AppState


def pixel_under_mouse(state: AppState) -> tuple[int, int] | None:
    """(row, column) of the image pixel under the mouse in the last drawn panel (shown at any
    size, through the linked 2D view), or None."""
    if not imgui.is_item_hovered():
        return None
    from .camera import view_window
    lo, mouse, size = imgui.get_item_rect_min(), imgui.get_mouse_pos(), imgui.get_item_rect_size()
    (u0, v0), (u1, v1) = view_window(state.view)
    fx, fy = (mouse.x - lo.x) / size.x, (mouse.y - lo.y) / size.y
    i = int((v0 + fy * (v1 - v0)) * state.camera.height)
    j = int((u0 + fx * (u1 - u0)) * state.camera.width)
    if 0 <= i < state.camera.height and 0 <= j < state.camera.width:
        return i, j
    return None


def probe_tooltip(state: AppState, ij: tuple[int, int]) -> None:
    """Tooltip with every panel's linear value at pixel ``ij`` (and the difference value)."""
    i, j = ij
    lines = [f"pixel row {i}, column {j}"]
    shape = (state.camera.height, state.camera.width)
    for m in [*state.methods, "difference"]:
        v = state.images.pixel(m, i, j, shape) if m in state.images else None
        if v is not None:
            lines.append(f"{m:>10}: " + " ".join(f"{x:.4f}" for x in np.atleast_1d(v)))
    imgui.set_tooltip("\n".join(lines))


def select_ray_tree(state: AppState, i: int, j: int) -> dict:
    """Compute the ray tree of pixel (i, j) with the shared camera and the ``raytrace``
    options (:func:`workbench.renderers.raytrace.ray_tree`); kept in ``state.ray_tree``."""
    from ...renderers.raytrace import ray_tree
    scene = replace(state.scene, camera=state.camera)
    state.ray_tree = {"pixel": [i, j], "tree": ray_tree(scene, i, j, **state.options["raytrace"])}
    return state.ray_tree


def shown_field(node: dict, key: str):
    """What the inspector shows for ``node[key]``: the hit object as its scene name (or kind
    and index) followed by its index, ``"glass (#2)"``; any other field as it is."""
    v = node[key]
    if key == "object" and v is not None and "object_name" in node:
        return f"{node['object_name']} (#{v})"
    return v


def _show_node(label: str, node) -> None:
    if isinstance(node, dict):
        if imgui.tree_node(f"{label}##{id(node)}"):
            for k in node:
                if k != "object_name":
                    _show_node(str(k), shown_field(node, k))
            imgui.tree_pop()
    elif isinstance(node, list) and node and isinstance(node[0], (dict, list)):
        if imgui.tree_node(f"{label} [{len(node)}]##{id(node)}"):
            for k, v in enumerate(node):
                _show_node(f"{label}[{k}]", v)
            imgui.tree_pop()
    else:
        if isinstance(node, (list, tuple)):
            node = "(" + ", ".join(f"{x:.4g}" if isinstance(x, float) else str(x) for x in node) + ")"
        elif isinstance(node, float):
            node = f"{node:.4g}"
        imgui.bullet_text(f"{label}: {node}")


def ray_tree_view(state: AppState) -> None:
    """The selected pixel's ray tree as nested tree nodes (Ctrl+click in the raytrace panel)."""
    section(state, "ray tree (Ctrl+click the raytrace panel)")
    if state.ray_tree is not None:
        i, j = state.ray_tree["pixel"]
        imgui.set_next_item_open(True, imgui.Cond_.once)
        _show_node(f"pixel ({i}, {j})", state.ray_tree["tree"])
