"""The one state object of the UI: every gui function takes it, nothing lives in module globals."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ...scene.model import Camera, Scene
from .images import PanelImages
from ...scene.features import scene_needs

RASTER = ("flat", "gouraud", "phong")
"""Methods drawn every frame in the window's own GL context."""
CPU = ("raycast", "raytrace", "radiosity", "hybrid")
"""Methods run in background threads."""
CHILD = ("pyrender",)
"""Methods rendered in a child process (PyOpenGL's EGL platform cannot share the window's
process): :mod:`.pyrender_proc`."""
MAX_PANELS = 6
FIRST_VIEW = ("phong", "raytrace")
"""The methods of the first view of any scene: a raster method beside the ray tracer (their
difference in the difference view); :data:`EMITTER_VIEW` is added for a scene with emitters."""
EMITTER_VIEW = ("radiosity", "pathtrace")
"""Added to the first view of a scene with emitters (where registered): the diffuse
interreflection and the path-traced ground truth."""
FPS_CAP_WHILE_JOB = 40.0
"""While a background job runs, frames come at most this often (the rest of a frame's time is
slept, so the job gets the CPU); 0 for no cap.  Above the 30 fps the window must keep."""
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

    ``scene`` is the loaded scene with the material and light overrides applied;
    ``scene_version`` grows with every change of it (cache keys of GL sessions and background
    jobs).  ``camera`` is the
    shared camera of all panels at the panel resolution (:func:`panel_camera`: ``panel_size``
    pixels along the longer side, the scene camera's aspect); ``view`` (zoom, centre u, centre v)
    the linked 2D zoom of every image panel.  ``images`` holds each panel's last
    linear (H, W, 3) float32 image (raster ones read back from the GPU on first access),
    ``timings`` its last render time in seconds.  ``gpu`` is :class:`.frames.PanelGPU` (raster
    sessions, the sRGB display pass), made in the window's GL context.
    """

    scene: Scene
    scene_path: Path
    base_scene: Scene
    camera: Camera
    methods: list[str]
    options: dict[str, dict]
    material: str
    overrides: dict[str, dict[str, float]] = field(default_factory=dict)
    light_overrides: dict[int, dict[str, object]] = field(default_factory=dict)
    scene_version: int = 0
    panel_size: int = 256
    images: PanelImages = field(default_factory=PanelImages)
    textures: dict[str, object] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    status: dict[str, str] = field(default_factory=dict)
    frame: int = 0
    frame_seconds: float = 0.0
    gui_seconds: float = 0.0
    fps_cap_while_job: float = FPS_CAP_WHILE_JOB
    diff_pair: tuple[str, str] = ("flat", "phong")
    diff_kind: str = "abs"
    gl_renderer: str = ""
    ctx: object = None
    gpu: object = None
    jobs: object = None
    ray_tree: dict | None = None
    view: tuple[float, float, float] = (1.0, 0.5, 0.5)
    display: dict[str, str] = field(default_factory=dict)
    wheel: tuple[float, str] = (0.0, "triad")
    export_dir: Path = Path("out/ui_export")
    browser: object = None
    errors: object = None
    patch_pick: object = None
    pyrender: object = None
    cut: set = field(default_factory=set)
    """Widgets that ran past their window's right edge in the last frame (``panels.check_fits``)."""
    quit: bool = False


def choosable_methods() -> list[str]:
    """Registered methods the UI can show (all of them)."""
    from ...renderers.base import available
    return list(available())


def default_options(method: str) -> dict:
    """The method's quality knob at its default value; a progressive method's
    (:data:`~.jobs.PROGRESSIVE`) at its most accurate, which it refines towards pass by pass."""
    from ...renderers.base import get_renderer
    from .jobs import PROGRESSIVE
    knob = get_renderer(method).knob
    return {knob.name: knob.values[-1] if method in PROGRESSIVE else knob.default}


def first_view(scene: Scene, allowed) -> list[str]:
    """The methods shown when none are named: :data:`FIRST_VIEW`, plus :data:`EMITTER_VIEW`
    when the scene has emitters (``features.scene_needs``), each where registered."""
    from ...scene.features import EMITTERS
    wanted = [*FIRST_VIEW, *(EMITTER_VIEW if EMITTERS in scene_needs(scene) else ())]
    return [m for m in wanted if m in allowed]


def panel_camera(camera: Camera, size: int) -> Camera:
    """``camera`` at the panels' resolution: ``size`` pixels along its longer side, the other
    side keeping its aspect ratio (at least 1 pixel)."""
    w, h = camera.width, camera.height
    if w >= h:
        return camera.with_resolution(size, max(1, round(size * h / w)))
    return camera.with_resolution(max(1, round(size * w / h)), size)


def new_state(scene_name: str, methods: list[str] | None = None,
              panel_size: int = 256) -> AppState:
    """Load ``scene_name`` (bundled name or path) and build the initial state; the panels
    render ``panel_size`` pixels along the camera's longer side (:func:`panel_camera`)."""
    from ...core.errors import WorkbenchError
    from ...scene.io import load_scene
    from ...scene.library import resolve
    from .file_browser import Browser
    from .jobs import RESTART_SETTLE_SECONDS, JobBoard
    from .plot import ErrorPlot
    path = resolve(scene_name)
    scene = load_scene(path)
    allowed = choosable_methods()
    methods = list(methods) if methods else first_view(scene, allowed)
    bad = [m for m in methods if m not in allowed]
    if bad or not 1 <= len(methods) <= MAX_PANELS:
        raise WorkbenchError(f"methods must be 1 to {MAX_PANELS} of {', '.join(allowed)} "
                             f"(got {', '.join(methods)})")
    return AppState(scene=scene, scene_path=path, base_scene=scene,
                    camera=panel_camera(scene.camera, panel_size), methods=methods,
                    options={m: default_options(m) for m in allowed},
                    material=next(iter(scene.materials)), panel_size=panel_size,
                    diff_pair=(methods[0], methods[min(1, len(methods) - 1)]), jobs=JobBoard(RESTART_SETTLE_SECONDS),
                    browser=Browser(path.parent), errors=ErrorPlot())


def set_scene(state: AppState, scene_name: str) -> None:
    """Switch to another scene: camera reset, overrides dropped; the methods of the old scene's
    first view (:func:`first_view`, not edited) become the new scene's.  A scene that does not
    load raises its :class:`~workbench.core.errors.WorkbenchError` and changes nothing."""
    from ...scene.io import load_scene
    from ...scene.library import resolve
    path = resolve(scene_name)
    scene = load_scene(path)
    allowed = choosable_methods()
    if state.methods == first_view(state.base_scene, allowed):
        state.methods[:] = first_view(scene, allowed)
        state.diff_pair = (state.methods[0], state.methods[min(1, len(state.methods) - 1)])
    state.scene_path, state.base_scene, state.scene = path, scene, scene
    state.camera = panel_camera(state.scene.camera, state.panel_size)
    state.overrides, state.light_overrides = {}, {}
    state.material = next(iter(state.scene.materials))
    state.scene_version += 1
    # what showed the old scene goes: the ray tree, the picked patch, the run times (a CPU
    # panel's time is its new job's), the file browser's last outcome
    state.ray_tree = state.patch_pick = None
    state.timings.clear()
    for k in ("patch pick", "lights", "export"):
        state.status.pop(k, None)
    if state.browser is not None:
        state.browser.message, state.browser.failed = "", False


def _apply_overrides(state: AppState) -> None:
    """``state.scene`` = the loaded scene with the material and light overrides applied
    (``dataclasses.replace``: the model is frozen); the version grows."""
    mats = dict(state.base_scene.materials)
    for mname, fields in state.overrides.items():
        mats[mname] = replace(mats[mname], **fields)
    lights = list(state.base_scene.lights)
    for k, fields in state.light_overrides.items():
        fields = dict(fields)
        if "centre" in fields:  # an area light moves as a whole
            v = lights[k].vertices
            fields["vertices"] = v - v.mean(0) + np.asarray(fields.pop("centre"))
        lights[k] = replace(lights[k], **fields)
    state.scene = replace(state.base_scene, materials=mats, lights=tuple(lights))
    state.scene_version += 1


def set_material_value(state: AppState, material: str, name: str, value: float) -> None:
    """Override one field of one material (``dataclasses.replace`` on ``scene.materials``)."""
    if name not in MATERIAL_FIELDS:
        raise ValueError(f"not an editable material field: {name!r}")
    state.overrides.setdefault(material, {})[name] = float(value)
    _apply_overrides(state)


def light_fields(light) -> tuple[str, ...]:
    """The editable fields of a light: where it is (``position``, ``direction`` or an area
    light's ``centre``), ``color`` and ``intensity``."""
    from ...scene.model import AreaLight, DirectionalLight
    where = ("centre" if isinstance(light, AreaLight)
             else "direction" if isinstance(light, DirectionalLight) else "position")
    return (where, "color", "intensity")


def light_value(light, name: str):
    """A light's current value of an editable field (an area light's centre is its vertices'
    mean)."""
    if name == "centre":
        return tuple(float(x) for x in light.vertices.mean(0))
    return getattr(light, name)


def set_light_value(state: AppState, index: int, name: str, value) -> None:
    """Override one field of light ``index`` (see :func:`light_fields`); bad values raise
    :class:`~workbench.core.errors.WorkbenchError` and change nothing."""
    from ...core.errors import WorkbenchError
    lights = state.base_scene.lights
    if not 0 <= index < len(lights):
        raise WorkbenchError(f"no light {index} (the scene has {len(lights)})")
    if name not in light_fields(lights[index]):
        raise WorkbenchError(f"light {index} has no editable field {name!r} "
                             f"(editable: {', '.join(light_fields(lights[index]))})")
    if name == "intensity":
        value = float(value)
        ok = np.isfinite(value) and value >= 0.0
    else:
        value = tuple(float(x) for x in value)
        ok = len(value) == 3 and bool(np.isfinite(value).all())
        if name == "color":
            ok = ok and min(value) >= 0.0
        if name == "direction":
            ok = ok and float(np.linalg.norm(value)) > 0.0
    if not ok:
        raise WorkbenchError(f"light {index}: {name} = {value!r} is not valid (finite; colour and "
                             "intensity >= 0; direction non-zero; positions as 3 numbers)")
    state.light_overrides.setdefault(index, {})[name] = value
    _apply_overrides(state)


def reset_lights(state: AppState) -> None:
    """Back to the scene file's lights."""
    state.light_overrides = {}
    _apply_overrides(state)


def toggle_method(state: AppState, method: str, on: bool) -> bool:
    """Show (``on``) or hide ``method``'s panel; returns whether the list changed.  A seventh
    panel or hiding the last one is refused with the reason in ``state.status["methods"]``
    (shown in the Methods window)."""
    state.status.pop("methods", None)
    if on and method not in state.methods:
        if len(state.methods) >= MAX_PANELS:
            state.status["methods"] = (f"{method} not added: at most {MAX_PANELS} panels "
                                       "(untick one first)")
            return False
        state.methods.append(method)
        return True
    if not on and method in state.methods:
        if len(state.methods) == 1:
            state.status["methods"] = f"{method} kept: at least one panel is shown"
            return False
        state.methods.remove(method)
        return True
    return False


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
