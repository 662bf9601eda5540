"""The command line: fast help, clear errors (one line, exit 2, no traceback)."""
from __future__ import annotations

import subprocess
import sys
import time

import pytest


def _wb(*args, timeout=300):
    return subprocess.run([sys.executable, "-m", "workbench.app.cli", *args], capture_output=True,
                          text=True, timeout=timeout)


def test_help_is_fast_and_lists_commands():
    t = time.perf_counter()
    r = _wb("--help")
    elapsed = time.perf_counter() - t
    assert r.returncode == 0 and "render" in r.stdout and "scenes" in r.stdout
    assert elapsed < 3.0  # includes interpreter start-up; the import itself is ~0.2 s
    for heavy in ("moderngl", "numba", "pyrender", "matplotlib", "trimesh"):
        r = subprocess.run([sys.executable, "-c", f"import workbench.app.cli as c, sys; c.build_parser(); "
                            f"sys.exit('{heavy}' in sys.modules)"], capture_output=True)
        assert r.returncode == 0, f"{heavy} imported by --help"


@pytest.mark.parametrize("args, expect", [
    (["info", "no_such_scene"], "no such scene file"),
    (["render", "whitted", "--method", "nope", "-o", "x.png"], "unknown method 'nope'"),
    (["render", "whitted", "-o", "x.jpg"], "must be a .png"),
])
def test_errors_are_one_line_without_traceback(args, expect, tmp_path):
    r = subprocess.run([sys.executable, "-m", "workbench.app.cli", *args], capture_output=True, text=True,
                       cwd=tmp_path, timeout=300)
    assert r.returncode == 2
    assert expect in r.stderr and "Traceback" not in r.stderr
    assert not list(tmp_path.iterdir()), "no output file on error"


def test_bad_scene_file_exit_code(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('[camera]\nposition = [0, 0, -5]\nlook_at = [0, 0, 0]\n[[objects]]\ntype = "sphere"\nradius = -1\nmaterial = "x"\n')
    r = _wb("info", str(p))
    assert r.returncode == 2 and "s.toml" in r.stderr and "material" in r.stderr and "Traceback" not in r.stderr


def test_bad_option_value_is_reported():
    r = _wb("render", "whitted", "--size", "12xx", "-o", "x.png")
    assert r.returncode == 2 and "WIDTHxHEIGHT" in r.stderr


def test_scenes_lists_every_bundled_scene():
    from workbench.scene.library import bundled
    r = _wb("scenes")
    assert r.returncode == 0
    for p in bundled():
        assert p.stem in r.stdout
    assert "(does not load" not in r.stdout
