"""Display modes ("Affichage" in the course) as a post-process on any linear ``(H, W, 3)`` image.

A frame buffer stores *encoded* values, so every mode works on the sRGB-encoded image
(:func:`workbench.core.imageio.srgb_encode`, which clips to [0, 1] and maps NaN to 0) and
returns the decoded, linear float32 image: the error of a mode against the 24-bit image is then
an ordinary linear RMSE/PSNR.

Modes
-----
``direct24``            3 x 8 bits (16.7 million colours).
``direct16-555``        3 x 5 bits (32 768 colours; the course's 16-bit mode). ``direct16`` = 555.
``direct16-565``        5:6:5 bits (65 536 colours; the extra bit goes to green, where the eye is
                        most sensitive).
``indexedN``            a colour look-up table (CLUT) of N = 2, 4, ..., 256 entries of 24 bits;
                        each pixel stores the index of the nearest entry (Euclidean distance in
                        encoded RGB).  Palette ``-mediancut`` (Heckbert 1982, default) or
                        ``-kmeans`` (Lloyd iterations started from the median-cut palette).
suffix ``-bayer``       ordered dithering with the 8 x 8 Bayer (1973) matrix: threshold added
                        per channel for direct modes, Knoll's pattern dithering for a CLUT
                        (:func:`knoll_ordered`).
suffix ``-fs``          error diffusion (Floyd & Steinberg 1976, weights 7, 3, 5, 1 / 16).

Examples: ``"direct24"``, ``"direct16-565-bayer"``, ``"indexed16-kmeans-fs"``, ``"indexed2"``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np

from .errors import WorkbenchError
from .imageio import srgb_decode, srgb_encode
from .memory import check_limit

PALETTES = ("median_cut", "kmeans")
DITHERS = ("none", "ordered", "floyd_steinberg")
_PALETTE_NAMES = {"mediancut": "median_cut", "median_cut": "median_cut", "kmeans": "kmeans"}
_DITHER_NAMES = {"bayer": "ordered", "ordered": "ordered", "fs": "floyd_steinberg",
                 "floyd_steinberg": "floyd_steinberg", "none": "none"}
_BITS = {"24": (8, 8, 8), "16": (5, 5, 5), "16-555": (5, 5, 5), "16-565": (5, 6, 5)}
_SYNTAX = ("direct24 | direct16[-555|-565] | indexedN[-mediancut|-kmeans] (N = 2, 4, ..., 256), "
           "each optionally followed by -bayer or -fs")
#: Lloyd iterations of the k-means palette, and pixels sampled (seeded) to fit it.
KMEANS_ITERATIONS = 12
KNOLL_CANDIDATES = 16
"""Palette colours mixed per pixel by the ordered dithering of an indexed mode (:func:`knoll_ordered`)."""
WORK_BYTES_PER_PIXEL = 192
"""Working memory per pixel of :func:`apply_display_mode` (six float64 RGB copies: the image,
its 24-bit encoding, the shown colours and the sRGB conversions' temporaries, with the
palette's or the dithering's indices), besides the input image."""
KNOLL_BYTES_PER_CANDIDATE = 48
"""Per pixel and candidate of :func:`knoll_ordered`: the candidate (float64 RGB), its luminance,
its rank (int64) and the accumulated error's update."""
KMEANS_SAMPLES = 32768


@dataclass(frozen=True)
class DisplayMode:
    """A parsed display mode; ``str(mode)`` is its canonical string."""

    kind: str                              # "direct" | "indexed"
    bits: tuple[int, int, int] = (8, 8, 8)  # direct: bits per channel
    entries: int = 0                       # indexed: CLUT size
    palette: str = "median_cut"            # indexed: "median_cut" | "kmeans"
    dither: str = "none"                   # "none" | "ordered" | "floyd_steinberg"

    def __str__(self) -> str:
        if self.kind == "direct":
            s = "direct24" if self.bits == (8, 8, 8) else "direct16-" + "".join(map(str, self.bits))
        else:
            s = f"indexed{self.entries}-" + {"median_cut": "mediancut", "kmeans": "kmeans"}[self.palette]
        return s + {"none": "", "ordered": "-bayer", "floyd_steinberg": "-fs"}[self.dither]


