"""The one state object of the UI: every gui function takes it, nothing lives in module globals."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ...scene.model import Camera, Scene

RASTER = ("flat", "gouraud", "phong")
"""Methods drawn every frame in the window's own GL context."""
CPU = ("raycast", "raytrace", "radiosity", "hybrid")
"""Methods run in background threads."""
LEFT_OUT = {"pyrender": "needs its own process with PyOpenGL's EGL platform; not in the UI"}
MAX_PANELS = 6
MATERIAL_FIELDS = ("ka", "kd", "ks", "shininess", "kr", "kt", "ior")
DISPLAY_MODES = ("direct24", "direct16-555", "direct16-565", "direct16-565-fs",
                 "indexed256-mediancut", "indexed16-mediancut", "indexed16-kmeans-fs",
                 "indexed4-mediancut-bayer", "indexed2-mediancut")
"""Display modes offered per panel (the colour chapter's 24/16-bit direct and indexed CLUTs);
``workbench.core.display`` accepts more from the CLI."""
HARMONIES = ("complementary", "triad", "square", "hexagon")


@dataclass
class AppState:
    """Everything the UI shows and edits.

    ``scene`` is the loaded scene with the material overrides applied; ``scene_version`` grows
    with every change of it (cache keys of GL sessions and background jobs).  ``camera`` is the
    shared camera of all panels at the panel resolution; ``view`` (zoom, centre u, centre v)
    the linked 2D zoom of every image panel.  ``images`` holds each panel's last
    linear (H, W, 3) float32 image, ``timings`` its last render time in seconds.
    """

    scene: Scene
    scene_path: Path
    base_scene: Scene
    camera: Camera
    methods: list[str]
    options: dict[str, dict]
    material: str
    overrides: dict[str, dict[str, float]] = field(default_factory=dict)
    scene_version: int = 0
    panel_size: tuple[int, int] = (256, 256)
    images: dict[str, np.ndarray] = field(default_factory=dict)
    textures: dict[str, object] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    status: dict[str, str] = field(default_factory=dict)
    frame: int = 0
    frame_seconds: float = 0.0
    gui_seconds: float = 0.0
    diff_pair: tuple[str, str] = ("flat", "phong")
    diff_kind: str = "abs"
    gl_renderer: str = ""
    ctx: object = None
    sessions: dict = field(default_factory=dict)
    jobs: object = None
    srgb_lut: object = None
    ray_tree: dict | None = None
    view: tuple[float, float, float] = (1.0, 0.5, 0.5)
    display: dict[str, str] = field(default_factory=dict)
    wheel: tuple[float, str] = (0.0, "triad")
    export_dir: Path = Path("out/ui_export")
    quit: bool = False


def choosable_methods() -> list[str]:
    """Registered methods the UI can show (pyrender is left out, see :data:`LEFT_OUT`)."""
    from ...renderers.base import available
    return [m for m in available() if m not in LEFT_OUT]


def default_options(method: str) -> dict:
    """The method's quality knob at its default value."""
    from ...renderers.base import get_renderer
    knob = get_renderer(method).knob
    return {knob.name: knob.default}


def new_state(scene_name: str, methods: list[str] | None = None,
              panel_size: tuple[int, int] = (256, 256)) -> AppState:
    """Load ``scene_name`` (bundled name or path) and build the initial state."""
    from ...core.errors import WorkbenchError
    from ...scene.io import load_scene
    from ...scene.library import resolve
    from .jobs import JobBoard
    path = resolve(scene_name)
    scene = load_scene(path)
    allowed = choosable_methods()
    methods = list(methods) if methods else [m for m in RASTER if m in allowed]
    bad = [m for m in methods if m not in allowed]
    if bad or not 1 <= len(methods) <= MAX_PANELS:
        raise WorkbenchError(f"methods must be 1 to {MAX_PANELS} of {', '.join(allowed)} "
                             f"(got {', '.join(methods)})")
    return AppState(scene=scene, scene_path=path, base_scene=scene,
                    camera=scene.camera.with_resolution(*panel_size), methods=methods,
                    options={m: default_options(m) for m in allowed},
                    material=next(iter(scene.materials)), panel_size=panel_size,
                    diff_pair=(methods[0], methods[-1]), jobs=JobBoard())


def set_scene(state: AppState, scene_name: str) -> None:
    """Switch to another scene: camera reset, overrides dropped."""
    from ...scene.io import load_scene
    from ...scene.library import resolve
    state.scene_path = resolve(scene_name)
    state.base_scene = state.scene = load_scene(state.scene_path)
    state.camera = state.scene.camera.with_resolution(*state.panel_size)
    state.overrides = {}
    state.material = next(iter(state.scene.materials))
    state.scene_version += 1


def set_material_value(state: AppState, material: str, name: str, value: float) -> None:
    """Override one field of one material (``dataclasses.replace`` on ``scene.materials``)."""
    if name not in MATERIAL_FIELDS:
        raise ValueError(f"not an editable material field: {name!r}")
    state.overrides.setdefault(material, {})[name] = float(value)
    mats = dict(state.base_scene.materials)
    for mname, fields in state.overrides.items():
        mats[mname] = replace(mats[mname], **fields)
    state.scene = replace(state.base_scene, materials=mats)
    state.scene_version += 1


def set_option(state: AppState, method: str, name: str, value) -> None:
    """Set a method's option (its quality knob)."""
    state.options[method] = {**state.options[method], name: value}


def set_display(state: AppState, method: str, mode: str) -> None:
    """Show ``method``'s panel through a display mode (checked by ``display_mode``)."""
    from ...core.display import display_mode
    display_mode(mode)  # raises WorkbenchError on a bad mode string
    state.display[method] = mode


def shown_image(state: AppState, method: str) -> np.ndarray:
    """The panel's linear image as displayed: through its display mode if one is set."""
    image = state.images[method]
    mode = state.display.get(method, "direct24")
    if mode == "direct24":
        return image
    from ...core.display import apply_display_mode
    return apply_display_mode(image, mode)
