"""The colour commands estimate their memory before they allocate (a 4000x4000 indexed k-means
took 4.4 GB unannounced), and every command and subcommand takes ``--max-memory`` (the colour
subcommands refused it: it was added to ``colour`` only, not to ``colour wheel``/``display``)."""
from __future__ import annotations

import subprocess
import tracemalloc

import numpy as np
import pytest

from ui_command import WORKBENCH
from workbench.app.cli import _leaf_parsers, build_parser
from workbench.core.display import apply_display_mode, estimate_display_bytes
from workbench.core.errors import WorkbenchError
from workbench.core.harmony import WHEEL_BYTES_PER_PIXEL, wheel_image


def _run(args, cwd):
    return subprocess.run([str(WORKBENCH), *args], capture_output=True, text=True, cwd=cwd, timeout=300)


def _refused(p, *words):
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1 and lines[0].startswith("workbench: error:"), p.stderr
    assert "Traceback" not in p.stderr and all(w in lines[0] for w in words), lines[0]


def test_every_command_and_subcommand_takes_max_memory():
    sub = next(a for a in build_parser()._actions if a.choices)
    leaves = _leaf_parsers(sub)
    progs = {p.prog for p in leaves}
    assert {"workbench render", "workbench colour wheel", "workbench colour display", "workbench ui"} <= progs, progs
    for parser in leaves:
        assert any("--max-memory" in a.option_strings for a in parser._actions), parser.prog


def test_a_large_npy_is_refused_from_its_header_before_it_is_read(tmp_path):
    big = np.lib.format.open_memmap(tmp_path / "big.npy", mode="w+", dtype=np.float32, shape=(4000, 4000, 3))
    del big  # a sparse 192 MB file of zeros: only its header is read before the refusal
    p = _run(["colour", "display", "big.npy", "--mode", "indexed16-kmeans", "-o", "o.png", "--max-memory", "256M"],
             tmp_path)
    _refused(p, "4000x4000", "256.0 MiB", "--max-memory")
    assert not (tmp_path / "o.png").exists()


def test_the_wheel_and_a_display_after_a_render_are_refused_before_the_work(tmp_path):
    p = _run(["colour", "wheel", "--size", "8000", "-o", "w.png", "--max-memory", "1G"], tmp_path)
    _refused(p, "8000x8000 colour wheel", "1.0 GiB")
    # the render would fit; its display post-process would not: refused before rendering
    p = _run(["render", "whitted", "-m", "raycast", "--size", "2000x2000", "--display", "indexed16-bayer",
              "-o", "r.png", "--max-memory", "1G"], tmp_path)
    _refused(p, "display mode indexed16", "2000x2000")
    assert p.stdout == "" and not list(tmp_path.iterdir())


def test_small_jobs_still_run_under_a_limit(tmp_path):
    assert _run(["colour", "wheel", "--size", "64", "-o", "w.png", "--max-memory", "64M"], tmp_path).returncode == 0
    np.save(tmp_path / "s.npy", np.random.default_rng(0).uniform(0, 1, (40, 50, 3)).astype(np.float32))
    p = _run(["colour", "display", "s.npy", "--mode", "indexed8-kmeans-fs", "-o", "o.png", "--max-memory", "64M"],
             tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "w.png").is_file() and (tmp_path / "o.png").is_file()


@pytest.mark.parametrize("mode", ["direct24", "direct16-565-bayer", "indexed16", "indexed16-kmeans", "indexed16-bayer"])
def test_the_estimate_bounds_what_numpy_allocates(mode):
    """tracemalloc's peak (numpy's arrays; the numba error diffusion is left out: its buffers are
    the image's size) stays under the estimate."""
    img = np.random.default_rng(1).uniform(0, 1, (300, 400, 3)).astype(np.float32)
    apply_display_mode(img[:8, :8], mode)  # imports and caches outside the measure
    tracemalloc.start()
    apply_display_mode(img, mode)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak <= estimate_display_bytes(300, 400, mode), (peak, estimate_display_bytes(300, 400, mode))


def test_wheel_estimate_bounds_what_numpy_allocates():
    wheel_image(0.0, "triad", 32)
    tracemalloc.start()
    wheel_image(0.0, "triad", 300)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak <= 300 * 300 * WHEEL_BYTES_PER_PIXEL, peak / (300 * 300)


def test_the_api_refuses_with_one_line():
    img = np.zeros((100, 100, 3), np.float32)
    with pytest.raises(WorkbenchError, match="display mode direct24 on 100x100 needs about"):
        apply_display_mode(img, "direct24", max_memory="1K")
    with pytest.raises(WorkbenchError, match="colour wheel needs about"):
        wheel_image(0.0, "triad", 64, max_memory="1K")
