"""Image files: sRGB encoding happens here and only here (images in memory are linear)."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np


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


def atomic_write_text(path, text: str) -> Path:
    """Write a text file atomically (same rules as the images)."""
    _atomic_write(Path(path), lambda t: Path(t).write_text(text))
    return Path(path)


def atomic_write_bytes(path, data: bytes) -> Path:
    """Write a binary file atomically (same rules as the images)."""
    _atomic_write(Path(path), lambda t: Path(t).write_bytes(data))
    return Path(path)


def _atomic_write(path: Path, write):
    """Write through a temporary file in the same folder, then rename: never a half-written file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=path.suffix)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    try:
        write(tmp)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file the usual mode
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def save_png(path, linear: np.ndarray) -> Path:
    """Save a linear (H, W, 3) image as an sRGB PNG, atomically."""
    from PIL import Image
    img = Image.fromarray(to_srgb8(linear))
    _atomic_write(Path(path), lambda t: img.save(t, format="PNG"))
    return Path(path)


def save_png8(path, rgb8: np.ndarray) -> Path:
    """Save an already-encoded (H, W, 3|4) uint8 image (plots, grids, heat maps), atomically."""
    from PIL import Image
    img = Image.fromarray(np.asarray(rgb8, dtype=np.uint8))
    _atomic_write(Path(path), lambda t: img.save(t, format="PNG"))
    return Path(path)


def save_npy(path, array: np.ndarray) -> Path:
    """Save linear data (float32) for exact comparison, atomically."""
    def write(tmp):
        with open(tmp, "wb") as f:  # a file object: np.save would append ".npy" to a name
            np.save(f, np.asarray(array, dtype=np.float32))
    _atomic_write(Path(path), write)
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
