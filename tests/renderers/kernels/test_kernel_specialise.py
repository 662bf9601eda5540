"""Kernels compiled only for the kinds a scene holds (the kernel layer: ``renderers/kernels``).

The geometry record's kind marker names the scene's features; a kernel compiled for a marker
without a kind never compiles that kind's kernels.  Checked in a new process on an empty numba
cache (numba's dispatchers start empty there, and a kernel loaded from a warm cache types none
of its callees, so would show nothing compiled whatever the marker): a closest-hit search compiled for the spheres of the Whitted
scene leaves the blob, isosurface, lathe and prism kernels and the CSG walk uncompiled, and the
same search for a marker naming the blob compiles the blob's kernel and no other, and compiles
it as a function of its own, not marked for inlining (``kernels/flags.py``)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import workbench
from workbench.renderers.kernels.layout import features, kinds_marker, marker_features
from workbench.renderers.raytrace.flatten import flatten

ROOT = Path(__file__).resolve().parents[3]
EXTENDED = ("blob", "isosurface", "lathe", "prism", "csg")

PROBE = r'''
import json, sys
import numba as nb
import numpy as np
import workbench
from workbench.renderers.kernels.layout import kinds_marker
from workbench.renderers.kernels import intersect as k
from workbench.renderers.raytrace.flatten import flatten
from workbench.scene.kinds import blob_kernels, isosurface_kernels, lathe_kernels, prism_kernels

@nb.njit(error_model="numpy")  # IEEE divisions, as the kernels it inlines
def first_hit(geo, scr):
    stack, st, sp_, sf, sn = scr
    return k.row_hit(geo, 0, 0.0, 0.0, 10.0, 0.0, 0.0, -1.0, 1.0, 0.0, np.inf, 1e-12, 1e-9, stack, st, sp_,
                     sf, sn)

geo = flatten(workbench.load_scene("whitted")).kernel_args()
if sys.argv[1] == "blob":
    geo = geo._replace(kinds=kinds_marker(["blob", "analytic"]))
first_hit(geo, k.scratch())
compiled = {name: len(f.signatures) for name, f in [
    ("blob", blob_kernels.first), ("isosurface", isosurface_kernels.first),
    ("lathe", lathe_kernels.first), ("prism", prism_kernels.first), ("csg", k.csg_hit)]}
apart = [blob_kernels.first, blob_kernels.blob_crossings]
inlined = sorted(f.py_func.__name__ for f in apart for cres in f.overloads.values() if cres.fndesc.inline)
print(json.dumps({"compiled": compiled, "inlined": inlined}))
'''


def _probe(code: str, cache: Path, *args: str):
    """The last line of ``code`` run in a new process on the empty numba cache ``cache``, as JSON."""
    out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=ROOT,
                         env={**os.environ, "NUMBA_CACHE_DIR": str(cache)}, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_scene_of_spheres_compiles_no_kind_kernel(tmp_path):
    assert _probe(PROBE, tmp_path, "scene")["compiled"] == {name: 0 for name in EXTENDED}


@pytest.fixture(scope="module")
def blob_probe(tmp_path_factory) -> dict:
    return _probe(PROBE, tmp_path_factory.mktemp("numba_cache"), "blob")


def test_a_marker_naming_the_blob_compiles_the_blob_alone(blob_probe):
    assert blob_probe["compiled"] == {name: int(name == "blob") for name in EXTENDED}


def test_kernels_under_an_inlined_helper_stay_functions_of_their_own(blob_probe):
    """``row_hit`` and ``prim_hit`` are inlined helpers (``flags.INLINE``); the kind gate they call
    and the blob's kernels below it are compiled when they are typed, and numba gives a callee
    that does not set ``forceinline`` its caller's: unless the gate sets it to ``False``
    (``flags.GATE``), they would be inlined into every caller."""
    assert blob_probe["inlined"] == []


def test_features_of_the_bundled_scenes():
    """The marker names the extended group (the media kinds, hypertexture and fur, among them)
    iff the scene has one of its kinds, the triangles iff it has triangles or one of those kinds
    (the path tracer's variant of it, whose plain planes are triangles, is then the ray
    tracer's); every scene's marker is one of four."""
    markers = set()
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        scene = workbench.load_scene(str(path))
        sd = flatten(scene)
        names = marker_features(sd.kernel_args().kinds)
        kinds = {o.kind for o in scene.objects}
        extended = bool(kinds & {"blob", "isosurface", "lathe", "prism", "csg", "hypertexture", "fur"})
        assert all(n in names for n in EXTENDED + ("hypertexture", "fur")) == extended, (path.stem, names)
        assert ("triangles" in names) == (len(sd.tri_v) > 0 or extended), (path.stem, names)
        markers.add(names)
    assert len(markers) <= 4


MEDIA_PROBE = r'''
import json
import numba as nb
import numpy as np
import workbench
from workbench.renderers.kernels import intersect as k
from workbench.renderers.kernels.media import march, ratio, track
from workbench.renderers.raytrace.flatten import flatten
from workbench.scene.kinds import fur_kernels, hypertexture_kernels

@nb.njit(error_model="numpy")
def media_steps(geo, scr, lights, mat_of, mat_tab):
    m = march(geo, 0, 0.0, 0.0, 10.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.1, 0.1, 0.1, 1.0, True,
              (lights, mat_of, mat_tab), scr)
    t = track(geo, 0, 0.0, 0.0, 10.0, 0.0, 0.0, -1.0, 0.0, 1.0, np.uint64(7), 3)
    r = ratio(geo, 0, 0.0, 0.0, 10.0, 0.0, 0.0, -1.0, 0.0, 1.0, np.uint64(7), 3)
    return m[0], m[1], t[0], t[7], r[0], r[1]

geo = flatten(workbench.load_scene("whitted")).kernel_args()
steps = media_steps(geo, k.scratch(), np.zeros((1, 16)), np.zeros(1, np.int64), np.zeros((1, 40)))
print(json.dumps({"steps": [float(v) for v in steps],
                  "compiled": [len(f.signatures) for f in (hypertexture_kernels.optics, hypertexture_kernels.density,
                                                           fur_kernels.texel, fur_kernels.optics)]}))
'''


def test_a_scene_without_media_compiles_no_medium_code(tmp_path):
    """The march of the ray caster and Whitted and the path tracer's delta and ratio tracking,
    compiled for the spheres' marker (in a new process, on an empty cache), type none of the
    media's kernels: they are gates that compile to constants without a medium (a clear ray:
    transmittance 1, no emission, no collision, the random dimension unchanged)."""
    probe = _probe(MEDIA_PROBE, tmp_path)
    assert probe["compiled"] == [0, 0, 0, 0]
    assert probe["steps"] == [1.0, 0.0, float("inf"), 3.0, 1.0, 3.0]


def test_unknown_feature_is_refused():
    try:
        kinds_marker(["torus"])
    except ValueError as e:
        assert "torus" in str(e) and all(f in str(e) for f in features())
    else:
        raise AssertionError("kinds_marker accepted an unknown feature")
