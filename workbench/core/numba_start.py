"""Numba's start-up for the ``workbench`` program: no BLAS probe, and no typing or lowering
registries loaded for kernels that come from the disk cache.

**The BLAS probe.**  The first compile or disk-cache load of any numba function loads numba's CPU target
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
makes it (the probe is cheap then).

**Cache hits without the registries.**  Before it loads a kernel from the disk cache, numba
refreshes its CPU target context (``Cache.load_overload`` calls ``refresh``): it imports and
installs every typing and lowering registry (252 of them: ``numba.np.*``, ``numba.typed.*``,
``numba.cpython.*``...), which typing and lowering need and a cached kernel does not: the cache
holds its machine code, linked with everything it calls, and its signature.  What loading does
need is numba's runtime (NRT: the allocator's symbols the machine code links to), which the
refresh initialises first, and string hashing's secret symbols, which only the import of
``numba.cpython.hashing`` adds (imported with the patch).  Left out, and so needing a compile
first in a process: a cached kernel that takes a ``cfunc`` from Python (its ``typeof`` lives
in a registry module).  :func:`load_cache_hits_without_registries` makes a cache hit
initialise the runtime only; a cache miss compiles, and numba's compiler refreshes both
contexts itself before it types anything (``CompilerBase.__init__``), so a process that
compiles after it loaded has every registry as before.

Only the ``workbench`` program installs these (:func:`workbench.app.cli.main`): a process that
imports the library keeps numba's own start-up.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import threading

from .jit_cache import when_caching_loads

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


def load_cache_hits_without_registries() -> None:
    """Make numba's disk-cache loads initialise its runtime (NRT) instead of refreshing the
    whole target context (see the module's docstring), now if numba's caching module is loaded,
    else as soon as it is (:func:`.jit_cache.when_caching_loads`: installing it does not import
    numba)."""
    when_caching_loads(_hits_without_registries)


def _hits_without_registries(caching) -> None:
    """Replace ``caching.Cache.load_overload``; left as numba makes it if the class lacks the
    methods this relies on (numba's ``Cache`` of 0.60 to 0.68 has them)."""
    # the one registry module that also gives cached machine code symbols: string hashing's
    # secrets (``_numba_hashsecret_*``), which a kernel hashing str or bytes links to
    importlib.import_module("numba.cpython.hashing")
    from numba.core.runtime import rtsys
    cache = caching.Cache
    if getattr(cache.load_overload, "without_registries", False) or not all(
            hasattr(cache, m) for m in ("_guard_against_spurious_io_errors", "_load_overload")):
        return

    def load_overload(self, sig, target_context):
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)
        # (None when the guard swallowed an I/O error, as numba's own method returns)

    load_overload.without_registries = True
    load_overload.__doc__ = cache.load_overload.__doc__
    cache.load_overload = load_overload
