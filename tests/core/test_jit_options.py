"""``jit_options.python_twin``: a wrapper-less kernel's copy that Python can call, cached on disk
under a name of its own (so that neither the copy nor the kernel ever loads the other's code)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

CHILD = textwrap.dedent('''
    import json
    from workbench.core.jit_options import python_twin, wrapperless
    from workbench.scene.kinds import hypertexture_kernels as h
    twin = python_twin(h.value_noise)
    print(json.dumps(dict(value=twin(0.3, 0.2, 0.1), hits=len(twin.stats.cache_hits),
                          kernel_wrapperless=wrapperless(h.value_noise), twin_wrapperless=wrapperless(twin))))
''')


def test_a_twin_is_callable_and_cached_apart(tmp_path):
    from workbench.core.noise import value_noise
    runs = []
    for _ in range(2):
        p = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=300,
                           env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
        assert p.returncode == 0, p.stderr[-2000:]
        runs.append(json.loads(p.stdout.strip().splitlines()[-1]))
    assert [r["hits"] for r in runs] == [0, 1]
    assert all(r["kernel_wrapperless"] and not r["twin_wrapperless"] for r in runs)
    # the numpy twin of the same noise (workbench.core.noise) at the same point
    want = float(value_noise([[0.3, 0.2, 0.1]])[0])
    assert all(abs(r["value"] - want) <= 1e-12 for r in runs)
    names = sorted(p.name for p in tmp_path.rglob("hypertexture_kernels.value_noise*.nbi"))
    assert names and all("__python_twin" in n for n in names)  # the kernel itself was never compiled here
