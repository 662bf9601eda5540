"""Invariant: every command on every bundled scene, at a tiny size, exits 0 or 2, never with a
traceback; a status 2 comes with exactly one line ``workbench: error: ...``.  It knows no
particular defect: it catches the next command that crashes on a scene it was not tried on.

Fast variant (default run): ``render`` with every registered method at the cheapest value of
its knob, and ``compare`` against a forced reference (the ray tracer) that a compared method
equals exactly on 9 of the 10 scenes (PSNR = inf: the case that crashed 7 scenes), in-process
through the CLI's ``_run``; one real subprocess.  Slow variant (``-m slow``): every method at
its default settings, ``compare`` with the documented reference rule, and ``study --quick``.
"""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

import workbench
from workbench.app.cli import _run
from workbench.compare.outputs import loads
from workbench.renderers.base import available, get_renderer
from workbench.scene.kinds import kind_of
from workbench.scene.library import bundled

SCENES = [p.stem for p in bundled()]
SIZE = "24x18"


def _check(argv, capsys) -> tuple[int, str]:
    """Run the CLI in-process; an exception escaping ``_run`` fails the test (a traceback)."""
    code = _run([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "Traceback" not in out, err
    assert code in (0, 2), (argv, code, err)
    if code == 2:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("workbench: error: "), (argv, err)
    return code, out


def _render_all(scene, tmp_path, capsys, cheapest: bool):
    for m in available():
        knob = get_renderer(m).knob
        extra = ["--set", f"{knob.name}={knob.values[0]}"] if cheapest else []
        png = tmp_path / f"{scene}-{m}.png"
        code, _ = _check(["render", scene, "-m", m, "--size", SIZE, "-o", png, *extra], capsys)
        assert png.is_file() == (code == 0), (scene, m)


def _compare_report_is_sound(out_dir, stdout):
    """report.json is strict JSON; read back, every metric is a number (inf allowed)."""
    text = (out_dir / "report.json").read_text()
    json.loads(text, parse_constant=lambda c: pytest.fail(f"non-strict JSON token {c}"))
    rep = loads(text)
    for e in rep["methods"]:
        if e["status"] == "ok":
            assert all(isinstance(e["metrics"][k], float) for k in ("rmse", "psnr", "flip")), e
    return rep


@pytest.mark.gl
@pytest.mark.parametrize("scene", SCENES)
def test_render_every_method_and_compare(scene, tmp_path, capsys):
    _render_all(scene, tmp_path, capsys, cheapest=True)
    out = tmp_path / "cmp"
    code, stdout = _check(["compare", scene, "--size", SIZE, "--out", out, "--methods", "raycast,raytrace",
                           "--reference", "raytrace", "--repeat", "1"], capsys)
    assert code == 0
    rep = _compare_report_is_sound(out, stdout)
    exact = [e for e in rep["methods"] if e["metrics"]["rmse"] == 0.0]
    for e in exact:
        assert e["metrics"]["psnr"] == float("inf")
        assert any(ln.split()[:1] == [e["method"]] and "PSNR inf dB" in ln for ln in stdout.splitlines())
    # the ray tracer at its default depth equals its depth-12 reference wherever no mirror
    # chain is deeper than the default: on every bundled scene but Whitted's and those with a
    # medium (their reference also marches at a quarter of the step)
    media = any(getattr(kind_of(o), "MEDIUM", False) for o in workbench.load_scene(scene).objects)
    assert scene == "whitted" or media or any(e["method"] == "raytrace" for e in exact)


def test_real_process_compare_with_an_exact_method(tmp_path):
    """The same through a real process (argv parsing, os._exit, stdout flushing)."""
    r = subprocess.run([sys.executable, "-m", "workbench.app.cli", "compare", "globe", "--size", SIZE,
                        "--out", str(tmp_path / "c"), "--methods", "raytrace", "--reference", "raytrace",
                        "--repeat", "1"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert "PSNR inf dB" in r.stdout
    _compare_report_is_sound(tmp_path / "c", r.stdout)


@pytest.mark.slow
@pytest.mark.gl
@pytest.mark.parametrize("scene", SCENES)
def test_every_command_default_settings(scene, tmp_path, capsys):
    _render_all(scene, tmp_path, capsys, cheapest=False)
    code, stdout = _check(["compare", scene, "--size", SIZE, "--out", tmp_path / "cmp"], capsys)
    assert code == 0
    _compare_report_is_sound(tmp_path / "cmp", stdout)
    code, _ = _check(["study", scene, "--quick", "--size", SIZE, "--out", tmp_path / "study"], capsys)
    assert code == 0 and (tmp_path / "study" / "study.json").is_file()
