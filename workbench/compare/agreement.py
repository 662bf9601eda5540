"""Agreement of two independent Monte Carlo estimates of the same image, each with its own
per-pixel noise estimate (the ground-truth check of ``pathtrace`` against ``mitsuba``).

Both images must follow one definition: each pixel the box-filtered average of the radiance
over its square, linear RGB, nothing clipped.  For two unbiased estimates ``a, b`` of that
image with per-pixel standard errors ``se_a, se_b`` (unbiased variance estimates with
``dof_a, dof_b`` degrees of freedom: ``N - 1`` for a pixel's sample variance of ``N`` samples,
1 for Mitsuba's two-pass estimate), the statistics are:

* **pixel ratio** ``R = sum (a - b)^2 / sum (se_a^2 + se_b^2)`` over pixels and channels.
  Its expectation is 1 (numerator and denominator are both unbiased for ``sum sigma^2``); a
  bias between the images raises it, noise estimates that are too large lower it.  Its
  standard deviation by the delta method, for Gaussian pixel means (``d ~ N(0, sigma^2)``, so
  ``Var d^2 = 2 sigma^4``; an estimate ``se^2`` with ``nu`` degrees of freedom has
  ``Var se^2 = 2 sigma^4 / nu`` and ``E se^4 = sigma^4 (nu + 2) / nu``):
  ``sd_R^2 = [2 sum s^4 + sum 2 se_a^4 / (dof_a + 2) + sum 2 se_b^4 / (dof_b + 2)] / (sum s^2)^2``
  with ``s^2 = se_a^2 + se_b^2`` (``s^4`` over-estimates ``sigma^4``: the bound is conservative).
  Agreement: ``|R - 1| <= 4 sd_R``.  ``n_eff = (sum s^2)^2 / sum s^4`` says how many pixels
  carry the sum: few where a handful of pixels (a light's edges, caustics) hold most of the
  variance, and then the bound is wide.
* **block chi-square**: per channel, the differences summed over ``block x block`` pixel
  blocks, ``z = sum d / sqrt(sum s^2)`` (a block's variance is estimated from many pixels, and
  its sum is near Gaussian); ``Q = mean z^2`` over blocks and channels.  Under agreement
  ``E Q = 1`` and ``sd Q <= sqrt(2 / K)`` for ``K`` blocks (the channels may be fully
  correlated: one path carries all three), so ``|Q - 1| <= 4 sqrt(2 / K)``.
* **fractions of |z| > 3**, per pixel (``z = d / s``: heavy-tailed when one side's noise
  estimate has one degree of freedom; the worst case, all the variance on a one-dof side, is
  Student's t with 1 dof: ``P(|t_1| > 3) = 0.205``; two equal one-dof sides: t with 2 dof,
  0.095; known variances: 0.0027) and per block (near-Gaussian: 0.0027).
* **mean radiance**: the relative difference of the means (summed over pixels and channels),
  with its standard error bounded by ``sqrt(sum_pixels (sum_c s_c)^2) / sum b`` (Cauchy-Schwarz:
  the channels of a pixel may be fully correlated, one path carries all three).

Values where both noise estimates are 0 (a light's interior seen directly, but also, by chance,
a pixel whose two Mitsuba passes drew the same number of samples off a light's edge: a
one-dof estimate of a discrete distribution is 0 with positive probability) count in the
ratio's numerator and the means, not in the z fractions; their number and largest difference
are reported.
"""
from __future__ import annotations

import math

import numpy as np

from ..core.errors import WorkbenchError
from ..scene import model as m

#: P(|t_1| > 3) for Student's t with 1 degree of freedom (Cauchy): the largest fraction of
#: pixel values with |z| > 3 two agreeing images give when one side's noise estimate has one
#: degree of freedom.
P_Z3_T1 = 1.0 - 2.0 * math.atan(3.0) / math.pi
#: Width of the acceptance bands in standard deviations.
BAND_SD = 4.0


def light_pixels(scene: m.Scene, width: int, height: int) -> np.ndarray:
    """(H, W) bool: the pixels the projected bounding boxes of the scene's area lights touch,
    grown by one pixel (the light seen directly: its interior is the emitted radiance on both
    sides, its edges the noisiest pixels of the image)."""
    cam = scene.camera.with_resolution(width, height)
    mask = np.zeros((height, width), bool)
    for light in scene.lights:
        if isinstance(light, m.AreaLight):
            xy, _ = cam.project(np.asarray(light.vertices, dtype=np.float64))
            lo = np.floor(xy.min(0)).astype(int) - 1
            hi = np.ceil(xy.max(0)).astype(int) + 1
            mask[max(lo[1], 0):max(hi[1], 0), max(lo[0], 0):max(hi[0], 0)] = True
    return mask


def _check(name, x, shape):
    x = np.asarray(x, dtype=np.float64)
    if x.shape != shape:
        raise WorkbenchError(f"agreement: {name} has shape {x.shape}, expected {shape}")
    if not np.isfinite(x).all():
        raise WorkbenchError(f"agreement: {name} holds non-finite values")
    return x