def parse_display_mode(text: str) -> DisplayMode:
    """Parse a mode string (see the module docstring); ``WorkbenchError`` on a bad one."""
    s = str(text).strip().lower()
    m = re.fullmatch(r"direct(24|16(?:-555|-565)?)(?:-(\w+))?", s)
    if m:
        mode, dither = DisplayMode("direct", bits=_BITS[m.group(1)]), m.group(2)
    else:
        m = re.fullmatch(r"indexed(\d+)(?:-(mediancut|median_cut|kmeans))?(?:-(\w+))?", s)
        if not m:
            raise WorkbenchError(f"unknown display mode {text!r}; expected {_SYNTAX}")
        mode = DisplayMode("indexed", entries=_entries(m.group(1), text),
                           palette=_PALETTE_NAMES[m.group(2) or "mediancut"])
        dither = m.group(3)
    if dither is None:
        return mode
    if dither not in _DITHER_NAMES:
        raise WorkbenchError(f"display mode {text!r}: unknown dithering {dither!r} "
                             "(expected bayer or fs)")
    return replace(mode, dither=_DITHER_NAMES[dither])


def _entries(n, text) -> int:
    n = int(n)
    if n < 2 or n > 256 or n & (n - 1):
        raise WorkbenchError(f"display mode {text!r}: a CLUT has 2, 4, 8, ..., 256 entries "
                             f"(1 to 8 bits per pixel), not {n}")
    return n


def display_mode(mode: str | DisplayMode = "direct24", *, entries: int | None = None,
                 palette: str | None = None, dither: str | None = None) -> DisplayMode:
    """A :class:`DisplayMode` from a mode string, optionally overridden field by field.

    ``display_mode("indexed", entries=16, palette="kmeans", dither="floyd_steinberg")`` equals
    ``parse_display_mode("indexed16-kmeans-fs")``; ``"indexed"`` alone needs ``entries``.
    """
    if isinstance(mode, DisplayMode):
        base = mode
    elif str(mode).strip().lower() == "indexed":
        if entries is None:
            raise WorkbenchError("display mode 'indexed' needs a number of CLUT entries")
        base = DisplayMode("indexed", entries=_entries(entries, "indexed"))
    else:
        base = parse_display_mode(mode)
    changes = {}
    if entries is not None or palette is not None:
        if base.kind != "indexed":
            raise WorkbenchError(f"CLUT entries and palette apply to indexed modes, not {base}")
        if entries is not None:
            changes["entries"] = _entries(entries, str(mode))
        if palette is not None:
            if palette not in PALETTES:
                raise WorkbenchError(f"unknown palette method {palette!r} (expected one of {PALETTES})")
            changes["palette"] = palette
    if dither is not None:
        if dither not in DITHERS:
            raise WorkbenchError(f"unknown dithering {dither!r} (expected one of {DITHERS})")
        changes["dither"] = dither
    return replace(base, **changes)


def estimate_display_bytes(height: int, width: int, mode: str | DisplayMode = "direct24") -> int:
    """Bytes :func:`apply_display_mode` allocates on an ``height x width`` image (an upper
    bound: :data:`WORK_BYTES_PER_PIXEL`, plus the candidates of an indexed mode's ordered
    dithering)."""
    spec = display_mode(mode)
    per_pixel = WORK_BYTES_PER_PIXEL
    if spec.kind == "indexed" and spec.dither == "ordered":
        per_pixel += KNOLL_CANDIDATES * KNOLL_BYTES_PER_CANDIDATE
    return int(height) * int(width) * per_pixel


def check_display_memory(height: int, width: int, mode: str | DisplayMode, max_memory=None) -> None:
    """Refuse (one line) before rendering or loading what showing an ``height x width`` image
    through ``mode`` beside its 24-bit reference would need above the memory limit: the image,
    the reference and the shown image (float32 RGB each), and the larger of the two modes'
    work (:func:`estimate_display_bytes`)."""
    work = max(estimate_display_bytes(height, width, "direct24"), estimate_display_bytes(height, width, mode))
    check_limit(3 * 12 * int(height) * int(width) + work,
                f"display mode {display_mode(mode)} on {int(width)}x{int(height)}", max_memory)


