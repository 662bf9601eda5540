"""The panels' linear images, read back from the GPU only when someone looks at the pixels.

A raster panel lives on the GPU (see :mod:`.panel_refresh` and :mod:`.panel_gpu`): after each draw its entry here is made
*pending*, a function that reads the float framebuffer back.  The first access (pixel probe,
difference view, export, a test script) calls it once and keeps the array until the panel is
drawn again, so a frame in which nothing asks for pixels reads nothing back.  The pixel probe
asks for one pixel per panel (:meth:`PanelImages.pixel`): a pending entry with a pixel reader
answers from the GPU without reading its whole image (a probe under the mouse during a camera
drag otherwise read every panel back every frame).

``version(key)`` grows with every change of an entry: the cache key of everything derived from
an image (its display texture, the difference view).
"""
from __future__ import annotations

from collections.abc import Callable, Iterator, MutableMapping

import numpy as np


class PanelImages(MutableMapping):
    """``{name: (H, W, 3) float32 linear image}`` whose entries may be pending reads.

    Attributes
    ----------
    reads : number of pending entries resolved so far (GPU read-backs of whole images).
    pixel_reads : number of single pixels read from pending entries.
    """

    def __init__(self):
        self._values: dict[str, np.ndarray] = {}
        self._pending: dict[str, Callable[[], np.ndarray]] = {}
        self._pixel: dict[str, Callable] = {}
        self._shapes: dict[str, tuple | None] = {}
        self._versions: dict[str, int] = {}
        self.reads = 0
        self.pixel_reads = 0

    def __getitem__(self, key: str) -> np.ndarray:
        read = self._pending.pop(key, None)
        self._pixel.pop(key, None)
        if read is not None:
            self._values[key] = read()
            self.reads += 1
        return self._values[key]

    def __setitem__(self, key: str, image: np.ndarray) -> None:
        self._pending.pop(key, None)
        self._pixel.pop(key, None)
        self._values[key] = image
        self._bump(key)

    def set_pending(self, key: str, read: Callable[[], np.ndarray],
                    pixel: Callable | None = None, shape: tuple[int, int] | None = None) -> None:
        """Replace ``key`` by an image that ``read()`` produces on first access;
        ``pixel(i, j, shape)``, if given, reads one of its pixels (see :meth:`pixel`) meanwhile;
        ``shape`` is the image's (H, W) (:meth:`has_shape`)."""
        self._values.pop(key, None)
        self._pending[key] = read
        self._shapes[key] = None if shape is None else tuple(shape)
        self._pixel.pop(key, None)
        if pixel is not None:
            self._pixel[key] = pixel
        self._bump(key)

    def pixel(self, key: str, i: int, j: int, shape: tuple[int, int]) -> np.ndarray | None:
        """The value at row ``i``, column ``j`` of ``key``'s image if that image is ``shape``
        (H, W), else None.  A pending entry with a pixel reader stays pending."""
        read = self._pixel.get(key) if key in self._pending else None
        if read is not None:
            self.pixel_reads += 1
            return read(i, j, shape)
        image = self[key]
        return image[i, j] if image.shape[:2] == tuple(shape) else None

    def has_shape(self, key: str, shape: tuple[int, int]) -> bool:
        """``key``'s image is (H, W) = ``shape``, without reading a pending entry (its size is
        the one given to :meth:`set_pending`)."""
        if key in self._pending:
            return self._shapes.get(key) == tuple(shape)
        return self._values[key].shape[:2] == tuple(shape)

    def __delitem__(self, key: str) -> None:
        if key not in self:
            raise KeyError(key)
        self._values.pop(key, None)
        self._pending.pop(key, None)
        self._pixel.pop(key, None)
        self._bump(key)

    def __contains__(self, key) -> bool:  # without reading a pending entry
        return key in self._values or key in self._pending

    def __iter__(self) -> Iterator[str]:
        return iter([*self._values, *self._pending])

    def __len__(self) -> int:
        return len(self._values) + len(self._pending)

    def nbytes(self, key: str | None = None) -> int:
        """Bytes of ``key``'s image held on the CPU (every entry's with no key; a pending entry
        holds none: its image is on the GPU)."""
        keys = self._values if key is None else [key] if key in self._values else []
        return sum(self._values[k].nbytes for k in keys)

    def version(self, key: str) -> int:
        """Number of changes of ``key`` so far (0 if never set)."""
        return self._versions.get(key, 0)

    def _bump(self, key: str) -> None:
        self._versions[key] = self._versions.get(key, 0) + 1
