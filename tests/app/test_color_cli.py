"""``workbench colour wheel`` and ``workbench colour display`` (in-process, small images)."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from workbench.app.cli import main
from workbench.core.harmony import harmony_colors
from workbench.core.imageio import save_png, to_srgb8


def test_wheel_command_writes_the_marked_wheel(tmp_path, capsys):
    out = tmp_path / "wheel.png"
    assert main(["colour", "wheel", "--hue", "30", "--harmony", "square", "--size", "128",
                 "-o", str(out)]) == 0
    assert "30, 120, 210, 300" in capsys.readouterr().out
    rgb8 = np.asarray(Image.open(out).convert("RGB"))
    assert rgb8.shape == (128, 128, 3)
    present = {tuple(p) for p in rgb8.reshape(-1, 3)}
    for col in to_srgb8(harmony_colors(30, "square")[None])[0]:
        assert tuple(col) in present          # every harmony colour is drawn


def test_display_command_quantises_an_image(tmp_path, capsys):
    rng = np.random.default_rng(5)
    src, out = tmp_path / "in.png", tmp_path / "out.png"
    save_png(src, rng.uniform(0, 1, (24, 32, 3)))
    assert main(["color", "display", str(src), "--mode", "indexed4-kmeans-fs", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "indexed4-kmeans-fs" in text and "RMSE" in text and "PSNR" in text
    rgb8 = np.asarray(Image.open(out).convert("RGB"))
    assert rgb8.shape == (24, 32, 3) and len(np.unique(rgb8.reshape(-1, 3), axis=0)) <= 4


@pytest.mark.parametrize("args, words", [
    (["colour", "display", "IN", "--mode", "indexed5", "-o", "OUT"], "2, 4, 8"),
    (["colour", "display", "IN", "--mode", "direct8", "-o", "OUT"], "unknown display mode"),
    (["colour", "display", "missing.png", "-o", "OUT"], "no such image file"),
    (["colour", "wheel", "--harmony", "pentagon", "-o", "OUT"], "unknown harmony"),
    (["colour", "wheel", "-o", "wheel.jpg"], "must be a .png"),
])
def test_bad_colour_arguments_fail_cleanly(args, words, tmp_path, capsys):
    src = tmp_path / "in.png"
    save_png(src, np.full((4, 4, 3), 0.5))
    out = tmp_path / "out.png"
    args = [str(src) if a == "IN" else str(out) if a == "OUT" else a for a in args]
    if args[-1] == "wheel.jpg":
        args[-1] = str(tmp_path / "wheel.jpg")
    if "missing.png" in args:
        args[args.index("missing.png")] = str(tmp_path / "missing.png")
    assert main(args) == 2
    assert words in capsys.readouterr().err
    assert not out.exists() and not (tmp_path / "wheel.jpg").exists()
