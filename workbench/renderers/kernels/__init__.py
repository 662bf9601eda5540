"""The kernel layer below the ray tracer, the path tracer and radiosity: the record layouts the
numba kernels take (:mod:`.layout`) and the dispatch specialised to the kinds a scene holds
(:mod:`.specialise`).  It imports the scene layer and no renderer."""
