"""The primitive-table row of a kind with variable-length data (blob, isosurface, lathe, prism):
its numbers go to the ray tracer's flat ``aux`` array, whose offset heads its parameter row
(each such kind's ``Par`` starts with ``OFFSET = AUX_OFFSET``)."""
from __future__ import annotations

import numpy as np

AUX_OFFSET = 0
"""The column of such a kind's ``par`` that holds the offset of its numbers in ``aux``."""
MEDIUM_BOUND = 1
"""The column of a medium kind's ``par`` (the hypertexture, the fur) holding the radius of its
bounding sphere, which :mod:`.medium_sphere` intersects for all of them."""


def flatten_aux(b, obj, index: int, W: np.ndarray, top: bool, ptype: int,
                params: tuple[np.ndarray, np.ndarray], solid: bool) -> int:
    """The registry's ``flatten`` for such a kind, through the builder ``b``: ``b.add_aux``
    its ``params[1]`` (returns the offset, written into ``params[0][AUX_OFFSET]``), ``b.add`` the row
    with the head ``params[0]``."""
    head, data = params
    head[AUX_OFFSET] = b.add_aux(data)
    return b.add(ptype, index, obj, W, head, top=top, solid=solid)
