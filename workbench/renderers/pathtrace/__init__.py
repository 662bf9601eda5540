"""Path tracing (``pathtrace``): unbiased Monte Carlo solution of the rendering equation
(Kajiya 1986) on the ray tracer's scene arrays, BVH and intersection kernels.

Modules: :mod:`.emitters` (the emitter triangles sampled by next-event estimation),
:mod:`.kernels` (numba: the estimator), :mod:`.session` (:class:`PathTraceSession`:
progressive accumulation, the noise estimate), :mod:`.method` (the registered renderer) and
:mod:`.reference` (the same estimator, readable, one path at a time; tested against the kernel).
"""
