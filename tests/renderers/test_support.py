"""The renderers' support tables (issue #27, item 4; :mod:`workbench.renderers.support`): every
registered method declares every scene feature, and what it declares left out is listed in a
render's ``left_out`` when the scene uses it (``workbench render`` run as users run it)."""
from __future__ import annotations

import json
import subprocess

import pytest

import workbench
from ui_command import WORKBENCH
from workbench.renderers.base import available, get_renderer
from workbench.renderers.support import Note, Status, declare, notes, used
from workbench.scene import features as ft


@pytest.mark.parametrize("method", available())
def test_every_method_declares_every_feature(method):
    table = get_renderer(method).support
    assert list(table) == list(ft.ALL)
    for f, cell in table.items():
        assert cell.status in (Status.SUPPORTED, Status.APPROXIMATED, Status.LEFT_OUT), (method, f)
        assert (cell.reason == "") == (cell.status is Status.SUPPORTED), (method, f, cell)


def test_declare_refuses_unknown_and_doubled_features():
    with pytest.raises(ValueError, match="unknown feature"):
        declare(left_out={"teleportation": "not in the course"})
    with pytest.raises(ValueError, match="declared twice"):
        declare(approximated={ft.BUMP: "a"}, left_out={ft.BUMP: "b"})


def test_notes_follow_the_needs_and_name_what_is_not_used():
    table = declare(approximated={ft.SPHERES: "tessellated"}, left_out={ft.BUMP: "flat", ft.SHADOWS: "none"})
    left = notes(table, {ft.BUMP, ft.SPHERES, ft.PLANES})
    assert left == [Note(ft.BUMP, "flat")] and str(left[0]) == "bump: flat"
    assert used({ft.BUMP, ft.SPHERES, ft.PLANES}, left) == [ft.PLANES, ft.SPHERES]
    assert Note.from_dict(left[0].as_dict()) == left[0]


#: (scene, method, options): bundled scenes that use features the method leaves out.
CASES = [("whitted", "zbuffer", []), ("bricks", "flat", []),
         ("cornell_spheres", "radiosity", ["--set", "patch_size=0.2"]), ("whitted", "raycast", [])]


@pytest.mark.parametrize("scene,method,options", CASES)
def test_declared_left_out_features_are_in_left_out(scene, method, options, tmp_path):
    needs = ft.scene_needs(workbench.load_scene(scene))
    table = get_renderer(method).support
    expected = [str(Note(f, c.reason)) for f, c in table.items() if f in needs and c.status is Status.LEFT_OUT]
    assert expected, (scene, method)   # the case exercises the table
    out = tmp_path / "r.json"
    r = subprocess.run([WORKBENCH, "render", scene, "-m", method, "--size", "16x12", "-o",
                        str(tmp_path / "r.png"), "--json", str(out), *options],
                       capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr
    rep = json.loads(out.read_text())
    missing = [e for e in expected if e not in rep["left_out"]]
    assert not missing, (missing, rep["left_out"])
    shown = next(line for line in r.stdout.splitlines() if line.startswith("  left out: "))
    assert all(e in shown for e in expected), shown
    gone = {f for f, c in table.items() if c.status is Status.LEFT_OUT}
    assert not gone & set(rep["features_used"]), rep["features_used"]
