"""What the X server shows of the window: ``xwd`` (x11-apps) dumps it, :func:`read_xwd` decodes
the dump (X Window Dump format, version 7: a header of big-endian 32-bit fields, the window's
name, a colour map, then the pixels in the image's byte order).

Unlike ``hello_imgui.final_app_window_screenshot`` (the GL back buffer read by the process
itself) this is the picture a user has on screen, taken from outside the process; the UI tests
check it (tests/app/ui/test_ui_screens.py) and the README's screenshot is one.
"""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

HEADER_FIELDS = ("header_size", "file_version", "pixmap_format", "pixmap_depth", "pixmap_width",
                 "pixmap_height", "xoffset", "byte_order", "bitmap_unit", "bitmap_bit_order",
                 "bitmap_pad", "bits_per_pixel", "bytes_per_line", "visual_class", "red_mask",
                 "green_mask", "blue_mask", "bits_per_rgb", "colormap_entries", "ncolors",
                 "window_width", "window_height", "window_x", "window_y", "window_bdrwidth")
"""The XWD header's 25 CARD32 fields in file order (X11's XWDFile.h)."""
ZPIXMAP = 2
COLOR_ENTRY_BYTES = 12


def read_xwd(data: bytes) -> np.ndarray:
    """(H, W, 3) uint8 RGB of an XWD dump of a TrueColor window (24 or 32 bits per pixel);
    ValueError for any other kind."""
    if len(data) < 4 * len(HEADER_FIELDS):
        raise ValueError("not an XWD dump: shorter than its header")
    head = dict(zip(HEADER_FIELDS, np.frombuffer(data[:100], ">u4").tolist()))
    if head["file_version"] != 7 or head["pixmap_format"] != ZPIXMAP:
        raise ValueError(f"XWD version {head['file_version']}, format {head['pixmap_format']}: "
                         "only version 7 ZPixmap dumps are read")
    bpp = head["bits_per_pixel"]
    if bpp not in (24, 32):
        raise ValueError(f"XWD with {bpp} bits per pixel: only 24 or 32 are read")
    w, h, stride = head["pixmap_width"], head["pixmap_height"], head["bytes_per_line"]
    start = head["header_size"] + head["ncolors"] * COLOR_ENTRY_BYTES
    if len(data) < start + stride * h:
        raise ValueError("XWD dump cut short")
    rows = np.frombuffer(data, np.uint8, count=stride * h, offset=start).reshape(h, stride)
    step = bpp // 8
    px = rows[:, :w * step].reshape(h, w, step).astype(np.uint32)
    order = range(step) if head["byte_order"] == 0 else range(step - 1, -1, -1)  # LSB first: 0
    value = sum(px[..., i] << np.uint32(8 * k) for k, i in enumerate(order))
    out = np.empty((h, w, 3), np.uint8)
    for c, name in enumerate(("red_mask", "green_mask", "blue_mask")):
        mask = head[name]
        if mask == 0:
            raise ValueError("XWD dump without colour masks (not TrueColor)")
        shift = (mask & -mask).bit_length() - 1
        top = mask >> shift
        out[..., c] = ((value & np.uint32(mask)) >> np.uint32(shift)) * 255 // top
    return out


def take(window_name: str, display: str | None = None) -> np.ndarray:
    """(H, W, 3) uint8: the window named ``window_name`` as the X server shows it now
    (``xwd -name``); RuntimeError if xwd is missing or fails."""
    xwd = shutil.which("xwd")
    if xwd is None:
        raise RuntimeError("xwd not found (Debian package x11-apps; workbench.sh installs it)")
    env = dict(os.environ)
    if display:
        env["DISPLAY"] = display
    p = subprocess.run([xwd, "-silent", "-name", window_name], env=env, capture_output=True,
                       timeout=60)
    if p.returncode != 0:
        raise RuntimeError(f"xwd failed: {p.stderr.decode(errors='replace').strip()}")
    return read_xwd(p.stdout)


def save(window_name: str, path: Path) -> np.ndarray:
    """:func:`take` saved as a PNG at ``path``; returns the pixels."""
    from ...core.imageio import save_png8
    shot = take(window_name)
    save_png8(path, shot)
    return shot
