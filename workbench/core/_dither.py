"""Floyd-Steinberg error diffusion (numba kernel; ``floyd_steinberg.py_func`` is the same code run
by the Python interpreter, the readable reference the tests compare it with)."""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def floyd_steinberg(e, palette, levels):
    """Error diffusion (Floyd & Steinberg 1976) of an encoded image.

    Parameters
    ----------
    e : (H, W, 3) float64 in [0, 1]
        Encoded image.
    palette : (K, 3) float64
        CLUT; when K = 0 the colours are instead rounded per channel to ``levels``.
    levels : (3,) float64
        Direct modes: ``2^bits - 1`` per channel (unused when K > 0).

    Returns
    -------
    (H, W, 3) float64
        The displayed colours.  Raster order; the quantisation error of a pixel goes 7/16 to
        the right, 3/16 below left, 5/16 below, 1/16 below right.  The value quantised (pixel
        plus diffused error) is clipped to [0, 1], which keeps the error bounded when the
        palette does not span the image's colours.
    """
    h, w = e.shape[0], e.shape[1]
    work = e.copy()
    out = np.empty_like(e)
    k = palette.shape[0]
    want = np.empty(3)
    got = np.empty(3)
    for y in range(h):
        for x in range(w):
            for c in range(3):
                want[c] = min(max(work[y, x, c], 0.0), 1.0)
            if k == 0:
                for c in range(3):
                    got[c] = np.floor(want[c] * levels[c] + 0.5) / levels[c]
            else:
                best, best_d = 0, np.inf
                for j in range(k):
                    d = 0.0
                    for c in range(3):
                        d += (palette[j, c] - want[c]) ** 2
                    if d < best_d:
                        best, best_d = j, d
                for c in range(3):
                    got[c] = palette[best, c]
            for c in range(3):
                out[y, x, c] = got[c]
                err = want[c] - got[c]
                if x + 1 < w:
                    work[y, x + 1, c] += err * (7.0 / 16.0)
                if y + 1 < h:
                    if x > 0:
                        work[y + 1, x - 1, c] += err * (3.0 / 16.0)
                    work[y + 1, x, c] += err * (5.0 / 16.0)
                    if x + 1 < w:
                        work[y + 1, x + 1, c] += err * (1.0 / 16.0)
    return out
