"""Where each registered method lives, as ``"module:attribute"`` strings, so that a renderer's
heavy imports (moderngl, numba, pyrender) happen only when it is used (Mitsuba's plugins by name).

Only methods that exist are listed here: a method that is not implemented is absent.

``OPT_IN`` methods are registered (``workbench methods`` lists them, any command takes them by
name) but are left out of the default method lists of ``compare`` and ``study``: an outside
path-traced reference takes seconds to minutes per image and its knob reaches thousands of
samples per pixel, so it runs when named (``--methods ...,mitsuba``), not in every report.
"""

BUILTIN: dict[str, str] = {
    "flat": "workbench.renderers.raster:FlatRenderer",
    "gouraud": "workbench.renderers.raster:GouraudRenderer",
    "phong": "workbench.renderers.raster:PhongRenderer",
    "zbuffer": "workbench.renderers.zbuffer:ZBufferRenderer",
    "pyrender": "workbench.renderers.reference:PyrenderRenderer",
    "povray": "workbench.renderers.povray:PovrayRenderer",
    "raycast": "workbench.renderers.raytrace.whitted:RaycastRenderer",
    "raytrace": "workbench.renderers.raytrace.whitted:RaytraceRenderer",
    "radiosity": "workbench.renderers.radiosity.method:RadiosityRenderer",
    "hybrid": "workbench.renderers.radiosity.hybrid:HybridRenderer",
    "pathtrace": "workbench.renderers.pathtrace.method:PathTraceRenderer",
    "mitsuba": "workbench.renderers.mitsuba_method:MitsubaRenderer",
}

OPT_IN: frozenset[str] = frozenset({"mitsuba"})

USER_SHADING = "workbench.renderers.user_shading:renderer_from_path"
"""The factory of ``glsl:PATH`` methods (a user's shading model), loaded by name like the rest:
it is a raster renderer, and the raster imports :mod:`.base`."""
