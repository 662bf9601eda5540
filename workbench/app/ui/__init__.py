"""Interactive comparison UI (imgui-bundle): one :class:`~.state.AppState`, gui functions that
take it (:mod:`.panels`), pure camera functions (:mod:`.camera`), background CPU jobs
(:mod:`.jobs`) and the window loop (:mod:`.main`)."""
