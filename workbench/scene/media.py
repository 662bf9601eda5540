"""The media around a point: which transmissive solids hold it (the camera inside a glass)."""
from __future__ import annotations

import numpy as np

from . import model as m
from .kinds import containing, kind_of, world_bounds


def enclosing_media(scene: m.Scene, point) -> list[m.Material]:
    """Materials of the transmissive solids (``kt > 0``) whose inside holds ``point``,
    outermost first: the media stack of rays leaving it, e.g. the camera's primary rays inside
    a glass.  Inside is each kind's ``inside`` test (a mesh's generalised winding number, CSG
    by its boolean; sheets have none).  Nested solids are ordered by the volume of their world
    bounding boxes (a solid inside another has the smaller box)."""
    p = np.asarray(point, dtype=np.float64)
    found = []
    for o in scene.objects:
        if not kind_of(o).COMPOSITE and scene.materials[o.material].kt <= 0.0:
            continue  # (a mesh's winding number costs a pass over its triangles)
        name = containing(o, np.eye(4), p)
        if name is not None and scene.materials[name].kt > 0.0:
            lo, hi = world_bounds(o, np.eye(4))
            found.append((float(np.prod(hi - lo)), scene.materials[name]))
    return [mat for _, mat in sorted(found, key=lambda x: -x[0])]
