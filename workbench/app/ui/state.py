"""The one state object of the UI: every gui function takes it, nothing lives in module globals.

Plain data and the functions that edit it: the views (panels, plot, browser, ...) import this
module, never the other way round.  What a method is to the window (a GL panel, a CPU job, a
child process, a progressive job) is asked of its renderer (``ui_kind``,
:data:`workbench.renderers.base.UI_KINDS`; :func:`method_kind`), so a newly registered method
appears in the window without any edit here.
"""
from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ...renderers.base import USER_PREFIX, available, check_methods, get_renderer
from ...scene.model import Camera, Scene
from .drag_resolution import DragResolution
from .bounded import LruCache
from .images import PanelImages
from ...scene.features import scene_needs
from .jobs import RESTART_SETTLE_SECONDS, JobBoard

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
MATCHED_BOARDS_KEPT = 4
"""The error plot's boards of matched references kept (one per reference method and options:
each holds its last images); the least recently used beyond them is dropped."""


@dataclass
class Browser:
    """The file browser's folder, the file selected in it and the last outcome (error or
    opened); the view is :mod:`.file_browser`."""

    folder: Path
    selected: Path | None = None
    message: str = ""
    failed: bool = False
    listed: tuple[list[Path], list[Path]] | None = field(default=None, repr=False)
    listed_at: float = 0.0
    pattern: str = "*.toml"
    """The files listed (``fnmatch`` pattern): scene files, or a shading model's ``*.glsl``."""


