"""Images of the existing object kinds are bit-identical before and after the move to
object-kind modules (issue 14): commit f2e4b0a (the last tree with the seven isinstance
chains) is extracted with ``git archive`` and renders :mod:`tests.kinds_identity`'s set (every
kind; flat, Phong, ray casting, Whitted, radiosity, path tracing; small, fixed seeds) in a
subprocess; this checkout renders the same set in-process; every image must be equal to the
last bit.  No image hashes are stored (numba / LLVM may contract differently on another CPU):
both trees run here, on the same machine and libraries."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
BEFORE = "f2e4b0a"


def _git(*args, **kw):
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, **kw)


@pytest.mark.slow
@pytest.mark.timeout(3600)   # two cold numba compiles (each tree its own cache) and 72 renders
def test_images_of_every_kind_are_bit_identical_to_before_the_move(tmp_path):
    if _git("rev-parse", "--is-inside-work-tree").returncode != 0:
        pytest.skip("not a git checkout: the tree before the move cannot be extracted")
    if _git("cat-file", "-e", f"{BEFORE}^{{commit}}").returncode != 0:
        pytest.skip(f"commit {BEFORE} is not in this clone's history (a shallow clone?)")
    old = tmp_path / "before"
    old.mkdir()
    archive = _git("archive", BEFORE, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(old)], input=archive, check=True)
    env = {**os.environ, "PYTHONPATH": str(old), "NUMBA_CACHE_DIR": str(tmp_path / "numba_before")}
    out = tmp_path / "before.npz"
    subprocess.run([sys.executable, str(ROOT / "tests" / "kinds_identity.py"), str(out)], env=env,
                   check=True, cwd=old, timeout=3000)
    before = np.load(out)

    sys.path.insert(0, str(ROOT / "tests"))
    try:
        import kinds_identity
    finally:
        sys.path.remove(str(ROOT / "tests"))
    after = kinds_identity.render_all(new=True)

    assert sorted(before.files) == sorted(after)
    images = [k for k in after if np.asarray(after[k]).ndim == 3]
    kinds_seen = {k.split("/")[0] for k in images}
    assert {"all_kinds", "csg", "quadrics", "mesh"} <= kinds_seen
    assert any(k == "all_kinds/radiosity" for k in images)
    for k in sorted(after):
        a, b = before[k], np.asarray(after[k])
        if b.ndim == 0:   # a method refused the scene: the same message in both trees
            assert str(a) == str(b), k
        else:
            assert a.shape == b.shape and a.dtype == b.dtype, k
            assert np.ptp(b) > 0, f"{k}: a constant image tests nothing"
            assert np.array_equal(a, b), (f"{k}: {int((a != b).any(-1).sum())} pixels differ, "
                                          f"largest difference {np.abs(a - b).max():.3g}")
