"""Display modes: parser, direct and indexed quantisation, palettes, dithering."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.core import display as D
from workbench.core.errors import WorkbenchError
from workbench.core.imageio import srgb_decode, srgb_encode


def _smooth_image(h=48, w=64, seed=3):
    """A smooth, colourful linear image (sums of random low-frequency waves)."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w] / max(h, w)
    chans = []
    for _ in range(3):
        f, p, a = rng.uniform(1, 4, 2), rng.uniform(0, 2 * np.pi, 2), rng.uniform(0.2, 0.5, 2)
        chans.append(0.5 + a[0] * np.sin(2 * np.pi * f[0] * x + p[0]) * a[1] * 2
                     * np.cos(2 * np.pi * f[1] * y + p[1]))
    return srgb_decode(np.clip(np.stack(chans, -1), 0, 1)).astype(np.float32)


def _rmse(a, b):
    return float(np.sqrt(np.mean((np.asarray(a, float) - b) ** 2)))


def _block_mean_error(a, b, k=8):
    h, w = (a.shape[0] // k) * k, (a.shape[1] // k) * k
    blocks = lambda im: im[:h, :w].reshape(h // k, k, w // k, k, 3).mean((1, 3))  # noqa: E731
    return float(np.abs(blocks(a) - blocks(b)).mean())


@pytest.mark.parametrize("text, canonical", [
    ("direct24", "direct24"), ("direct16", "direct16-555"), ("Direct16-565", "direct16-565"),
    ("direct16-555-fs", "direct16-555-fs"), ("indexed16", "indexed16-mediancut"),
    ("indexed16-kmeans-fs", "indexed16-kmeans-fs"), ("indexed2-bayer", "indexed2-mediancut-bayer"),
    ("indexed256-median_cut-ordered", "indexed256-mediancut-bayer")])
def test_parse_mode_strings(text, canonical):
    mode = D.parse_display_mode(text)
    assert str(mode) == canonical
    assert D.parse_display_mode(str(mode)) == mode


@pytest.mark.parametrize("bad, words", [
    ("direct32", "unknown display mode"), ("indexed3", "2, 4, 8"), ("indexed512", "2, 4, 8"),
    ("indexed16-kmeans-foo", "unknown dithering"), ("", "unknown display mode"),
    ("indexed16-octree", "unknown dithering"), ("direct24-fs-fs", "unknown display mode")])
def test_bad_mode_strings_are_workbench_errors(bad, words):
    with pytest.raises(WorkbenchError, match=words):
        D.parse_display_mode(bad)


def test_keyword_form_equals_string_form():
    assert D.display_mode("indexed", entries=16, palette="kmeans", dither="floyd_steinberg") \
        == D.parse_display_mode("indexed16-kmeans-fs")
    assert D.display_mode("direct16-565", dither="ordered") == D.parse_display_mode("direct16-565-bayer")
    for kw in ({"palette": "kmeans"}, {"entries": 4}):
        with pytest.raises(WorkbenchError, match="indexed"):
            D.display_mode("direct24", **kw)
    with pytest.raises(WorkbenchError, match="entries"):
        D.display_mode("indexed")
    with pytest.raises(WorkbenchError, match="dithering"):
        D.display_mode("indexed4", dither="random")
    with pytest.raises(WorkbenchError, match=r"\(H, W, 3\)"):
        D.apply_display_mode(np.zeros((4, 4)), "direct24")


def test_direct24_is_8bit_rounding_and_modes_are_idempotent():
    img = _smooth_image()
    out = D.apply_display_mode(img, "direct24")
    assert np.abs(srgb_encode(out) - srgb_encode(img)).max() <= 0.5 / 255 + 1e-6
    for mode in ("direct24", "direct16-555", "direct16-565"):
        once = D.apply_display_mode(img, mode)
        np.testing.assert_allclose(D.apply_display_mode(once, mode), once, atol=1e-6)


def test_direct16_levels_and_565_beats_555_on_green():
    ramp = np.linspace(0.0, 1.0, 256)
    img = srgb_decode(np.stack([ramp, ramp, ramp], -1)[None].repeat(4, 0))
    ref = D.apply_display_mode(img, "direct24")
    e555 = D.apply_display_mode(img, "direct16-555")
    e565 = D.apply_display_mode(img, "direct16-565")
    levels = lambda im, c: len(np.unique(np.round(srgb_encode(im[..., c]) * 1e4)))  # noqa: E731
    assert [levels(e555, c) for c in range(3)] == [32, 32, 32]
    assert [levels(e565, c) for c in range(3)] == [32, 64, 32]
    assert _rmse(e565[..., 1], ref[..., 1]) < 0.6 * _rmse(e555[..., 1], ref[..., 1])
    np.testing.assert_array_equal(e565[..., [0, 2]], e555[..., [0, 2]])
    assert _rmse(e565, ref) < _rmse(e555, ref)


@pytest.mark.parametrize("palette", D.PALETTES)
def test_palette_error_falls_as_the_palette_grows(palette):
    img = _smooth_image()
    ref = D.apply_display_mode(img, "direct24")
    errs = [_rmse(D.apply_display_mode(img, "indexed", entries=n, palette=palette), ref)
            for n in (2, 4, 16, 256)]
    assert errs[0] > errs[1] > errs[2] > errs[3] > 0
    assert errs[3] < 0.5 * errs[2]


def test_indexed_output_uses_at_most_the_clut_entries():
    img = _smooth_image()
    for n in (2, 4, 16):
        for dither in D.DITHERS:
            out = D.apply_display_mode(img, "indexed", entries=n, dither=dither)
            assert len(np.unique(out.reshape(-1, 3), axis=0)) <= n
            assert out.dtype == np.float32 and np.isfinite(out).all()


def test_kmeans_does_not_increase_distortion_over_its_median_cut_start():
    rng = np.random.default_rng(7)
    centres = rng.uniform(0, 1, (6, 3))
    x = np.clip(centres[rng.integers(0, 6, 3000)] + rng.normal(0, 0.08, (3000, 3)), 0, 1)
    start = D.median_cut(x, 6)
    fitted = D.kmeans(x, start)
    dist = lambda pal: np.mean(np.sum((x - pal[D.nearest(x, pal)]) ** 2, -1))  # noqa: E731
    assert dist(fitted) < dist(start)


@pytest.mark.parametrize("mode, grey", [("indexed2", True), ("indexed4", False),
                                        ("indexed16", False), ("indexed256", False),
                                        ("direct16-555", False)])
def test_dithering_keeps_the_local_mean_colour_closer(mode, grey):
    """On a smooth ramp, 8x8 block means of the dithered image are closer to the 24-bit ones.

    Two CLUT entries only reach the segment between them, hence a grey ramp for indexed2.
    """
    ramp = np.tile(np.linspace(0.05, 0.95, 256), (64, 1))
    y = np.broadcast_to(np.linspace(0.2, 0.8, 64)[:, None], (64, 256))
    enc = np.stack([ramp] * 3 if grey else [ramp, y, ramp[:, ::-1]], -1)
    img = srgb_decode(enc)
    ref = D.apply_display_mode(img, "direct24")
    plain = _block_mean_error(D.apply_display_mode(img, mode), ref)
    for dither in ("floyd_steinberg", "ordered"):
        assert _block_mean_error(D.apply_display_mode(img, mode, dither=dither), ref) < 0.8 * plain


def test_floyd_steinberg_kernel_matches_its_python_reference():
    from workbench.core._dither import floyd_steinberg
    e = srgb_encode(_smooth_image(12, 10))
    pal = D.build_palette(e.reshape(-1, 3), 4)
    for palette, levels in ((pal, np.zeros(3)), (np.zeros((0, 3)), np.array([31.0, 63.0, 31.0]))):
        fast = floyd_steinberg(e, palette, levels)
        slow = floyd_steinberg.py_func(e, palette, levels)
        np.testing.assert_array_equal(fast, slow)


def test_non_finite_and_out_of_range_inputs_give_a_clean_image():
    img = _smooth_image(16, 16)
    img[0, 0] = [np.nan, np.inf, -np.inf]
    img[1, 1] = [-3.0, 7.0, 0.5]
    for mode in ("direct24", "direct16-565-fs", "indexed4-kmeans-bayer", "indexed16-fs"):
        out = D.apply_display_mode(img, mode)
        assert np.isfinite(out).all() and out.min() >= 0.0 and out.max() <= 1.0


def test_bayer_matrix_is_a_permutation_of_thresholds():
    for n in (2, 4, 8):
        m = D.bayer_matrix(n)
        np.testing.assert_array_equal(np.sort((m * n * n - 0.5).ravel()), np.arange(n * n))
    np.testing.assert_array_equal(D.bayer_matrix(2) * 4 - 0.5, [[0, 2], [3, 1]])
