"""In-window file browsers: scene files (``*.toml``) and users' shading models (``*.glsl``).

imgui-bundle's ``portable_file_dialogs`` opens zenity or kdialog, which a bare (or headless)
machine does not have; a browser lists a folder inside the window instead: its sub-folders,
its files of the browser's pattern, a parent button and a folder field.  Opening a scene file
that does not load leaves the current scene as it was and shows the loader's message
(:class:`~workbench.scene.io.SceneError` names the file, the key and what was expected) in the
window; a shading model that cannot be used or does not compile shows its one-line message
(the user's file and line) the same way.
"""
from __future__ import annotations

import time
from pathlib import Path

from ...core.errors import WorkbenchError
from .section import section
from .state import AppState, Browser, add_shading_model, set_scene

RELIST_SECONDS = 1.0
"""A shown folder is listed again after this long (files saved meanwhile appear), not every frame."""


def cached_listing(browser: Browser, now: float | None = None) -> tuple[list[Path], list[Path]]:
    """:func:`listing` of the browser's folder, listed again only after ``RELIST_SECONDS`` or a
    change of folder (a folder that cannot be listed raises each time it is listed)."""
    now = time.monotonic() if now is None else now
    if browser.listed is None or now - browser.listed_at >= RELIST_SECONDS:
        browser.listed, browser.listed_at = None, now
        browser.listed = listing(browser.folder, browser.pattern)
    return browser.listed


def listing(folder: Path, pattern: str = "*.toml") -> tuple[list[Path], list[Path]]:
    """(sub-folders, files matching ``pattern``) of ``folder``, each sorted by name; hidden
    entries left out."""
    folder = Path(folder)
    try:
        entries = [p for p in folder.iterdir() if not p.name.startswith(".")]
    except OSError as e:
        raise WorkbenchError(f"{folder}: cannot list this folder ({e.strerror or e})") from None
    dirs = sorted((p for p in entries if p.is_dir()), key=lambda p: p.name.lower())
    files = sorted((p for p in entries if p.is_file() and p.match(pattern)),
                   key=lambda p: p.name.lower())
    return dirs, files


def go_to(browser: Browser, folder: Path) -> None:
    """Show ``folder`` (a message instead if it is not a folder)."""
    folder = Path(folder).expanduser()
    if not folder.is_dir():
        browser.message, browser.failed = f"{folder}: not a folder", True
        return
    browser.folder, browser.selected, browser.listed = folder.resolve(), None, None
    browser.message, browser.failed = "", False


def open_scene(state: AppState, path: Path) -> bool:
    """Load ``path`` as the scene; on a bad file keep the current scene and keep the message."""
    b = state.browser
    try:
        set_scene(state, str(path))
    except WorkbenchError as e:
        b.message, b.failed = str(e), True
        return False
    except OSError as e:  # unreadable file: permissions, vanished
        b.message, b.failed = f"{path}: cannot be read ({e.strerror or e})", True
        return False
    b.message, b.failed = f"opened {Path(path).name}", False
    return True


def add_model(state: AppState, path: Path) -> bool:
    """Add the shading model in ``path`` as a method panel (:func:`~.state.add_shading_model`);
    a file that cannot be used keeps everything as it was and its message is kept."""
    b = state.shading_browser
    try:
        m = add_shading_model(state, path)
    except WorkbenchError as e:
        b.message, b.failed = str(e), True
        return False
    except OSError as e:
        b.message, b.failed = f"{path}: cannot be read ({e.strerror or e})", True
        return False
    b.message, b.failed = state.status.get("methods") or f"added {m}", "methods" in state.status
    return True


def file_browser(state: AppState) -> None:
    """The scene file browser (:func:`browse`), under its title."""
    section(state, "scene file")
    browse(state.browser, "open", lambda path: open_scene(state, path))


def shading_picker(state: AppState) -> None:
    """The picker of users' shading models: a ``*.glsl`` file becomes a method panel
    (``glsl:FILE``); under it, the one-line compile error of each added model that failed."""
    from imgui_bundle import imgui
    section(state, "your shading model (GLSL)")
    browse(state.shading_browser, "add", lambda path: add_model(state, path))
    imgui.push_text_wrap_pos(0.0)
    for m in state.user_methods:
        if m in state.panel_errors:
            imgui.text_colored(imgui.ImVec4(1.0, 0.35, 0.3, 1.0), state.panel_errors[m][1])
    imgui.pop_text_wrap_pos()


def browse(b: Browser, action: str, chosen) -> None:
    """A browser's widgets: folder field, parent button, its folders and files, the ``action``
    button; ``chosen(path)`` on a double click or the button; the last outcome under them."""
    from imgui_bundle import imgui
    imgui.push_id(action)
    if imgui.button("parent"):
        go_to(b, b.folder.parent)
    imgui.same_line()
    imgui.set_next_item_width(-1)
    entered, text = imgui.input_text("##folder", str(b.folder),
                                     imgui.InputTextFlags_.enter_returns_true)
    if entered:
        go_to(b, Path(text))
    try:
        dirs, files = cached_listing(b)
    except WorkbenchError as e:
        dirs, files = [], []
        b.message, b.failed = str(e), True
    imgui.begin_child("listing", imgui.ImVec2(0, 90), imgui.ChildFlags_.borders)
    for d in dirs:
        if imgui.selectable(f"[{d.name}]", False, imgui.SelectableFlags_.allow_double_click)[0] \
                and imgui.is_mouse_double_clicked(imgui.MouseButton_.left):
            go_to(b, d)
    for f in files:
        clicked, _ = imgui.selectable(f.name, f == b.selected,
                                      imgui.SelectableFlags_.allow_double_click)
        if clicked:
            b.selected = f
            if imgui.is_mouse_double_clicked(imgui.MouseButton_.left):
                chosen(f)
    if not dirs and not files:
        imgui.text_disabled(f"no folder and no {b.pattern} file here")
    imgui.end_child()
    imgui.begin_disabled(b.selected is None)
    if imgui.button(action):
        chosen(b.selected)
    imgui.end_disabled()
    if b.message:
        colour = imgui.ImVec4(1.0, 0.35, 0.3, 1.0) if b.failed else imgui.ImVec4(0.5, 0.9, 0.5, 1.0)
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(colour, b.message)
        imgui.pop_text_wrap_pos()
    imgui.pop_id()
