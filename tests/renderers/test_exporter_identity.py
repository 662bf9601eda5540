"""The exporters' output for bundled scenes is pinned: the POV-Ray SDL text and the Mitsuba
scene dictionary (recorded by :func:`mitsuba_record`) are kept in ``tests/golden/exporters``,
and the exporters must still write them exactly.  Regenerate only for an intended change of the
mapping: ``cd tests/renderers && python -c "import test_exporter_identity as t; t.write_golden()"``.

Text and structure must be the same; numbers agree to :data:`REL_TOL` relative (or
:data:`ABS_TOL` absolute, for values that are rounding noise around zero): the exported
transforms come out of matrix products whose last bits differ between CPUs and BLAS builds
(``-9.13e-18`` on one machine is ``-1.06e-17`` on the next).
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

import workbench
from workbench.renderers import mitsuba_export, povray_sdl

GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "exporters"
POV_SCENES = ("csg", "quadrics", "whitted", "cornell", "globe")
MITSUBA_SCENES = ("csg", "cornell_spheres", "whitted")
W, H = 64, 48
LEVEL = 2
REL_TOL = 1e-9
ABS_TOL = 1e-12
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= max(ABS_TOL, REL_TOL * max(abs(a), abs(b)))


def same_text(got: str, want: str) -> bool:
    """The texts are equal once every number is compared by :func:`_close`."""
    if NUMBER.split(got) != NUMBER.split(want):
        return False
    a, b = NUMBER.findall(got), NUMBER.findall(want)
    return len(a) == len(b) and all(_close(float(x), float(y)) for x, y in zip(a, b))


def same_data(got, want) -> bool:
    """JSON data equal, floats by :func:`_close`."""
    if isinstance(want, dict):
        return isinstance(got, dict) and got.keys() == want.keys() and \
            all(same_data(got[k], want[k]) for k in want)
    if isinstance(want, list):
        return isinstance(got, list) and len(got) == len(want) and \
            all(same_data(g, w) for g, w in zip(got, want))
    if isinstance(want, float) or isinstance(got, float):
        return isinstance(got, (int, float)) and isinstance(want, (int, float)) and _close(got, want)
    if isinstance(want, str):
        return isinstance(got, str) and same_text(got, want)
    return got == want


def _ply_summary(path: str) -> str:
    """``name: V vertices, F faces, normals yes/no`` from a PLY file's header."""
    head = Path(path).read_bytes().split(b"end_header", 1)[0].decode("ascii")
    v = re.search(r"element vertex (\d+)", head).group(1)
    f = re.search(r"element face (\d+)", head).group(1)
    return f"{Path(path).name}: {v} vertices, {f} faces, normals {'yes' if 'nx' in head else 'no'}"


def mitsuba_record(name: str, folder: str) -> dict:
    """The Mitsuba export of bundled scene ``name`` as plain JSON data (file names replaced by
    their PLY summary)."""
    ex = mitsuba_export.export_scene(workbench.load_scene(name), folder, LEVEL)

    def plain(v):
        if isinstance(v, dict):
            return {k: plain(x) for k, x in v.items()}
        if isinstance(v, list):
            return [plain(x) for x in v]
        if isinstance(v, str) and v.startswith(folder):
            return _ply_summary(v)
        return v
    return json.loads(json.dumps({"dict": plain(ex.scene_dict), "left_out": [str(x) for x in ex.left_out],
                                  "triangles": ex.triangles, "shapes": ex.shapes}))


def write_golden() -> None:
    import tempfile
    GOLDEN.mkdir(parents=True, exist_ok=True)
    for name in POV_SCENES:
        (GOLDEN / f"{name}.pov").write_text(povray_sdl.export(workbench.load_scene(name), W, H).sdl)
    for name in MITSUBA_SCENES:
        with tempfile.TemporaryDirectory() as tmp:
            (GOLDEN / f"{name}_mitsuba.json").write_text(json.dumps(mitsuba_record(name, tmp), indent=1, sort_keys=True))


@pytest.mark.parametrize("name", POV_SCENES)
def test_povray_sdl_of_bundled_scenes_is_unchanged(name):
    ex = povray_sdl.export(workbench.load_scene(name), W, H)
    want = (GOLDEN / f"{name}.pov").read_text()
    assert same_text(ex.sdl, want), (ex.sdl, want)


@pytest.mark.parametrize("name", MITSUBA_SCENES)
def test_mitsuba_dict_of_bundled_scenes_is_unchanged(name, tmp_path):
    got = mitsuba_record(name, str(tmp_path))
    want = json.loads((GOLDEN / f"{name}_mitsuba.json").read_text())
    assert same_data(got, want), (got, want)


def test_the_comparison_sees_a_changed_number_and_a_changed_word():
    assert same_text("a <1.0, -9.1325521e-18> b", "a <1.0, -1.06309128e-17> b")
    assert not same_text("a <1.0, 2.0> b", "a <1.0, 2.000001> b")
    assert not same_text("a <1.0, 2.0> b", "a <1.0, 2.0> c")
    assert same_data({"x": [1.0, "m 0.5"]}, {"x": [1.0 + 1e-12, "m 0.5"]})
    assert not same_data({"x": [1.0, "m 0.5"]}, {"x": [1.0, "m 0.6"]})