def apply_display_mode(image, mode: str | DisplayMode = "direct24", *, max_memory=None, **fields) -> np.ndarray:
    """Show a linear ``(H, W, 3)`` image through a display mode; returns linear float32 ``(H, W, 3)``.

    ``mode`` and ``fields`` as in :func:`display_mode`, e.g.
    ``apply_display_mode(img, "indexed", entries=16, palette="median_cut",
    dither="floyd_steinberg")`` or ``apply_display_mode(img, "indexed16-kmeans-fs")``.
    Deterministic (k-means samples pixels with a fixed seed).  The work is estimated
    (:func:`estimate_display_bytes`) and checked against the memory limit (``max_memory``, see
    :func:`workbench.core.memory.memory_limit`) first.
    """
    spec = display_mode(mode, **fields)
    shape = np.shape(image)
    if len(shape) != 3 or shape[-1] != 3 or shape[0] == 0 or shape[1] == 0:
        raise WorkbenchError(f"a display mode applies to an (H, W, 3) image, got shape {shape}")
    check_limit(estimate_display_bytes(shape[0], shape[1], spec), f"display mode {spec} on {shape[1]}x{shape[0]}",
                max_memory)
    img = np.asarray(image, dtype=np.float64)
    e = np.round(srgb_encode(img) * 255.0) / 255.0          # the 24-bit frame buffer
    if spec.kind == "direct":
        levels = np.array([2.0 ** b - 1.0 for b in spec.bits])
        shown = _show(e, np.zeros((0, 3)), levels, spec.dither)
    else:
        pal = build_palette(e.reshape(-1, 3), spec.entries, spec.palette)
        shown = _show(e, pal, np.zeros(3), spec.dither)
    return srgb_decode(shown).astype(np.float32)


