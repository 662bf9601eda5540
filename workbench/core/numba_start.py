"""Numba's start-up without its BLAS probe: scipy.linalg is not imported by a render.

The first compile or disk-cache load of any numba function loads numba's CPU target
registries (``CPUContext.load_additional_registries``), among them ``numba.np.arraymath``,
whose import probes for a BLAS by importing ``scipy.linalg.cython_blas`` (its flag
``_HAVE_BLAS``).  Importing ``scipy.linalg`` imports scipy's array-API layer, which copies
every attribute of numpy and so imports ``numpy.f2py`` and ``numpy.testing``: about 0.1 s of
CPU, an eighth of a warm ``workbench render whitted -m raytrace`` (measured: issue #28).

The flag only chooses the inner product of ``np.correlate`` and ``np.convolve`` in jitted code
(BLAS ``dot`` or numba's own loop); no workbench kernel calls them, and numba's linear algebra
in jitted code (``np.dot``, ``np.linalg``) imports scipy itself when such a function compiles
(``numba.np.linalg.ensure_blas``), so it keeps working.  :func:`skip_blas_probe` installs a
one-shot import finder: while ``numba.np.arraymath`` runs its module code, in that thread
only, ``scipy.linalg`` (not yet imported) cannot be imported, the probe answers "no BLAS", and
the finder removes itself.  A process that imported ``scipy.linalg`` before is left as numba
makes it (the probe is cheap then).  Only the ``workbench`` program installs it
(:func:`workbench.app.cli.main`): a process that imports the library keeps numba's own start-up.
"""
from __future__ import annotations

import importlib.abc
import importlib.machinery
import sys
import threading

PROBER = "numba.np.arraymath"
"""The numba module whose import probes for a BLAS."""
PROBED = "scipy.linalg"
"""The package the probe imports (``scipy.linalg.cython_blas``: its parent is the cost)."""


class _SkipBlasProbe(importlib.abc.MetaPathFinder):
    """Finds :data:`PROBER` with a loader that runs it with :data:`PROBED` refused in its
    thread; refuses :data:`PROBED` in that thread meanwhile."""

    def __init__(self):
        self.thread: int | None = None

    def find_spec(self, name, path=None, target=None):
        if name == PROBED and self.thread == threading.get_ident():
            raise ModuleNotFoundError(f"{PROBED} is not imported while numba loads its registries "
                                      "(workbench.core.numba_start)", name=name)
        if name != PROBER:
            return None
        spec = importlib.machinery.PathFinder.find_spec(name, path, target)
        if spec is not None and type(spec.loader) is importlib.machinery.SourceFileLoader:
            spec.loader = _ProbeFreeLoader(spec.loader.name, spec.loader.path, self)
        else:       # not a plain source file: leave it to numba
            _remove(self)
        return spec


class _ProbeFreeLoader(importlib.machinery.SourceFileLoader):
    """:data:`PROBER`'s own source loader, its module code run with the finder refusing
    :data:`PROBED` in this thread; the finder is removed once it has run."""

    def __init__(self, fullname, path, finder: _SkipBlasProbe):
        super().__init__(fullname, path)
        self.finder = finder

    def exec_module(self, module):
        self.finder.thread = threading.get_ident()
        try:
            super().exec_module(module)
        finally:
            self.finder.thread = None
            _remove(self.finder)


def _remove(finder) -> None:
    try:
        sys.meta_path.remove(finder)
    except ValueError:  # removed already
        pass


def skip_blas_probe() -> None:
    """Install the finder (see the module's docstring) unless ``numba.np.arraymath`` or
    ``scipy.linalg`` is imported already or the finder is installed."""
    if PROBER in sys.modules or PROBED in sys.modules:
        return
    if not any(isinstance(f, _SkipBlasProbe) for f in sys.meta_path):
        sys.meta_path.insert(0, _SkipBlasProbe())
