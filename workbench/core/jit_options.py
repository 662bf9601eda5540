"""Numba options and helpers shared by every layer's kernels (the scene's kinds and the
renderers'): :data:`INTERNAL` and :func:`python_twin`.  Importing this module does not import
numba."""
from __future__ import annotations

import types

INTERNAL = dict(no_cpython_wrapper=True, no_cfunc_wrapper=True)
"""Options of the kernels called from compiled code only (the renderers' ``flags.INLINE`` and
``flags.GATE``, the kinds' kernel modules): numba builds no CPython wrapper (the code that
unboxes each argument from a Python object: for the geometry record, its 29 arrays) nor
C-callable wrapper for them, and LLVM does not optimise and generate code for either
(``docs/kernels.md``).  Such a kernel called from Python would jump to an entry point that does
not exist (a crash, not an exception): tests and benches call one through :func:`python_twin`,
and ``tests/project/test_internal_kernels.py`` looks for Python calls of them."""

TWIN_SUFFIX = "__python_twin"
"""Added to a twin's qualified name: the name numba's disk cache files the twin under."""


def python_twin(kernel):
    """A copy of the :data:`INTERNAL` kernel ``kernel`` (a numba dispatcher) callable from Python:
    the same code and options, with numba's wrappers.  The copy is a function of its own whose
    qualified name ends in :data:`TWIN_SUFFIX`, so that numba caches it on disk apart from the
    wrapper-less kernel (its cache index is keyed by the function's name and signature, not by
    the options: under the kernel's own name it would load the copy without wrappers); a kernel
    that passes a function by value (a dispatcher's address) cannot be cached, and numba says
    so.  For tests and benches that call a helper kernel directly."""
    import numba as nb
    f = kernel.py_func
    twin = types.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__, f.__closure__)
    twin.__qualname__ = f.__qualname__ + TWIN_SUFFIX
    twin.__module__, twin.__doc__ = f.__module__, f.__doc__
    # (numba keeps ``cache`` out of ``targetoptions``: stated here)
    options = {k: v for k, v in kernel.targetoptions.items() if k not in INTERNAL and k != "nopython"}
    return nb.njit(**options, cache=True)(twin)


def wrapperless(obj) -> bool:
    """Whether ``obj`` is a numba dispatcher compiled with :data:`INTERNAL` (not callable from
    Python)."""
    options = getattr(obj, "targetoptions", None)
    return isinstance(options, dict) and bool(options.get("no_cpython_wrapper")) and hasattr(obj, "py_func")
