"""Interactive comparison UI (imgui-bundle): one :class:`~.state.AppState`, gui functions that
take it (:mod:`.panels`), pure camera functions (:mod:`.camera`), background CPU jobs
(:mod:`.jobs`) and the window loop (:mod:`.main`), started by ``workbench ui``."""

WINDOW_SIZE = (1280, 760)
"""The window's default size in pixels (width, height)."""
