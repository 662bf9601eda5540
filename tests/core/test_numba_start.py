"""The ``workbench`` program's numba start-up (:mod:`workbench.core.numba_start`): a kernel
loaded from the disk cache initialises numba's runtime only, not its typing and lowering
registries; a kernel compiled afterwards in the same process still gets every registry (numba's
compiler refreshes them itself), so the two kinds of kernel mix.  Each case runs in a child
process: the patch and the registries are per process."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

REGISTRY_MODULES = ("numba.np.arraymath", "numba.np.npyimpl", "numba.typed.dictimpl", "numba.cpython.unicode")
"""Modules that only numba's target-context refresh imports (``CPUContext.load_additional_registries``)."""

KERNELS = textwrap.dedent('''
    import numba as nb
    import numpy as np

    @nb.njit(cache=True)
    def cached(x):
        return np.sqrt(x) + 1.0

    @nb.njit(cache=False)
    def compiled(n):
        a = np.arange(n) * 2.0       # an allocation (NRT) and numpy's array lowering
        d = {1: a.sum()}             # a typed dict (numba.typed's registries)
        return d[1] + np.linalg.norm(a[:3]) + cached(9.0)  # and a callee loaded from the cache
''')

CHILD = textwrap.dedent('''
    import json, sys
    sys.path.insert(0, sys.argv[1])
    from workbench.core.numba_start import load_cache_hits_without_registries
    load_cache_hits_without_registries()
    import kernels_under_test as k
    first = k.cached(4.0)
    before = sorted(m for m in {registries} if m in sys.modules)
    second = k.compiled(5)
    after = sorted(m for m in {registries} if m in sys.modules)
    print(json.dumps(dict(first=first, second=second, before=before, after=after,
                          hits=len(k.cached.stats.cache_hits))))
''')


def _run(tmp_path) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    p = subprocess.run([sys.executable, "-c", CHILD.format(registries=REGISTRY_MODULES), str(tmp_path)],
                       capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_a_cache_hit_loads_no_registries_and_a_later_compile_gets_them(tmp_path):
    (tmp_path / "kernels_under_test.py").write_text(KERNELS)
    cold = _run(tmp_path)  # compiles `cached` (so the registries load) and saves it
    assert cold["hits"] == 0 and cold["before"] == sorted(REGISTRY_MODULES)
    warm = _run(tmp_path)
    assert warm["hits"] == 1                       # `cached` came from the disk cache...
    assert warm["before"] == []                    # ...without the registries
    assert warm["after"] == sorted(REGISTRY_MODULES)  # which the compile of `compiled` loaded
    expected = sum(2.0 * i for i in range(5)) + (0.0 + 4.0 + 16.0) ** 0.5 + 4.0
    for run in (cold, warm):
        assert run["first"] == 3.0
        assert abs(run["second"] - expected) <= 1e-12 * expected
