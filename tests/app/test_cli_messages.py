"""Bad arguments found in a new user's trial, each answered by the console script with one line
``workbench: error: ...`` naming what is wrong, exit 2, no traceback, no numpy repr and no output
file."""
from __future__ import annotations

import subprocess

import numpy as np
import pytest

from ui_command import WORKBENCH

CASES = {  # id -> (argv after "workbench", words the one line must hold); {tmp} is the test folder
    "size negative, space form": (["render", "whitted", "-m", "phong", "--size", "-5x5", "-o", "{tmp}/x.png"],
                                  ["--size", "-5x5", "1..16384"]),
    "size negative, = form": (["render", "whitted", "-m", "phong", "--size=-5x5", "-o", "{tmp}/x.png"],
                              ["--size", "-5x5"]),
    "tiny memory limit shown in its unit": (["render", "whitted", "-m", "phong", "--size", "32x24",
                                             "--max-memory", "1K", "-o", "{tmp}/x.png"], ["1.0 KiB"]),
    "compare --repeat 0": (["compare", "whitted", "--repeat", "0", "--out", "{tmp}/c"], ["--repeat", "at least 1"]),
    "study --repeat -1": (["study", "whitted", "--repeat", "-1", "--out", "{tmp}/s"], ["--repeat", "at least 1"]),
    "raytrace threshold -1": (["render", "whitted", "-m", "raytrace", "--set", "threshold=-1",
                               "-o", "{tmp}/x.png"], ["threshold", ">= 0"]),
    "hybrid threshold -1": (["render", "cornell", "-m", "hybrid", "--set", "threshold=-1",
                             "-o", "{tmp}/x.png"], ["threshold", ">= 0"]),
    "NaN image to colour": (["colour", "display", "{tmp}/nan.npy", "-o", "{tmp}/x.png"], ["NaN", "nan.npy"]),
}
# every command that writes, its output under a regular file ({tmp}/afile): refused before any
# work (snapshot record rendered first and then failed on "Not a directory")
UNWRITABLE = {
    "render -o": ["render", "whitted", "-m", "flat", "--size", "16x12", "-o", "{tmp}/afile/x.png"],
    "render --json": ["render", "whitted", "-m", "flat", "--size", "16x12", "-o", "{tmp}/x.png",
                      "--json", "{tmp}/afile/x.json"],
    "compare --out": ["compare", "whitted", "--methods", "flat", "--size", "16x12", "--out", "{tmp}/afile/c"],
    "study --out": ["study", "whitted", "--methods", "flat", "--quick", "--size", "16x12", "--out", "{tmp}/afile/s"],
    "stress --out": ["stress", "--out", "{tmp}/afile/st"],
    "snapshot record --dir": ["snapshot", "record", "--dir", "{tmp}/afile/snap", "--methods", "flat", "whitted"],
    "snapshot check --update --dir": ["snapshot", "check", "whitted", "--update", "--dir", "{tmp}/afile/snap",
                                      "--methods", "flat"],
    "colour wheel -o": ["colour", "wheel", "-o", "{tmp}/afile/w.png"],
    "colour display -o": ["colour", "display", "whitted", "-o", "{tmp}/afile/d.png"],
    "ui --out": ["ui", "whitted", "--frames", "1", "--out", "{tmp}/afile/u"],
}
for _name, _argv in UNWRITABLE.items():
    CASES[f"unwritable {_name}"] = (_argv, ["afile is a file, not a folder"])


@pytest.mark.parametrize("case", sorted(CASES))
def test_one_line_and_exit_2(case, tmp_path):
    np.save(tmp_path / "nan.npy", np.full((4, 4, 3), np.nan, np.float32))
    (tmp_path / "afile").write_text("a file where a folder is expected")
    argv, words = CASES[case]
    p = subprocess.run([WORKBENCH, *(a.format(tmp=tmp_path) for a in argv)], cwd=tmp_path,
                       capture_output=True, text=True, timeout=300)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2, p.stderr[-2000:]
    assert len(lines) == 1 and lines[0].startswith("workbench: error: "), p.stderr[-2000:]
    assert "np." not in lines[0]
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not (tmp_path / "x.png").exists() and p.stdout == "", p.stdout  # refused before any work


