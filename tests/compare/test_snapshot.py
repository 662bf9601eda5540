"""Snapshot tests for users: ``workbench snapshot record|check`` and the pytest plugin
``workbench.testing`` (record then check passes; a changed material fails with the difference
image and heat map written and a one-line message; update rewrites; a missing snapshot fails
with the command that records it; bad arguments exit 2 with one line)."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from workbench.compare.snapshot import check, record
from workbench.scene.io import load_scene
from workbench.testing import SnapshotMismatch, assert_snapshot

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.gl

SCENE = """
[scene]
name = "ball"
description = "one sphere on a floor"
background = [0.2, 0.3, 0.5]
ambient = [0.1, 0.1, 0.1]

[camera]
position = [0.0, 1.0, -4.0]
look_at = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov_y = 45.0
resolution = [64, 48]

[[lights]]
type = "point"
position = [-3.0, 4.0, -3.0]
color = [1.0, 1.0, 1.0]
intensity = 1.0

[materials.ball]
color = COLOR
ka = 0.2
kd = 0.7
ks = 0.3
shininess = 40.0

[materials.floor]
color = [0.8, 0.8, 0.8]
ka = 0.2
kd = 0.8
ks = 0.0
shininess = 1.0

[[objects]]
type = "sphere"
center = [0.0, 0.6, 0.0]
radius = 0.6
material = "ball"

