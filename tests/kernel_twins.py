"""A kernel module as tests call it from Python: :class:`Twins`."""
from __future__ import annotations

from workbench.core.jit_options import python_twin, wrapperless


class Twins:
    """``Twins(module).name`` is ``module.name``, except that a kernel compiled without numba's
    wrappers (``workbench.core.jit_options.INTERNAL``: a crash if Python calls it) is its
    :func:`~workbench.core.jit_options.python_twin`, made at its first use in this object."""

    def __init__(self, module):
        self._module = module
        self._twins: dict[str, object] = {}

    def __getattr__(self, name: str):
        value = getattr(self._module, name)
        if not wrapperless(value):
            return value
        if name not in self._twins:
            self._twins[name] = python_twin(value)
        return self._twins[name]
