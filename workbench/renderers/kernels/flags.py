"""Compile options shared by the numba kernels.

Numba gives a function compiled without an explicit ``forceinline`` the setting of the function
being compiled when it is first called (numba's ``inherit_if_not_set``): a kernel first reached
from an :data:`INLINE` helper would be marked ``alwaysinline`` too, and so would everything it
calls in turn.  So every option set here states ``forceinline``."""
from __future__ import annotations

from ...core.jit_options import INTERNAL

FAST_MATH = {"nsz", "arcp"}
"""The fast-math flags of the hot kernels: signed zeros may be ignored, a division may become a
multiplication by a reciprocal.  Not ``nnan``/``ninf``: misses are ``inf`` and the tests look
for NaN, so the compiler may not assume either away.  Not ``contract``: a fused multiply-add
breaks the watertight triangle test (the two triangles of a shared edge must round its edge
function the same way, or a ray through the edge misses both)."""
NO_REFCOUNT = dict(cache=True, error_model="numpy", _nrt=False, fastmath=FAST_MATH, forceinline=False)
"""Options of the kernels that allocate nothing: compiled without numba's reference counting
(no atomic increments and decrements of every array they touch, which cost the fused kernel
40 % of its time); the arrays they use belong to their (reference-counted) callers.  Each is a
function of its own (``forceinline=False``, stated so that it does not take an inlined caller's
setting): the drivers, and the kernels of the rarely used kinds and CSG below the gates.  Numba
links a callee's whole module, with everything it calls, into each caller's module, where LLVM
optimises it and generates its machine code again; inlined, these kernels would be copied into
each call site, and the copies compiled again at each level above (the path tracer's
``trace_path`` would be one function holding every kind's code)."""
TASK = dict(NO_REFCOUNT, nogil=True)
"""Options of the drivers that :func:`.tasks.run_tasks` runs on Python threads: :data:`NO_REFCOUNT`
and the GIL released.  Such a driver is handed its scratch arrays by its caller, and walks its
pixel blocks itself: one compiled level fewer between the thread and the per-ray kernels (each
level links and compiles again the whole module below it)."""
INLINE = dict(NO_REFCOUNT, forceinline=True, **INTERNAL)
"""Options of the small helpers: compiled once per signature (and cached) as functions of their
own, marked ``alwaysinline`` for LLVM, which inlines them into every caller when it links the
caller's module.  Numba's own ``inline="always"`` copies a helper's IR into each caller and types
it again there, which cost several times the machine-code generation it saves.  They are also
the options of the hot steps of every ray that are not small (the two tree walks and the gates
that reach them, the polygon and quadric tests): a call passes the geometry's arrays one by one,
which costs the common scenes more than the machine code their inlining adds.  A kernel such a
helper calls must state ``forceinline=False`` (:data:`NO_REFCOUNT`, :data:`GATE`), or numba
compiles it inlined too (see the module docstring)."""
GATE = dict(error_model="numpy", _nrt=False, fastmath=FAST_MATH, forceinline=False, **INTERNAL)
"""Options of the kind gates (``@overload`` implementations in :mod:`.specialise` and
``csg_gate`` in :mod:`.intersect`): ordinary calls, not inlined, so that a scene's rarely used
kinds stay out of its hot loops and their code is not copied into every caller.
``forceinline=False`` is stated because the gates are compiled when an :data:`INLINE` helper
calling them is typed: left unset, they and the kinds' kernels they call would take that
helper's setting.  (The gates of the two tree walks take :data:`INLINE`: every ray of a scene
that has the tree goes through them.)"""

