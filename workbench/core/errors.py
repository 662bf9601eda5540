"""Errors the workbench reports to users as one clear message (never a traceback)."""


class WorkbenchError(ValueError):
    """Bad input from a user: a scene, an argument, an option.  The message says what and where."""


class NotApplicable(WorkbenchError):
    """A method cannot render this scene (e.g. radiosity without emitters); says why."""


class OverMemory(WorkbenchError):
    """Work refused before it allocates: its estimate is above the memory limit.  A setting the
    user can lift (a smaller image or knob, a higher limit), not a method's failure: a study or
    a comparison lists it as ``over_memory`` and goes on."""


class ShaderSourceError(WorkbenchError):
    """A user's shader code does not compile: the message is one line naming the user's file
    and line.  Bad input, not a method's failure: comparisons stop on it rather than list it."""


class SceneWarning(UserWarning):
    """A scene that loads but likely does not show what its author meant (an area light that
    faces away from every object).  The CLI prints it as one ``workbench: warning:`` line."""
