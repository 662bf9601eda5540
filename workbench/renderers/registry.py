"""Where each registered method lives, as ``"module:attribute"`` strings, so that a renderer's
heavy imports (moderngl, numba, pyrender) happen only when it is used (Mitsuba's plugins by name).

Only methods that exist are listed here: a method that is not implemented is absent.
"""

BUILTIN: dict[str, str] = {
    "flat": "workbench.renderers.raster:FlatRenderer",
    "gouraud": "workbench.renderers.raster:GouraudRenderer",
    "phong": "workbench.renderers.raster:PhongRenderer",
    "pyrender": "workbench.renderers.reference:PyrenderRenderer",
    "raycast": "workbench.renderers.raytrace.whitted:RaycastRenderer",
    "raytrace": "workbench.renderers.raytrace.whitted:RaytraceRenderer",
    "radiosity": "workbench.renderers.radiosity.method:RadiosityRenderer",
    "hybrid": "workbench.renderers.radiosity.hybrid:HybridRenderer",
    "pathtrace": "workbench.renderers.pathtrace.method:PathTraceRenderer",
}
