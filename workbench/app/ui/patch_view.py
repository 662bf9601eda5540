"""The radiosity patch view: Ctrl+click a surface in the radiosity panel to see the patch under
the pixel, its hemicube item buffer and its form-factor row (Cohen & Greenberg 1985).

* Picking draws the panel's patches (same scene, camera and ``patch_size`` as the panel) with
  the radiosity display (:func:`workbench.renderers.radiosity.display.draw`), each patch flat
  in the colour ``patch number + 1`` (a float32 target holds it exactly), and reads the pixel.
* The item buffer is :meth:`Hemicube.item_buffers` of that patch, unfolded into a cross (the
  top face in the middle as the hemicube's eye sees it looking along the normal, each half side
  folded out from the edge it shares with the top face), coloured by patch number.
* The row ``F[i, :]`` is :meth:`Hemicube.rows` (the item buffer's delta form factors summed per
  patch), shown by colouring every patch with ``F_ij`` from the panel's camera, with the row
  sum (1 for a closed scene when the delta form factors are normalised; less where the
  hemicube sees out of the scene).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from .state import AppState

VIEW_SIZE = 160
"""Pixels across the row image (the panel's view, smaller)."""
SELECTED = np.array([0.2, 1.0, 1.0])
"""Colour of the selected patch in the row image (linear RGB)."""
EMPTY = np.array([40, 40, 40], np.uint8)
"""Item-buffer pixels that see no patch (display sRGB)."""


@dataclass
class PatchPick:
    """The patch picked in the radiosity panel and what its hemicube saw."""

    pixel: tuple[int, int]
    patch: int
    surface: str
    item: np.ndarray          # (res, 3 res) uint32, patch + 1, rows bottom-up
    row: np.ndarray           # (P,) F[patch, :]
    patches: object           # the PatchSet
    resolution: int
    made: float = field(default_factory=time.perf_counter)   # tells two picks apart


def radiosity_options(state: AppState) -> dict:
    """The radiosity panel's options: its knob from the UI, the rest at their defaults."""
    from ...renderers.base import get_renderer
    opts = {k: o.default for k, o in get_renderer("radiosity").options.items()}
    return {**opts, **state.options["radiosity"]}


def scene_patches(state: AppState):
    """The panel's patches (``patch_size`` times the scene's extent, as the method cuts them)."""
    from ...renderers.radiosity.patches import patches_from_scene
    from ...scene.prepared import prepare
    size = radiosity_options(state)["patch_size"] * prepare(state.scene).extent
    return patches_from_scene(state.scene, size)[0]


def flat(patches):
    """The patches with unshared corners: per-patch values show flat (no Gouraud blending)."""
    P = len(patches)
    return replace(patches, vertices=patches.corners.reshape(-1, 3),
                   vertex_ids=np.arange(4 * P).reshape(P, 4))


def patch_ids(patches, camera) -> np.ndarray:
    """(H, W) int: the patch seen at each pixel of ``camera`` (front faces), -1 for none."""
    from ...renderers.radiosity.display import draw
    values = np.repeat(np.arange(1, len(patches) + 1, dtype=np.float64)[:, None], 3, 1)
    img, _ = draw(flat(patches), values, camera, (0.0, 0.0, 0.0))
    return np.rint(img[..., 0]).astype(np.int64) - 1


def unfold(item: np.ndarray) -> np.ndarray:
    """A hemicube item buffer (res, 3 res), rows bottom-up, laid out as
    :func:`~workbench.renderers.radiosity.hemicube.delta_form_factors` (top face, then the half
    sides looking along +u, -u, +v, -v), unfolded into a (2 res, 2 res) cross, rows top-down:
    the top face in the middle as seen looking along the normal (right = -u, up = +v), each
    half side folded out from its shared edge (horizon outermost).  Outside the cross: -1.

    Net coordinates (X, Y) in [-2, 2]^2, the top face [-1, 1]^2; a side pixel (x_s, y_s)
    (x_s in [-1, 1] along the face's right vector, y_s in [0, 1] up the normal) sits at
      +u (right -v): (y_s - 2, -x_s)    -u (right +v): (2 - y_s, x_s)
      +v (right +u): (-x_s, 2 - y_s)    -v (right -u): (x_s, y_s - 2)
    """
    res = item.shape[0]
    h = res // 2
    n = 2 * res
    c = (np.arange(n) + 0.5) / n * 4.0 - 2.0
    X, Y = np.meshgrid(c, -c)                                   # row 0 at Y = +2
    out = np.full((n, n), -1, np.int64)

    def put(mask, xs, ys, x0, y0, height):
        col = np.clip(((xs[mask] + 1.0) / 2.0 * res).astype(int), 0, res - 1) + x0
        row = np.clip((ys[mask] * height).astype(int), 0, height - 1) + y0
        out[mask] = item[row, col]

    inner = (np.abs(X) < 1) & (np.abs(Y) < 1)
    put(inner, X, (Y + 1.0) / 2.0, 0, 0, res)                    # top face: x = X, y = Y
    band = np.abs(Y) < 1
    # (mask, x_s, y_s, block origin) of each half side, blocks as in delta_form_factors
    sides = (((X < -1) & band, -Y, X + 2.0, (res, 0)),           # +u
             ((X > 1) & band, Y, 2.0 - X, (res, h)),             # -u
             ((Y > 1) & (np.abs(X) < 1), -X, 2.0 - Y, (2 * res, 0)),   # +v
             ((Y < -1) & (np.abs(X) < 1), X, Y + 2.0, (2 * res, h)))   # -v
    for mask, xs, ys, (x0, y0) in sides:
        put(mask, xs, ys, x0, y0, h)
    return out


def id_colours(ids: np.ndarray) -> np.ndarray:
    """(..., 3) uint8 colours of patch numbers + 1 (golden-ratio hues; 0: grey, -1: black)."""
    from ...core.color import hsv_to_rgb
    k = ids.astype(np.float64)
    hue = (k * 0.6180339887) % 1.0 * 360.0
    rgb = hsv_to_rgb(np.stack([hue, np.full_like(k, 0.65), 0.55 + 0.4 * ((k * 0.37) % 1.0)], -1))
    rgb = (np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8)
    rgb[ids == 0] = EMPTY
    rgb[ids < 0] = 0
    return rgb


def select_patch(state: AppState, i: int, j: int) -> PatchPick | None:
    """Pick the patch at pixel (i, j) of the radiosity panel and draw its hemicube (item buffer
    and form-factor row); kept in ``state.patch_pick`` (None where no patch is seen)."""
    from ...core.errors import WorkbenchError
    from ...renderers.radiosity.hemicube import Hemicube
    opts = radiosity_options(state)
    state.patch_pick, state.status["patch pick"] = None, f"pixel ({i}, {j}) shows no patch"
    try:
        patches = scene_patches(state)
        p = int(patch_ids(patches, state.camera)[i, j])
        if p < 0:
            return None
        hc = Hemicube(patches.geometry(), opts["hemicube_resolution"],
                      rotate=opts["hemicube_rotate"], normalize=opts["hemicube_normalize"])
        try:
            item, row = hc.item_buffers([p])[0], hc.rows([p])[0]
        finally:
            hc.release()
    except WorkbenchError as e:  # e.g. a surface that cannot be cut into patches
        state.status["patch pick"] = str(e)
        return None
    names = patches.surface_names
    surface = names[patches.surface[p]] if len(names) else str(patches.surface[p])
    state.patch_pick = PatchPick((i, j), p, surface, item, row, patches, hc.res)
    return state.patch_pick


def row_image(state: AppState, pick: PatchPick) -> np.ndarray:
    """(VIEW_SIZE, VIEW_SIZE, 3) uint8: each patch coloured by F_ij (the difference panel's
    colour scale, 0 to the row's maximum), the picked patch in :data:`SELECTED`."""
    from ...renderers.radiosity.display import draw
    from .colours import colour_scale
    vmax = float(pick.row.max())
    colours = colour_scale(pick.row[None], vmax)[0].astype(np.float64) / 255.0
    colours[pick.patch] = SELECTED
    camera = state.camera.with_resolution(VIEW_SIZE, VIEW_SIZE)
    img, _ = draw(flat(pick.patches), colours, camera, (0.0, 0.0, 0.0))
    return (np.clip(img, 0.0, 1.0) * 255 + 0.5).astype(np.uint8)


def patch_view(state: AppState) -> None:
    """The picked patch: item buffer (unfolded hemicube) and form-factor row."""
    from imgui_bundle import imgui

    from .panel_gpu import stale, upload
    pick = state.patch_pick
    if pick is None:
        imgui.text_disabled("Ctrl+click a surface in the radiosity panel")
        imgui.text_disabled(state.status.get("patch pick", ""))
        return
    if stale(state, "patch view", pick.made) or "patch row" not in state.textures:
        upload(state, "patch item", id_colours(unfold(pick.item)))
        upload(state, "patch row", row_image(state, pick))
    imgui.text(f"patch {pick.patch} of {len(pick.patches)} ({pick.surface}), pixel {pick.pixel}")
    imgui.text(f"hemicube {pick.resolution} px: row sum {pick.row.sum():.4f}, "
               f"{int((pick.row > 0).sum())} patches seen, max F {pick.row.max():.4g}")
    side = min(imgui.get_content_region_avail().x / 2 - 8, imgui.get_content_region_avail().y - 8)
    side = max(side, 64.0)
    imgui.image(imgui.ImTextureRef(state.textures["patch item"].glo), imgui.ImVec2(side, side))
    imgui.same_line()
    imgui.image(imgui.ImTextureRef(state.textures["patch row"].glo), imgui.ImVec2(side, side))