def _mean_part(a, b, s2, keep) -> dict:
    """Means of the kept pixels (per channel), relative difference and its standard error."""
    ak, bk = a[keep], b[keep]
    total = float(bk.sum())
    rel = float(ak.sum() / total - 1.0) if total > 0.0 else math.nan
    se = float(math.sqrt(float((np.sqrt(s2[keep]).sum(1) ** 2).sum())) / total) if total > 0.0 else math.nan
    return {"pixels": int(keep.sum()), "mean_a": ak.mean(0).tolist(), "mean_b": bk.mean(0).tolist(),
            "rel_diff": rel, "rel_diff_se": se}


def noise_agreement(a, se_a, dof_a: float, b, se_b, dof_b: float, *, block: int = 4,
                    exclude: np.ndarray | None = None, band_sd: float = BAND_SD) -> dict:
    """The statistics of the module docstring.

    Parameters
    ----------
    a, b : (H, W, 3) the two images (box-filtered pixel averages, linear, not clipped).
    se_a, se_b : (H, W, 3) their per-pixel standard errors.
    dof_a, dof_b : degrees of freedom of those estimates (>= 1).
    block : block edge in pixels for the block test (H and W are cut to multiples of it).
    exclude : (H, W) bool or None, pixels left out of the ``mean_off`` part (e.g.
        :func:`light_pixels`); every other statistic uses all pixels.
    band_sd : width of the ratio's and the block chi-square's acceptance bands in standard
        deviations (a caller with a false-failure budget derives it from a normal quantile).

    Returns
    -------
    dict with ``ratio, ratio_sd, ratio_ok, n_eff, frac_abs_z_gt_3`` (pixel level),
    ``block_count, block_chi2, block_chi2_band, block_chi2_ok, block_frac_abs_z_gt_3``,
    ``zero_noise_values, max_abs_diff_at_zero_noise``, and ``mean`` (all pixels) and
    ``mean_off`` (without ``exclude``), each ``{pixels, mean_a, mean_b, rel_diff, rel_diff_se}``.

    Raises
    ------
    WorkbenchError
        Shapes that differ, non-finite values, dof < 1, a block larger than the image.
    """
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 3 or a.shape[2] != 3:
        raise WorkbenchError(f"agreement: image a has shape {a.shape}, expected (H, W, 3)")
    shape = a.shape
    b, se_a, se_b = _check("image b", b, shape), _check("se_a", se_a, shape), _check("se_b", se_b, shape)
    a = _check("image a", a, shape)
    if not (dof_a >= 1 and dof_b >= 1):
        raise WorkbenchError(f"agreement: degrees of freedom must be >= 1, got {dof_a}, {dof_b}")
    H, W = shape[:2]
    if not 1 <= block <= min(H, W):
        raise WorkbenchError(f"agreement: block must be within 1..{min(H, W)}, got {block}")
    d = a - b
    va, vb = se_a ** 2, se_b ** 2
    s2 = va + vb
    ok = s2 > 0.0
    S = float(s2[ok].sum())
    out: dict = {"image_definition": "box-filtered pixel average, linear RGB, not clipped",
                 "dof_a": float(dof_a), "dof_b": float(dof_b), "zero_noise_values": int((~ok).sum()),
                 "max_abs_diff_at_zero_noise": float(np.abs(d[~ok]).max()) if (~ok).any() else 0.0}
    if S > 0.0:
        R = float((d ** 2).sum()) / S  # every value: a one-dof estimate can be 0 by chance
        var_R = (2.0 * float((s2[ok] ** 2).sum()) + 2.0 * float((va ** 2).sum()) / (dof_a + 2.0)
                 + 2.0 * float((vb ** 2).sum()) / (dof_b + 2.0)) / S ** 2
        z = d[ok] / np.sqrt(s2[ok])
        out.update(ratio=R, ratio_sd=math.sqrt(var_R), ratio_ok=bool(abs(R - 1.0) <= band_sd * math.sqrt(var_R)),
                   n_eff=S ** 2 / float((s2[ok] ** 2).sum()), frac_abs_z_gt_3=float(np.mean(np.abs(z) > 3.0)))
    Hb, Wb = H // block, W // block
    db = d[:Hb * block, :Wb * block].reshape(Hb, block, Wb, block, 3).sum((1, 3))
    vbk = s2[:Hb * block, :Wb * block].reshape(Hb, block, Wb, block, 3).sum((1, 3))
    live = vbk > 0.0
    if live.any():
        zb = db[live] / np.sqrt(vbk[live])
        K = int(live.any(axis=2).sum())
        Q = float(np.mean(zb ** 2))
        band = band_sd * math.sqrt(2.0 / K)
        out.update(block=block, block_count=K, block_chi2=Q, block_chi2_band=band,
                   block_chi2_ok=bool(abs(Q - 1.0) <= band), block_frac_abs_z_gt_3=float(np.mean(np.abs(zb) > 3.0)))
    out["mean"] = _mean_part(a, b, s2, np.ones((H, W), bool))
    keep = np.ones((H, W), bool) if exclude is None else ~np.asarray(exclude, bool)
    out["mean_off"] = _mean_part(a, b, s2, keep)
    return out
