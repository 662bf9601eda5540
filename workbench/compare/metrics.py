"""Image error metrics on linear images (same size, (H, W, 3) float).

* RMSE on linear RGB values clipped to the display range [0, 1].  Unclipped, a few pixels on
  the edge of an emitter (radiance ~20 in the Cornell box) that two methods sample differently
  outweigh every other pixel of the image; the unclipped value is kept as ``rmse_hdr``.
* PSNR = 20 log10(peak / RMSE) with ``peak = 1`` (display white in linear units); an exact
  match gives ``inf`` in the dictionary (JSON writers turn it into a string).
* FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"), LDR, via
  the ``flip-evaluator`` package, on the sRGB-encoded images clipped to [0, 1] (what is shown):
  mean FLIP in [0, 1] and a per-pixel map.  FLIP is the perceptual metric of the workbench.
"""
from __future__ import annotations

import numpy as np

from ..core.errors import WorkbenchError
from ..core.imageio import srgb_encode


def _check_pair(image, reference) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(image, dtype=np.float64)
    b = np.asarray(reference, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 3 or a.shape[-1] != 3:
        raise WorkbenchError(f"metrics need two (H, W, 3) images of the same size, got {a.shape} and {b.shape}")
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise WorkbenchError("metrics need finite images (an image holds NaN or Inf)")
    return a, b


def flip(image, reference) -> tuple[float, np.ndarray]:
    """Mean FLIP error and the (H, W) FLIP map (LDR, sRGB-encoded inputs)."""
    import flip_evaluator
    a, b = _check_pair(image, reference)
    ref8 = srgb_encode(b).astype(np.float32)
    test8 = srgb_encode(a).astype(np.float32)
    fmap, mean, _ = flip_evaluator.evaluate(ref8, test8, "LDR", inputsRGB=True, applyMagma=False)
    fmap = np.asarray(fmap, dtype=np.float64)
    if fmap.ndim == 3:
        fmap = fmap[..., 0]
    return float(mean), fmap


def metrics(image, reference) -> dict[str, float]:
    """``{"rmse", "psnr", "flip", "rmse_hdr"}`` of ``image`` against ``reference`` (linear
    (H, W, 3)): RMSE and PSNR in the display range [0, 1], FLIP (LDR), and the RMSE of the
    unclipped values."""
    return metrics_and_maps(image, reference)[0]


def metrics_and_maps(image, reference) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """:func:`metrics` and the (H, W) error maps ``{"flip", "abs"}`` of :func:`error_map`,
    with FLIP evaluated once for both (it dominates the cost)."""
    a, b = _check_pair(image, reference)
    ca, cb = np.clip(a, 0.0, 1.0), np.clip(b, 0.0, 1.0)
    rmse = float(np.sqrt(np.mean((ca - cb) ** 2)))
    psnr = float("inf") if rmse == 0.0 else float(20.0 * np.log10(1.0 / rmse))
    mean_flip, flip_map = flip(a, b)
    values = {"rmse": rmse, "psnr": psnr, "flip": mean_flip,
              "rmse_hdr": float(np.sqrt(np.mean((a - b) ** 2)))}
    return values, {"flip": flip_map, "abs": np.abs(ca - cb).mean(-1)}


def error_map(image, reference, kind: str = "abs") -> np.ndarray:
    """Per-pixel error (H, W): ``"abs"`` (mean absolute difference over RGB of the linear values
    clipped to [0, 1], as RMSE) or ``"flip"``."""
    a, b = _check_pair(image, reference)
    if kind == "abs":
        return np.abs(np.clip(a, 0.0, 1.0) - np.clip(b, 0.0, 1.0)).mean(-1)
    if kind == "flip":
        return flip(a, b)[1]
    raise WorkbenchError(f"unknown error map kind {kind!r} (expected 'abs' or 'flip')")