@dataclass
class ErrorPlot:
    """Points of error against run time for one (scene version, camera); the view is
    :mod:`.plot`.

    ``points[method][option values]`` is ``{"seconds", "rmse", "psnr", "flip", "label"}``
    against the full reference (the total error); ``matched_points`` holds the same against
    the method's matched reference (its discretisation error, the error split of
    :mod:`workbench.compare.reference`), evaluated on its own when that reference arrives.
    ``matched[method]`` is that reference's image once rendered, or False (the method has
    none), for the panel's options ``matched_options[method]`` (Gouraud's and Phong's
    matched reference follows their stand-ins); ``matched_boards`` render them, one :class:`~.jobs.JobBoard` per (reference method,
    options) (a board runs one job per method), the :data:`MATCHED_BOARDS_KEPT` used last
    within the window's cache budget (:class:`~.bounded.LruCache`: an evicted board's jobs are
    cancelled, and it is joined at exit from ``retired``), never one the current key uses
    (``matched_in_use``: evicted, it would be asked for again at once); ``matched_message``
    says which are still rendering.
    """

    key: tuple | None = None
    since: float = 0.0
    candidates: list = field(default_factory=list)
    reference: str | None = None
    ref_options: dict = field(default_factory=dict)
    ref_image: np.ndarray | None = None
    message: str = ""
    points: dict = field(default_factory=dict)
    pending: dict = field(default_factory=dict)
    failed: dict = field(default_factory=dict)
    matched: dict = field(default_factory=dict)
    matched_options: dict = field(default_factory=dict)
    matched_points: dict = field(default_factory=dict)
    matched_pending: dict = field(default_factory=dict)
    matched_boards: LruCache = None
    retired: list = field(default_factory=list)
    matched_in_use: set = field(default_factory=set)
    matched_message: str = ""
    metric: str = "rmse"
    hover: str = ""
    """The tooltip of the point under the mouse in the last frame (empty: none)."""
    axes: dict = field(default_factory=dict)
    """The last frame's plot: ``{"rect": [x, y, w, h] pixels of the plot area, "x"|"y":
    {"limits": [lo, hi], "ticks": [[value, label, pixel along the axis, label's size]]}}``."""
    shown: int = -2
    gave_up: bool = False
    board: object = None
    pool: ProcessPoolExecutor | None = None

    def __post_init__(self):
        if self.matched_boards is None:
            self.matched_boards = LruCache(MATCHED_BOARDS_KEPT, size_of=lambda board: board.nbytes(),
                                           on_evict=self._retire, pinned=self.matched_in_use.__contains__)

    def _retire(self, _key, board) -> None:
        """An evicted matched board: its jobs cancelled (unless a panel shares one), kept in
        ``retired`` until its threads have ended."""
        board.keep_only(())
        self.retired = [b for b in self.retired if b.alive()] + [board]

    def busy(self, frame: int) -> bool:
        """Something will arrive without any input: evaluations in the worker, or, while the
        plot is shown (drawn in frame ``frame`` or the one before), its reference or a matched
        reference still rendering."""
        if self.pending or self.matched_pending:
            return True
        return self.shown >= frame - 1 and ((self.ref_image is None and not self.gave_up)
                                            or bool(self.matched_message))

    def boards(self) -> list:
        """The boards rendering references: the full one's and the matched ones'."""
        return [b for b in (self.board, *self.matched_boards.values()) if b is not None]

    def shutdown(self, timeout: float | None = None) -> None:
        """Cancel the reference renders (their threads joined, within ``timeout`` seconds
        each when given) and end the worker process (joined)."""
        for board in [*self.boards(), *self.retired]:
            board.join_all(timeout)
        self.retired = []
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)
            self.pool = None


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
    ``timings`` its last render time in seconds.  ``gpu`` is :class:`.panel_gpu.PanelGPU` (raster
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
    user_methods: list[str] = field(default_factory=list)
    """Users' shading models (``glsl:PATH``, :func:`add_shading_model`), listed in the Methods
    window after the registered methods."""
    shading_browser: Browser | None = None
    """The file picker of users' shading models (``*.glsl``)."""
    panel_errors: dict[str, tuple] = field(default_factory=dict)
    """method -> (what its GL session was to be built from, one-line message) of a GL panel
    whose session could not be built (a user's model that does not compile): the message is
    shown, and the build is not tried again until what it is built from changes."""
    progress: dict[str, dict] = field(default_factory=dict)
    """method -> what a CPU or progressive panel's image is (done, refining at how many spp,
    rendering how many rows, stale): :func:`.panel_refresh.shown_progress`; the export records
    it."""
    image_requests: dict[str, tuple] = field(default_factory=dict)
    """method -> (camera, scene) its panel's image was made for (a GL panel's last draw, a CPU
    job's request, or the previous one while a restart is pending); the difference view
    pauses while its two differ (:func:`.panel_refresh.mismatch`)."""
    kinds: dict[str, str] = field(default_factory=dict)
    """method -> its renderer's ``ui_kind`` (:func:`method_kind`)."""
    cut: set = field(default_factory=set)
    """Widgets that ran past their window's right edge in the last frame (``panels.check_fits``)."""
    window_size: tuple[int, int] = (0, 0)
    """The window's size when it closed (GLFW), kept for the next run (:mod:`.window_size`)."""
    layout_fit: tuple | None = None
    """(dock space height, panels' height) the control row was last sized for
    (:func:`.layout.refit`)."""
    wrapped: set = field(default_factory=set)
    """Section titles too long for their window in the last frame, wrapped instead of cut
    (:func:`.section.section`)."""
    hidden_panels: object = None
    """The panels hidden lately that still hold their images, sessions and textures, with the
    bytes each holds (a :class:`~.bounded.LruCache`: :func:`.panel_memory.keep_hidden`)."""
    quit: bool = False
    """Close the window at the end of this frame (scripts; SIGTERM and SIGINT)."""
    quit_signal: int = 0
    """The signal that closed the window (0: none)."""
    drag: DragResolution = field(default_factory=DragResolution)
    """The GL panels' render resolution while the camera moves (:mod:`.drag_resolution`)."""


def choosable_methods() -> list[str]:
    """Registered methods the UI can show (all of them)."""
    return list(available())


def short_name(method: str) -> str:
    """What the window calls a method: its name, or ``glsl:`` and the file's name for a
    user's shading model ``glsl:PATH`` (the whole path is a tooltip)."""
    if method.startswith(USER_PREFIX):
        return USER_PREFIX + Path(method[len(USER_PREFIX):]).name
    return method


def method_kind(state: AppState, method: str) -> str:
    """What ``method`` is to the window: its renderer's ``ui_kind`` (``"gl"``, ``"cpu"``,
    ``"child"`` or ``"progressive"``, :data:`workbench.renderers.base.UI_KINDS`), asked once."""
    kind = state.kinds.get(method)
    if kind is None:
        kind = state.kinds[method] = get_renderer(method).ui_kind
    return kind


def default_options(method: str) -> dict:
    """The method's quality knob at its default value; a progressive method's (``ui_kind``
    ``"progressive"``) at its most accurate, which it refines towards pass by pass; for a
    method that draws the raster's stand-ins (Gouraud, Phong: ``draws_standins``) also their
    options (:data:`~workbench.renderers.raster_standins.OPTIONS`) at the CLI's defaults, so a
    panel draws what ``workbench render`` draws; then the renderer's ``ui_options`` if it has
    any (radiosity's ``solver="progressive"``: each shooting round shown as it lands)."""
    from ...renderers.raster_standins import OPTIONS
    r = get_renderer(method)
    opts = {r.knob.name: r.knob.values[-1] if r.ui_kind == "progressive" else r.knob.default}
    if getattr(r, "draws_standins", False):
        opts.update({k: r.options[k].default for k in OPTIONS})
    opts.update(getattr(r, "ui_options", {}))
    return opts


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
    path = resolve(scene_name)
    scene = load_scene(path)
    allowed = choosable_methods()
    methods = list(methods) if methods else first_view(scene, allowed)
    user = [m for m in methods if m.startswith(USER_PREFIX)]
    bad = [m for m in methods if m not in allowed and m not in user]
    if bad or not 1 <= len(methods) <= MAX_PANELS:
        raise WorkbenchError(f"methods must be 1 to {MAX_PANELS} of {', '.join(allowed)} or "
                             f"{USER_PREFIX}FILE (got {', '.join(methods)})")
    check_methods(user)  # a user's shading model file that cannot be used: one line
    examples = Path.cwd() / "examples" / "shading"
    errors = ErrorPlot()
    # a panel takes the error plot's reference job of its very request (issue #29)
    jobs = JobBoard(RESTART_SETTLE_SECONDS, share=errors.boards)
    return AppState(scene=scene, scene_path=path, base_scene=scene,
                    camera=panel_camera(scene.camera, panel_size), methods=methods,
                    options={m: default_options(m) for m in [*allowed, *user]},
                    material=next(iter(scene.materials)), panel_size=panel_size,
                    diff_pair=(methods[0], methods[min(1, len(methods) - 1)]), jobs=jobs,
                    browser=Browser(path.parent), errors=errors, user_methods=user,
                    shading_browser=Browser(examples if examples.is_dir() else Path.cwd(),
                                            pattern="*.glsl"))


def add_shading_model(state: AppState, path) -> str:
    """Add the user's shading model in the GLSL file ``path``
    (:mod:`workbench.renderers.user_shading`) as the method ``glsl:PATH`` and show its panel
    (a seventh panel is refused as by :func:`toggle_method`); returns the method's name.  A
    file that cannot be used, or whose name would clash with another model's output files,
    raises :class:`~workbench.core.errors.WorkbenchError` (one line) and changes nothing; a
    model that does not compile shows its one-line message (the user's file and line) in its
    panel; adding the file again (once fixed) compiles it again."""
    from ...renderers.user_shading import method_name
    m = method_name(path)
    user = [*state.user_methods, *([] if m in state.user_methods else [m])]
    check_methods(user)
    state.user_methods[:] = user
    state.options.setdefault(m, default_options(m))
    state.kinds.pop(m, None)
    state.panel_errors.pop(m, None)
    toggle_method(state, m, True)
    return m


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