[[objects]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
size = [8.0, 8.0]
material = "floor"
"""
RED, BLUE = "[0.9, 0.2, 0.1]", "[0.1, 0.3, 0.9]"


def _scene_file(folder: Path, color: str) -> Path:
    p = folder / "ball.toml"
    p.write_text(SCENE.replace("COLOR", color))
    return p


def _wb(*args, cwd, env=None):
    e = dict(os.environ, PYTHONPATH=str(ROOT), **(env or {}))
    return subprocess.run([sys.executable, "-m", "workbench", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, env=e, timeout=300)


def test_record_check_fail_update_cli(tmp_path):
    scene = _scene_file(tmp_path, RED)
    snaps = tmp_path / "snaps"
    r = _wb("snapshot", "record", scene, "--methods", "phong,flat", "--dir", snaps, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    for stem in ("ball.phong", "ball.flat"):
        assert (snaps / f"{stem}.npy").is_file() and (snaps / f"{stem}.png").is_file()
        assert (snaps / f"{stem}.json").is_file()
    stored = np.load(snaps / "ball.phong.npy")
    assert stored.dtype == np.float32 and stored.shape == (48, 64, 3)
    r = _wb("snapshot", "check", scene, "--methods", "phong,flat", "--dir", snaps, cwd=tmp_path)
    assert r.returncode == 0 and r.stdout.count("ok ") == 2, r.stdout + r.stderr

    _scene_file(tmp_path, BLUE)  # the material changed
    r = _wb("snapshot", "check", scene, "--methods", "phong", "--dir", snaps, "--metric", "rmse",
            "--tolerance", "0.01", cwd=tmp_path)
    assert r.returncode == 1
    (line,) = [x for x in r.stdout.splitlines() if x.startswith("FAILED")]
    assert "ball / phong" in line and "rmse" in line and "> tolerance 0.01" in line
    value = float(line.split("rmse ")[1].split()[0])
    assert value > 0.01
    for suffix in (".diff.png", ".heat.png", ".actual.png", ".actual.npy"):
        assert (snaps / f"ball.phong{suffix}").is_file(), suffix
    assert np.array_equal(np.load(snaps / "ball.phong.npy"), stored)  # not touched by a failure
    assert not (snaps / "ball.flat.diff.png").exists()

    r = _wb("snapshot", "check", scene, "--methods", "phong", "--dir", snaps, "--update", cwd=tmp_path)
    assert r.returncode == 0 and "updated" in r.stdout, r.stdout + r.stderr
    assert np.abs(np.load(snaps / "ball.phong.npy") - stored).max() > 0.1
    assert not (snaps / "ball.phong.diff.png").exists()  # failure files removed on update
    r = _wb("snapshot", "check", scene, "--methods", "phong", "--dir", snaps, "--metric", "flip", cwd=tmp_path)
    assert r.returncode == 0, r.stdout


def test_missing_snapshot_fails_with_the_record_command(tmp_path):
    r = _wb("snapshot", "check", "whitted", "--methods", "phong", "--dir", tmp_path / "none",
            "--size", "32x24", cwd=tmp_path)
    assert r.returncode == 1
    assert f"record it with: workbench snapshot record whitted --methods phong --dir {tmp_path / 'none'} " \
           f"--size 32x24" in r.stdout
    assert not (tmp_path / "none").exists()


@pytest.mark.parametrize("args, expect", [
    (["snapshot", "keep", "whitted", "--methods", "phong", "--dir", "d"], "action must be record or check"),
    (["snapshot", "check", "--methods", "phong", "--dir", "d"], "at least one SCENE"),
    (["snapshot", "check", "whitted", "--dir", "d"], "--methods needs at least one method"),
    (["snapshot", "check", "whitted", "--methods", "phong"], "--dir is required"),
    (["snapshot", "check", "whitted", "--methods", "nope", "--dir", "d"], "unknown method(s) nope"),
    (["snapshot", "check", "whitted", "--methods", "phong", "--dir", "d", "--metric", "ssim"], "metric must be one of rmse, flip"),
    (["snapshot", "check", "whitted", "--methods", "phong", "--dir", "d", "--tolerance", "-1"], "finite number >= 0"),
    (["snapshot", "check", "whitted", "--methods", "phong", "--dir", "d", "--tolerance", "nan"], "finite number >= 0"),
    (["snapshot", "check", "whitted", "--methods", "phong", "--dir", "d", "--size", "3x"], "--size"),
    (["snapshot", "check", "nosuchscene", "--methods", "phong", "--dir", "d"], "no such scene"),
    (["snapshot", "record", "whitted", "--methods", "phong", "--dir", "d", "--tolerance", "1"], "belong to check"),
    (["snapshot", "check", "whitted", "--methods", "glsl:missing.glsl", "--dir", "d"], "no such file"),
])
def test_bad_arguments_are_one_line(tmp_path, args, expect):
    r = _wb(*args, cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and expect in r.stderr, r.stderr
    assert not list(tmp_path.iterdir()), "nothing written on bad arguments"


def test_assert_snapshot_api(tmp_path, monkeypatch):
    monkeypatch.delenv("WORKBENCH_SNAPSHOT_UPDATE", raising=False)
    path = _scene_file(tmp_path, RED)
    with pytest.raises(SnapshotMismatch, match="no stored image.*WORKBENCH_SNAPSHOT_UPDATE=1"):
        assert_snapshot(path, "phong", tmp_path / "s")
    monkeypatch.setenv("WORKBENCH_SNAPSHOT_UPDATE", "1")
    assert assert_snapshot(path, "phong", tmp_path / "s").status == "updated"
    monkeypatch.delenv("WORKBENCH_SNAPSHOT_UPDATE")
    assert assert_snapshot(path, "phong", tmp_path / "s", metric="flip").status == "passed"
    # a size other than the stored one fails (not silently re-recorded)
    with pytest.raises(SnapshotMismatch, match="size 32x24 differs from the stored 64x48"):
        assert_snapshot(path, "phong", tmp_path / "s", size=(32, 24))
    # a damaged stored image is bad input
    (tmp_path / "s" / "ball.flat.npy").write_bytes(b"not numpy")
    from workbench.core.errors import WorkbenchError
    with pytest.raises(WorkbenchError, match="not a snapshot image"):
        check(load_scene(path), "flat", tmp_path / "s")
    assert record(load_scene(path), "flat", tmp_path / "s").status == "recorded"


PLUGIN_TEST = '''
from pathlib import Path

def test_ball(snapshot):
    snapshot.check(str(Path(__file__).parent / "ball.toml"), "phong", metric="rmse", tolerance=0.002)
'''


def test_pytest_plugin(tmp_path):
    """A user's test file with the ``snapshot`` fixture, run by pytest with the plugin."""
    _scene_file(tmp_path, RED)
    (tmp_path / "test_user.py").write_text(textwrap.dedent(PLUGIN_TEST))

    def pytest_run(*extra, env=None):
        return _wb_pytest(tmp_path, *extra, env=env)

    r = pytest_run()
    assert r.returncode == 1 and "no stored image" in r.stdout and "pytest --snapshot-update" in r.stdout
    r = pytest_run("--snapshot-update")
    assert r.returncode == 0, r.stdout
    assert (tmp_path / "snapshots" / "ball.phong.npy").is_file()
    assert pytest_run().returncode == 0
    _scene_file(tmp_path, BLUE)
    r = pytest_run()
    assert r.returncode == 1
    (line,) = [x for x in r.stdout.splitlines() if "snapshot ball / phong: rmse" in x and "Failed" in x]
    assert "> tolerance 0.002" in line and "Traceback" not in r.stdout
    assert (tmp_path / "snapshots" / "ball.phong.diff.png").is_file()
    assert (tmp_path / "snapshots" / "ball.phong.heat.png").is_file()
    before = np.load(tmp_path / "snapshots" / "ball.phong.npy")
    assert pytest_run(env={"WORKBENCH_SNAPSHOT_UPDATE": "1"}).returncode == 0
    assert np.abs(np.load(tmp_path / "snapshots" / "ball.phong.npy") - before).max() > 0.1  # rewritten
    assert not (tmp_path / "snapshots" / "ball.phong.diff.png").exists()


def _wb_pytest(folder: Path, *extra, env=None):
    e = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="1000")  # summary lines unshortened
    e.pop("WORKBENCH_SNAPSHOT_UPDATE", None)
    e.update(env or {})
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "workbench.testing", "-p", "no:cacheprovider",
                           "-o", "addopts=", "--rootdir", str(folder), "test_user.py", *extra],
                          capture_output=True, text=True, cwd=folder, env=e, timeout=300)
