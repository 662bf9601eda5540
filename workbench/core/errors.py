"""Errors the workbench reports to users as one clear message (never a traceback)."""


class WorkbenchError(ValueError):
    """Bad input from a user: a scene, an argument, an option.  The message says what and where."""


class NotApplicable(WorkbenchError):
    """A method cannot render this scene (e.g. radiosity without emitters); says why."""