def _show(e: np.ndarray, palette: np.ndarray, levels: np.ndarray, dither: str) -> np.ndarray:
    """Encoded ``(H, W, 3)`` -> nearest representable colours, with the chosen dithering."""
    if dither == "floyd_steinberg":
        from ._dither import floyd_steinberg
        return floyd_steinberg(np.ascontiguousarray(e), np.ascontiguousarray(palette), levels)
    h, w = e.shape[:2]
    if palette.shape[0] == 0:
        if dither == "ordered":
            t = np.tile(bayer_matrix(8), (h // 8 + 1, w // 8 + 1))[:h, :w, None]
            e = np.clip(e + (t - 0.5) / levels, 0.0, 1.0)
        return np.round(e * levels) / levels
    flat = e.reshape(-1, 3)
    if dither == "ordered":
        t = np.tile(bayer_matrix(8), (h // 8 + 1, w // 8 + 1))[:h, :w].ravel()
        return knoll_ordered(flat, palette, t, KNOLL_CANDIDATES).reshape(e.shape)
    return palette[nearest(flat, palette)].reshape(e.shape)


def knoll_ordered(colors: np.ndarray, palette: np.ndarray, thresholds: np.ndarray,
                  candidates: int = 16) -> np.ndarray:
    """Ordered dithering with an arbitrary palette (Knoll's pattern dithering, US patent
    6 606 166, 1999): ``(N, 3)`` colours, ``(N,)`` Bayer thresholds in (0, 1) -> ``(N, 3)``.

    For each pixel, ``candidates`` palette colours are chosen one after the other as the nearest
    entry to the target plus the error accumulated so far, so that their mean approaches the
    target; they are sorted by luminance and the Bayer threshold picks one.  Over a Bayer tile
    the pixels thus show the candidates in equal shares, and the local mean colour follows the
    target even where no single entry is close.  (Adding the threshold to the colour, as done
    for direct modes, only works on a regular grid of levels.)
    """
    from scipy.spatial import cKDTree

    from .color import LUMINANCE_WEIGHTS
    tree = cKDTree(palette)
    err = np.zeros_like(colors)
    picks = np.empty((candidates,) + colors.shape)
    for i in range(candidates):
        picks[i] = palette[tree.query(colors + err)[1]]
        err += colors - picks[i]
    order = np.argsort(picks @ LUMINANCE_WEIGHTS, axis=0, kind="stable")
    which = np.minimum((thresholds * candidates).astype(int), candidates - 1)
    chosen = np.take_along_axis(order, which[None], axis=0)[0]
    return picks[chosen, np.arange(len(colors))]


def bayer_matrix(n: int) -> np.ndarray:
    """Bayer (1973) ordered-dither thresholds ``(n, n)`` in (0, 1), n a power of two.

    Recursive construction ``M_2n = [[4M, 4M + 2], [4M + 3, 4M + 1]]``, thresholds
    ``(M + 0.5) / n^2``.
    """
    m = np.zeros((1, 1))
    while m.shape[0] < n:
        m = np.block([[4 * m, 4 * m + 2], [4 * m + 3, 4 * m + 1]])
    return (m + 0.5) / m.size


def nearest(colors: np.ndarray, palette: np.ndarray) -> np.ndarray:
    """Index ``(N,)`` of the nearest palette entry ``(K, 3)`` to each colour ``(N, 3)`` (Euclidean)."""
    from scipy.spatial import cKDTree
    return cKDTree(palette).query(colors)[1]


def build_palette(colors: np.ndarray, entries: int, method: str = "median_cut") -> np.ndarray:
    """CLUT ``(K, 3)``, K <= entries, for encoded colours ``(N, 3)`` in [0, 1], entries rounded
    to 8 bits (a CLUT entry holds a 24-bit colour).  Fewer entries when the image has fewer
    distinct colours."""
    if method not in PALETTES:
        raise WorkbenchError(f"unknown palette method {method!r} (expected one of {PALETTES})")
    pal = median_cut(colors, entries)
    if method == "kmeans":
        pal = kmeans(colors, pal)
    return np.unique(np.round(pal * 255.0) / 255.0, axis=0)


def median_cut(colors: np.ndarray, entries: int) -> np.ndarray:
    """Median-cut palette (Heckbert 1982): ``(K, 3)`` box means, K <= entries.

    Start from one box holding every colour; repeatedly take the box whose longest side is the
    longest of all, and cut it at the median of its colours along that side; the palette is the
    mean colour of each box (so it is weighted by pixel counts).
    """
    def side(b):
        return np.ptp(b, axis=0) if len(b) > 1 else np.zeros(3)

    boxes = [np.asarray(colors, dtype=np.float64)]
    sides = [side(boxes[0])]
    while len(boxes) < entries:
        i = int(np.argmax([sd.max() for sd in sides]))
        if sides[i].max() <= 0.0:
            break                                   # every box holds one colour
        box, axis = boxes.pop(i), int(np.argmax(sides.pop(i)))
        order = np.argsort(box[:, axis], kind="stable")
        half = len(box) // 2
        for part in (box[order[:half]], box[order[half:]]):
            boxes.append(part)
            sides.append(side(part))
    return np.array([b.mean(axis=0) for b in boxes])


def kmeans(colors: np.ndarray, initial: np.ndarray) -> np.ndarray:
    """k-means palette (Lloyd 1982) ``(K, 3)`` started from ``initial``.

    Fitted on at most :data:`KMEANS_SAMPLES` colours drawn with a fixed seed, for
    :data:`KMEANS_ITERATIONS` iterations or until no centre moves by more than half an 8-bit
    step; an empty cluster keeps its centre.
    """
    x = np.asarray(colors, dtype=np.float64)
    if len(x) > KMEANS_SAMPLES:
        x = x[np.random.default_rng(0).choice(len(x), KMEANS_SAMPLES, replace=False)]
    c = np.array(initial, dtype=np.float64)
    for _ in range(KMEANS_ITERATIONS):
        lab = nearest(x, c)
        counts = np.bincount(lab, minlength=len(c))
        sums = np.stack([np.bincount(lab, weights=x[:, k], minlength=len(c)) for k in range(3)], -1)
        new = np.where(counts[:, None] > 0, sums / np.maximum(counts, 1)[:, None], c)
        moved = np.abs(new - c).max()
        c = new
        if moved < 0.5 / 255.0:
            break
    return c
