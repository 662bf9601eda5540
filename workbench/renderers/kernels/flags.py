"""Compile options shared by the numba kernels."""
from __future__ import annotations

FAST_MATH = {"nsz", "arcp"}
"""The fast-math flags of the hot kernels: signed zeros may be ignored, a division may become a
multiplication by a reciprocal.  Not ``nnan``/``ninf``: misses are ``inf`` and the tests look
for NaN, so the compiler may not assume either away.  Not ``contract``: a fused multiply-add
breaks the watertight triangle test (the two triangles of a shared edge must round its edge
function the same way, or a ray through the edge misses both)."""
NO_REFCOUNT = dict(cache=True, error_model="numpy", _nrt=False, fastmath=FAST_MATH)
"""Options of the kernels that allocate nothing: compiled without numba's reference counting
(no atomic increments and decrements of every array they touch, which cost the fused kernel
40 % of its time); the arrays they use belong to their (reference-counted) callers."""
INLINE = dict(NO_REFCOUNT, forceinline=True)
"""Options of the small helpers: compiled once per signature (and cached) as functions of their
own, marked ``alwaysinline`` for LLVM, which inlines them into every caller when it links the
caller's module.  Numba's own ``inline="always"`` copies a helper's IR into each caller and types
it again there, which cost several times the machine-code generation it saves."""
GATE = dict(error_model="numpy", _nrt=False, fastmath=FAST_MATH)
"""Options of the kind and feature gates (``@overload`` implementations in :mod:`.specialise`
and :mod:`.intersect`): ordinary calls, not inlined, so that a scene's rarely used kinds stay
out of its hot loops."""
