"""Numba's cache folder is keyed by the code (``workbench.core.jit_cache``): an edit of a
kernel module that another module's cached kernels inline must not load their stale machine
code (numba itself checks only each function's own file)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from workbench.core import jit_cache

ROOT = Path(__file__).resolve().parents[2]
_PRINT = "import workbench, numba.core.config as c; print(c.CACHE_DIR)"


def _cache_dir(pkg_parent: Path, base: Path) -> Path:
    env = {**os.environ, "PYTHONPATH": str(pkg_parent), "NUMBA_CACHE_DIR": str(base)}
    out = subprocess.run([sys.executable, "-c", _PRINT], env=env, cwd=pkg_parent, capture_output=True,
                         text=True, timeout=120, check=True)
    return Path(out.stdout.strip())


def test_an_edited_kind_kernel_gets_a_cache_folder_of_its_own(tmp_path):
    src = tmp_path / "src"
    shutil.copytree(ROOT / "workbench", src / "workbench", ignore=shutil.ignore_patterns("__pycache__"))
    base = tmp_path / "numba"
    before = _cache_dir(src, base)
    assert before.parent == base and before.is_dir()
    assert _cache_dir(src, base) == before                      # same code: the warm cache
    kernel = src / "workbench" / "scene" / "kinds" / "lathe_kernels.py"
    kernel.write_text(kernel.read_text() + "\n# edited\n")
    after = _cache_dir(src, base)
    assert after.parent == base and after != before             # numba alone would reuse `before`
    assert before.is_dir()                                      # the older version's cache is kept


def test_an_edit_outside_the_kernel_sources_keeps_the_warm_cache(tmp_path):
    src = tmp_path / "src"
    shutil.copytree(ROOT / "workbench", src / "workbench", ignore=shutil.ignore_patterns("__pycache__"))
    base = tmp_path / "numba"
    before = _cache_dir(src, base)
    raster = src / "workbench" / "renderers" / "raster.py"    # GLSL raster: no numba kernel reads it
    raster.write_text(raster.read_text() + "\n# edited\n")
    assert _cache_dir(src, base) == before
    constants = src / "workbench" / "core" / "tol.py"          # read by the kernels as constants
    constants.write_text(constants.read_text() + "\n# edited\n")
    assert _cache_dir(src, base) != before


def test_the_kernel_sources_are_the_numba_modules_and_what_they_import():
    names = {str(p.relative_to(ROOT / "workbench")) for p in jit_cache.kernel_sources()}
    assert {"renderers/raytrace/kernels.py", "renderers/kernels/intersect.py", "scene/kinds/lathe_kernels.py",
            "scene/kinds/lathe.py", "core/tol.py", "renderers/kernels/specialise.py"} <= names
    assert not names & {"renderers/raster.py", "app/cli.py", "compare/report.py"}


def test_a_child_process_keeps_the_keyed_folder_and_old_ones_are_pruned(tmp_path):
    given = os.environ["NUMBA_CACHE_DIR"]
    try:
        _check_pruning(tmp_path)
    finally:  # this process's numba must keep compiling into the run's warm cache
        os.environ["NUMBA_CACHE_DIR"] = given
        import numba.core.config
        numba.core.config.reload_config()


def _check_pruning(tmp_path):
    fp = jit_cache.kernel_fingerprint()[:jit_cache.DIGITS]
    old = [tmp_path / f"{i:016x}" for i in range(jit_cache.KEEP + 2)]
    for i, p in enumerate(old):
        p.mkdir()
        os.utime(p, (1000.0 + i, 1000.0 + i))
    (tmp_path / "notes").mkdir()                                # not a fingerprint: left alone
    os.environ["NUMBA_CACHE_DIR"] = str(tmp_path)
    current = jit_cache.use_code_keyed_cache()
    assert current == tmp_path / fp and os.environ["NUMBA_CACHE_DIR"] == str(current)
    assert jit_cache.use_code_keyed_cache() == current          # a child: no nesting
    kept = sorted(p.name for p in tmp_path.iterdir())
    assert kept == sorted([fp, "notes"] + [p.name for p in old[-jit_cache.KEEP:]])


def test_pruning_skips_a_folder_another_process_removed_meanwhile(tmp_path, monkeypatch):
    """Two processes pruning the same base: a folder listed by one and removed by the other
    before its ``stat`` is skipped, not raised (it was, with more than KEEP old folders)."""
    old = [tmp_path / f"{i:016x}" for i in range(jit_cache.KEEP + 3)]
    for i, p in enumerate(old):
        p.mkdir()
        os.utime(p, (1000.0 + i, 1000.0 + i))
    current = tmp_path / ("f" * jit_cache.DIGITS)
    current.mkdir()
    gone = old[1]
    real_stat = Path.stat

    calls = []

    def stat_after_removal(self, *a, **k):  # the listing's is_dir is the first stat, then removed
        if self == gone:
            calls.append(self)
            if len(calls) == 2:
                shutil.rmtree(self)
        return real_stat(self, *a, **k)

    monkeypatch.setattr(Path, "stat", stat_after_removal)
    jit_cache._prune(tmp_path, current)
    monkeypatch.undo()
    assert len(calls) >= 2
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted([current.name] + [p.name for p in old[-jit_cache.KEEP:]])


CACHED = '''
import workbench, numba
@numba.njit(cache=True)
def plus_one(x):
    return x + 1
print(plus_one(1.5))
'''


def _waits_for_flock(pid: int) -> bool:
    """Whether process ``pid`` is blocked on an ``flock`` (a ``->`` row of ``/proc/locks``:
    ``N: -> FLOCK ADVISORY WRITE <pid> ...``)."""
    return any(f[1:3] == ["->", "FLOCK"] and f[5] == str(pid)
               for f in (line.split() for line in Path("/proc/locks").read_text().splitlines()) if len(f) > 5)


def test_a_cache_save_waits_for_another_process_holding_the_lock(tmp_path):
    """Numba's save of a new cache entry runs under an exclusive ``flock`` on the function's
    ``<index>.lock`` (``jit_cache.lock_cache_saves``): while this process holds the lock, a
    process compiling the cached function cannot finish its save (it is seen blocked on the
    lock, with no index written, rather than after a fixed wait); once released, it does."""
    import fcntl
    (tmp_path / "cached.py").write_text(CACHED)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(ROOT))
    base = _cache_dir(ROOT, tmp_path / "cache")
    run = [sys.executable, "cached.py"]
    subprocess.run(run, cwd=tmp_path, env=env, check=True, capture_output=True, timeout=300)  # the index exists
    (index,) = base.rglob("cached.plus_one-*.nbi")
    for f in base.rglob("cached.plus_one-*.nbc"):
        f.unlink()
    index.unlink()                              # a fresh save, under the held lock
    with open(str(index) + ".lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        child = subprocess.Popen(run, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 300
        while child.poll() is None and not _waits_for_flock(child.pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        waited = child.poll() is None and _waits_for_flock(child.pid) and not index.exists()
    out, err = child.communicate(timeout=300)
    assert waited, "the save did not wait for the lock"
    assert child.returncode == 0 and out.strip() == b"2.5", err[-500:]
    assert index.exists()


def test_a_child_process_locks_its_cache_saves_too(tmp_path):
    """A process started by another (the window's jobs, the suite's workers) inherits
    ``NUMBA_CACHE_DIR`` already keyed by the code; its saves are locked all the same.  Before:
    :func:`jit_cache.use_code_keyed_cache` returned early for it, and only the parent's saves
    took the lock, while the children are the processes that save at the same moment."""
    probe = "import workbench, numba.core.caching as c; print(getattr(c.IndexDataCacheFile.save, 'locked', False))"
    fp = jit_cache.kernel_fingerprint()[:jit_cache.DIGITS]
    for folder in (tmp_path, tmp_path / fp):  # a first process, then a child of it
        env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(folder)}
        out = subprocess.run([sys.executable, "-c", probe], env=env, cwd=ROOT, capture_output=True, text=True,
                             timeout=120, check=True)
        assert out.stdout.strip() == "True", folder
