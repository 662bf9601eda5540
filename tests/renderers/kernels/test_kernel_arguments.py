"""No numba kernel takes more than 8 array arguments (the kernel-layer issue's rule): a kernel
takes named records (:class:`workbench.renderers.kernels.layout.Geometry`, the Whitted driver's
``Shading`` and ``Pixels``, an interval stack as one tuple), not dozens of positional arrays.
Checked on the signatures numba compiled for renders that reach every kernel family: the kinds
and CSG scenes (every kind's dispatch, the CSG walk), the mesh (the BVH walk), the Cornell box
with the path tracer and radiosity (both form-factor methods).  A kernel reached through a caller loaded from numba's disk
cache is not compiled in this process: its signatures are read from its cache index (numba's
``_cache._cache_file._load_index()``, whose keys are ``(signature, target magic)``)."""
from __future__ import annotations

import sys

import numba
import pytest
from numba.core.registry import CPUDispatcher

import workbench

LIMIT = 8
KNOWN: set[str] = set()
"""Kernels still over the limit, named so that the list can only shrink: none now (the Whitted
wavefront drivers are gone; the batch intersector takes its rays and hits as two tuples)."""
RENDERS = [("kinds", "raytrace", {}), ("csg", "raycast", {}), ("mesh", "raytrace", {}),
           ("cornell", "pathtrace", {"spp": 2}), ("cornell", "radiosity", {}),
           ("cornell", "radiosity", {"form_factors": "raycast", "patch_size": 0.2}),
           ("cornell", "radiosity", {"solver": "progressive", "shot_rows": "raycast", "patch_size": 0.2}),
           ("whitted", "raytrace", {})]


def _dispatchers():
    seen = {}
    for m in list(sys.modules.values()):
        if getattr(m, "__name__", "").startswith("workbench"):
            for d in vars(m).values():
                if isinstance(d, CPUDispatcher):
                    seen[id(d)] = d
    return seen.values()


def _signatures(d):
    """The argument types of every version of ``d``: compiled here or held in its cache index."""
    sigs = set(d.signatures)
    cache = getattr(d, "_cache", None)
    if cache is not None and hasattr(cache, "_cache_file"):
        sigs |= {key[0] for key in cache._cache_file._load_index()}
    return sigs


@pytest.mark.parametrize("scene, method, opts", RENDERS)
def test_no_compiled_kernel_takes_more_than_eight_arrays(scene, method, opts):
    """(but those named in :data:`KNOWN`)"""
    workbench.render(workbench.load_scene(scene), method, width=8, height=6, **opts)
    over = {d.py_func.__name__: f"{d.py_func.__module__}.{d.py_func.__name__}: {n} arrays"
            for d in _dispatchers() for sig in _signatures(d)
            if (n := sum(isinstance(t, numba.types.Array) for t in sig)) > LIMIT}
    checked = sum(len(_signatures(d)) for d in _dispatchers())
    new = sorted(v for k, v in over.items() if k not in KNOWN)
    assert checked > 20 and not new, new
    assert set(over) <= KNOWN