def test_sizes_below_a_mebibyte_keep_their_value():
    from workbench.core.memory import gib
    assert gib(1024) == "1.0 KiB" and gib(12) == "12 bytes" and gib(3 * 2 ** 20) == "3.0 MiB"
    assert gib(2 ** 30) == "1.0 GiB"


def test_study_points_over_the_memory_limit_are_listed_and_exit_0(tmp_path):
    """Phong at tessellations 12 and 32 needs more than 100 MiB at 32x24, 1 and 4 less: the
    study is written with the points that rendered, the others listed as over_memory (a setting
    refused before it allocates, not a failure: the bundled mesh scene's radiosity needs 300 GiB)."""
    p = subprocess.run([WORKBENCH, "study", "whitted", "--quick", "--methods", "phong", "--size", "32x24",
                        "--max-memory", "100M", "--out", str(tmp_path / "s")], cwd=tmp_path,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    assert "Traceback" not in p.stderr
    assert "tessellation=32: over_memory: method 'phong': 32x24 needs about" in p.stdout
    assert (tmp_path / "s" / "study.csv").stat().st_size > 0


BALL = """[scene]
name = "ball"
[camera]
position = [0, 0, -4]
look_at = [0, 0, 0]
fov_y = 40
resolution = [24, 18]
[[lights]]
type = "point"
position = [-3, 4, -4]
[materials.m]
color = [0.8, 0.4, 0.2]
[[objects]]
type = "sphere"
material = "m"
center = [0, 0, 0]
radius = 1.0
"""


def test_study_with_a_failed_point_exits_1(tmp_path, monkeypatch, capsys):
    """A method's bug at one setting (a fake method registered in place of the real ones: no
    bundled method fails on purpose) is listed and makes the study exit 1, once written."""
    import compare_fakes
    from workbench.app.cli import main
    compare_fakes.install(monkeypatch, compare_fakes.BROKEN)
    scene = tmp_path / "ball.toml"
    scene.write_text(BALL)
    code = main(["study", str(scene), "--methods", "broken", "--reference", "facets", "--size", "24x18",
                 "--repeat", "1", "--out", str(tmp_path / "s")])
    out = capsys.readouterr()
    assert code == 1
    assert "n=64: failed: RuntimeError: a bug of this fake at n = 64" in out.out
    assert "1 of 5 study points failed" in out.err
    assert (tmp_path / "s" / "study.csv").stat().st_size > 0


def test_snapshot_record_keeps_another_scene_stored_under_the_same_name(tmp_path):
    """Recording the same scene again replaces its snapshot; a different scene file with the
    same scene name is refused before rendering, and the stored snapshot is left as it was."""
    from workbench.scene.library import resolve
    other = tmp_path / "whitted.toml"  # another file whose scene is also named whitted
    other.write_text(resolve("whitted").read_text().replace("fov_y =", "fov_y = 30.0\n#", 1))
    snap = tmp_path / "snap"
    opts = ["--methods", "phong", "--size", "16x12", "--dir", str(snap)]
    for scene in ("whitted", "whitted"):
        done = subprocess.run([WORKBENCH, "snapshot", "record", scene, *opts], capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, done.stderr
    before = (snap / "whitted.phong.npy").read_bytes()
    p = subprocess.run([WORKBENCH, "snapshot", "record", str(other), *opts], capture_output=True,
                       text=True, timeout=300)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2 and len(lines) == 1 and "holds scene 'whitted'" in lines[0], p.stderr
    assert (snap / "whitted.phong.npy").read_bytes() == before


def test_snapshot_scenes_may_follow_the_options(tmp_path):
    """``snapshot record --dir D --methods M SCENE`` (the scenes after the options) records, as
    ``snapshot record SCENE --dir D ...`` does (it failed: unrecognized arguments: SCENE)."""
    for action in ("record", "check"):
        p = subprocess.run([WORKBENCH, "snapshot", action, "--dir", str(tmp_path / "snap"), "--methods", "flat",
                            "--size", "16x12", "whitted"], capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
    assert (tmp_path / "snap" / "whitted.flat.npy").is_file()
    p = subprocess.run([WORKBENCH, "snapshot", "check", "--dir", str(tmp_path / "snap"), "whitted", "--bogus"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 2 and "unrecognized arguments: --bogus" in p.stderr
