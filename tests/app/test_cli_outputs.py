"""Every command checks all its output paths before any work, writes all or nothing, and reports
every user error (argparse's included) as one line ``workbench: error: ...`` with status 2.
The Python API refuses bad arguments with a WorkbenchError naming them."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import workbench
from workbench.app.cli import _run
from workbench.core.errors import WorkbenchError


def _cli(argv, capsys):
    code = _run([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _one_error_line(code, err):
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("workbench: error: "), err
    assert "Traceback" not in err and "usage:" not in err
    return lines[0]


@pytest.fixture
def no_work(monkeypatch):
    """Any render, scene load, comparison, study or stress run fails the test: the path checks
    must refuse first."""
    def forbidden(*a, **k):
        raise AssertionError("work started before the output paths were checked")
    import workbench.compare.report as report
    import workbench.compare.stress as stress
    import workbench.compare.study as study
    import workbench.renderers.base as base
    import workbench.scene.io as io
    for mod, name in ((base, "render"), (io, "load_scene"), (report, "compare"), (study, "study"),
                      (stress, "stress")):
        monkeypatch.setattr(mod, name, forbidden)


def _bad_outputs(tmp):
    afile = tmp / "afile"
    afile.write_text("x")
    folder = tmp / "folder.png"
    folder.mkdir()
    return {
        "a folder": (folder, "is a folder"),
        "under a file": (afile / "x.png", "is a file, not a folder"),
        "under a file, deeper": (afile / "sub" / "x.png", "is a file, not a folder"),
        "unwritable": ("/proc/wb-test/x.png", "cannot write"),
    }


@pytest.mark.parametrize("case", ["a folder", "under a file", "under a file, deeper", "unwritable"])
def test_render_refuses_bad_outputs_before_rendering(case, tmp_path, capsys, no_work):
    path, expect = _bad_outputs(tmp_path)[case]
    good = tmp_path / "good.png"
    for argv in (["render", "whitted", "-o", path],
                 ["render", "whitted", "-o", good, "--npy", str(path)[:-4] + ".npy"],
                 ["render", "whitted", "-o", good, "--json", str(path)[:-4] + ".json"],
                 ["colour", "wheel", "-o", path]):
        if case == "a folder" and argv[-2] != "-o":
            argv[-1] = path          # the folder itself
        line = _one_error_line(*_cli(argv, capsys)[::2])
        assert expect in line, line
        assert not good.exists()


@pytest.mark.parametrize("command", ["compare", "study", "stress"])
def test_folder_outputs_are_checked_before_any_work(command, tmp_path, capsys, no_work):
    afile = tmp_path / "afile"
    afile.write_text("x")
    for out, expect in ((afile, "is a file, expected a folder"), (afile / "sub", "is a file, not a folder"),
                        ("/proc/wb-test", "cannot write")):
        argv = [command] + ([] if command == "stress" else ["whitted"]) + ["--out", out]
        line = _one_error_line(*_cli(argv, capsys)[::2])
        assert "--out" in line and expect in line, line


def test_render_writes_all_outputs_or_none(tmp_path, capsys):
    """A bad --npy leaves no PNG (checked first); a write failing midway leaves none either."""
    png, npy, js = tmp_path / "a.png", tmp_path / "a.npy", tmp_path / "a.json"
    (tmp_path / "f").write_text("")
    _one_error_line(*_cli(["render", "whitted", "-m", "flat", "--size", "24x18", "-o", png,
                           "--npy", tmp_path / "f" / "a.npy"], capsys)[::2])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f"]
    _one_error_line(*_cli(["render", "whitted", "-m", "flat", "--size", "24x18", "-o", png,
                           "--json", png], capsys)[::2])          # two outputs, one file
    code, _, err = _cli(["render", "whitted", "-m", "flat", "--size", "24x18", "-o", png,
                         "--npy", npy, "--json", js], capsys)
    assert code == 0, err
    assert np.load(npy).shape == (18, 24, 3) and png.stat().st_size > 0 and js.stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "a.npy", "a.png", "f"]


def test_write_together_is_all_or_nothing(tmp_path):
    from workbench.core.output_paths import write_together
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old")

    def fails(tmp):
        raise OSError(28, "No space left on device")
    with pytest.raises(OSError):
        write_together([(a, lambda t: open(t, "w").write("new")), (b, fails)])
    assert a.read_text() == "old" and not b.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]     # no temporary left


@pytest.mark.parametrize("argv, expect", [
    (["render", "whitted", "-o", "x.png", "--size", "10"], "render: argument --size: expected WIDTHxHEIGHT"),
    (["render", "whitted", "-o", "x.png", "--size", "abc"], "argument --size"),
    (["render", "whitted", "-o", "x.png", "--size", "0x5"], "within 1..16384"),
    (["study", "whitted", "--out", "d", "--sweep", "raycast"], "argument --sweep: expected [METHOD:]OPTION"),
    (["render", "whitted"], "required: -o/--output"),
    (["render", "whitted", "-o", "x.png", "--bogus"], "unrecognized arguments: --bogus"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
    ([], "required: COMMAND"),
    (["compare", "whitted", "--out", "d", "--repeat", "x"], "argument --repeat: expected a whole number"),
])
def test_argparse_errors_are_one_line(argv, expect, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    line = _one_error_line(*_cli(argv, capsys)[::2])
    assert expect in line, line
    assert not list(tmp_path.iterdir())


def test_argparse_error_in_a_real_process(tmp_path):
    r = subprocess.run([sys.executable, "-m", "workbench.app.cli", "render", "whitted", "--size", "10",
                        "-o", "x.png"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert r.stderr.startswith("workbench: error: render: argument --size")
    assert not list(tmp_path.iterdir())


def test_help_still_prints_and_exits_0(capsys):
    with pytest.raises(SystemExit) as e:
        _run(["render", "--help"])
    assert e.value.code == 0 and "usage:" in capsys.readouterr().out


def test_study_refuses_bad_sweep_values_before_rendering(tmp_path, capsys, monkeypatch):
    import workbench.compare.study as study
    monkeypatch.setattr(study, "timed_run", lambda *a, **k: pytest.fail("rendered"))
    monkeypatch.setattr(study, "References", lambda *a, **k: pytest.fail("rendered"))
    line = _one_error_line(*_cli(["study", "whitted", "--out", tmp_path / "s", "--methods", "raycast",
                                  "--sweep", "raycast:spp=a,b"], capsys)[::2])
    assert "--sweep raycast:spp" in line and "'a'" in line
    assert not (tmp_path / "s").exists()


def _no_reference(monkeypatch):
    """Rendering a study's reference fails the test (it may take minutes: a study that has
    nothing to compare must say so before)."""
    from workbench.compare import study

    def forbidden(*a, **k):
        raise AssertionError("the reference was rendered")
    monkeypatch.setattr(study, "References", forbidden)


def test_study_with_nothing_rendered_is_an_error(tmp_path, capsys, monkeypatch):
    _no_reference(monkeypatch)
    line = _one_error_line(*_cli(["study", "whitted", "--quick", "--size", "16x12", "--out", tmp_path / "s",
                                  "--methods", "radiosity"], capsys)[::2])
    assert "nothing to study" in line and "no emitters" in line
    assert not (tmp_path / "s" / "study.json").exists()


def test_study_with_an_unknown_reference_fails_before_any_render(tmp_path, capsys, monkeypatch):
    from workbench.compare import study

    def forbidden(*a, **k):
        raise AssertionError("a sweep point was rendered")
    monkeypatch.setattr(study, "timed_run", forbidden)
    _no_reference(monkeypatch)
    line = _one_error_line(*_cli(["study", "whitted", "--quick", "--size", "16x12", "--out", tmp_path / "s",
                                  "--methods", "flat", "--reference", "nosuch"], capsys)[::2])
    assert "nosuch" in line
    assert not (tmp_path / "s").exists() or not any((tmp_path / "s").iterdir())


@pytest.mark.parametrize("args, kwargs, expect", [
    (("whitted", "phong"), {}, "scene must be a Scene"),
    ((None, "phong"), {}, "scene must be a Scene"),
    (("SCENE", None), {}, "method must be"),
    (("SCENE", 3), {}, "method must be"),
    (("SCENE", "phong"), {"width": "abc"}, "width must be an integer"),
    (("SCENE", "phong"), {"height": 2.5}, "height must be an integer"),
    (("SCENE", "phong"), {"width": True}, "width must be an integer"),
    (("SCENE", "phong"), {"width": 0}, "within 1..16384"),
    (("SCENE", "nope"), {}, "unknown method 'nope'"),
    (("SCENE", "phong"), {"tessellation": "x"}, "option 'tessellation' expects int"),
])
def test_python_api_refuses_bad_arguments_clearly(args, kwargs, expect):
    scene = workbench.load_scene("whitted")
    args = tuple(scene if a == "SCENE" else a for a in args)
    with pytest.raises(WorkbenchError, match=expect):
        workbench.render(*args, **kwargs)


@pytest.mark.parametrize("given", [None, 3, 2.5, ["whitted"]])
def test_load_scene_refuses_non_paths(given):
    with pytest.raises(workbench.SceneError, match="file path or a bundled scene's name"):
        workbench.load_scene(given)


def test_numpy_integer_sizes_are_accepted():
    r = workbench.render(workbench.load_scene("whitted"), "flat", width=np.int64(16), height=np.int32(12))
    assert r.image.shape == (12, 16, 3)
