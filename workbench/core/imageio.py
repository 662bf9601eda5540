"""Image files: sRGB encoding happens here and only here (images in memory are linear)."""
from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from .output_paths import write_together


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1 transfer function on linear values clipped to [0, 1]."""
    x = np.clip(np.nan_to_num(linear, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def srgb_decode(encoded: np.ndarray) -> np.ndarray:
    """Inverse of :func:`srgb_encode` (values in [0, 1])."""
    x = np.asarray(encoded, dtype=np.float64)
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def to_srgb8(linear: np.ndarray) -> np.ndarray:
    """(H, W, 3) linear float -> (H, W, 3) uint8 sRGB."""
    return (srgb_encode(linear) * 255.0 + 0.5).astype(np.uint8)


def text_writer(text: str) -> Callable[[str], None]:
    """A writer of ``text`` for :func:`.output_paths.write_together`."""
    return lambda tmp: Path(tmp).write_text(text)


def png_writer(linear: np.ndarray) -> Callable[[str], None]:
    """A writer of a linear (H, W, 3) image as an sRGB PNG (see :func:`save_png`)."""
    return png8_writer(to_srgb8(linear))


def png8_writer(rgb8: np.ndarray) -> Callable[[str], None]:
    """A writer of an already-encoded (H, W, 3|4) uint8 image."""
    from PIL import Image
    img = Image.fromarray(np.asarray(rgb8, dtype=np.uint8))
    return lambda tmp: img.save(tmp, format="PNG")


def npy_writer(array: np.ndarray) -> Callable[[str], None]:
    """A writer of linear data as float32 ``.npy`` (exact comparison)."""
    def write(tmp):
        with open(tmp, "wb") as f:  # a file object: np.save would append ".npy" to a name
            np.save(f, np.asarray(array, dtype=np.float32))
    return write


def atomic_write_text(path, text: str) -> Path:
    """Write a text file atomically (temporary file, then rename: never a half-written file)."""
    write_together([(path, text_writer(text))])
    return Path(path)


def atomic_write_bytes(path, data: bytes) -> Path:
    """Write a binary file atomically (through :func:`.output_paths.write_together`)."""
    write_together([(path, lambda tmp: Path(tmp).write_bytes(data))])
    return Path(path)


def save_png(path, linear: np.ndarray) -> Path:
    """Save a linear (H, W, 3) image as an sRGB PNG, atomically."""
    write_together([(path, png_writer(linear))])
    return Path(path)


def save_png8(path, rgb8: np.ndarray) -> Path:
    """Save an already-encoded (H, W, 3|4) uint8 image (plots, grids, heat maps), atomically."""
    write_together([(path, png8_writer(rgb8))])
    return Path(path)


def save_npy(path, array: np.ndarray) -> Path:
    """Save linear data (float32) for exact comparison, atomically."""
    write_together([(path, npy_writer(array))])
    return Path(path)


def load_image_linear(path, data: bool = False) -> np.ndarray:
    """Read an 8-bit image file as float32 RGBA (H, W, 4): colours sRGB-decoded to linear, alpha
    kept as stored; with ``data`` (height and opacity maps, which hold values, not colours) every
    channel is taken as stored, ``v / 255``."""
    from PIL import Image
    with Image.open(path) as im:
        a = np.asarray(im.convert("RGBA"), dtype=np.float64) / 255.0
    if not data:
        a[..., :3] = srgb_decode(a[..., :3])
    return a.astype(np.float32)
