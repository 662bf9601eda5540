"""The colour scale of error maps (the difference panel, its export, the patch view's form
factors): black through red and yellow to white."""
from __future__ import annotations

import numpy as np

HOT = np.array([[0, 0, 0], [0.5, 0, 0], [1, 0.3, 0], [1, 0.9, 0], [1, 1, 1]], np.float32)
"""Colour scale of the difference panel, from 0 (black) to the maximum (white)."""


def hot_table(n: int = 256) -> np.ndarray:
    """(n, 3) uint8 colours of :data:`HOT`, piecewise linear from 0 to 1."""
    t = np.linspace(0.0, 1.0, n) * (len(HOT) - 1)
    i = np.minimum(t.astype(int), len(HOT) - 2)
    f = (t - i)[:, None]
    return ((HOT[i] * (1 - f) + HOT[i + 1] * f) * 255 + 0.5).astype(np.uint8)


def colour_scale(values: np.ndarray, vmax: float) -> np.ndarray:
    """(H, W) values in [0, vmax] -> (H, W, 3) uint8 colours of :data:`HOT` (display space)."""
    table = hot_table()
    idx = (np.clip(values * (1.0 / vmax if vmax > 0 else 0.0), 0.0, 1.0) * (len(table) - 1))
    return table[idx.astype(np.intp)]
