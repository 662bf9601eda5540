"""An area light emits from its front face; one that faces away from every object lights nothing,
and loading the scene says so (a SceneWarning; the CLI prints one ``workbench: warning:`` line
and still renders).  No bundled scene has such a light."""
from __future__ import annotations

import subprocess
import warnings

import pytest

import workbench
from ui_command import WORKBENCH
from workbench.core.errors import SceneWarning
from workbench.scene.library import bundled, resolve

FRONT = "vertices = [[343.0, 548.0, 227.0], [343.0, 548.0, 332.0], [213.0, 548.0, 332.0], [213.0, 548.0, 227.0]]"
# the same light moved under the floor, still facing down: nothing is in front of it
BELOW = FRONT.replace("548.0", "-10.0")


@pytest.fixture
def turned(tmp_path):
    text = resolve("cornell").read_text()
    assert FRONT in text
    path = tmp_path / "cornell_below.toml"
    path.write_text(text.replace(FRONT, BELOW))
    return path


def test_a_light_facing_away_from_everything_is_warned(turned):
    with pytest.warns(SceneWarning, match="faces away from every object"):
        workbench.load_scene(turned)


def test_the_bundled_scenes_load_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        for p in bundled():
            workbench.load_scene(p)


def test_the_cli_prints_one_warning_line_and_renders(turned, tmp_path):
    p = subprocess.run([WORKBENCH, "render", str(turned), "-m", "raycast", "--size", "16x16",
                        "-o", str(tmp_path / "x.png")], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    lines = [ln for ln in p.stderr.splitlines() if "warning" in ln]
    assert len(lines) == 1 and lines[0].startswith("workbench: warning: ") and "front face" in lines[0]
    assert (tmp_path / "x.png").is_file()
