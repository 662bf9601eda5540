"""Every command the README gives a user, run the way the user runs it: the ``workbench`` console
script as a subprocess (``tests/app/ui/test_ui_command.py`` does ``workbench ui``).  Each command the
README names must have an entry in :data:`RUNS`, so a command added to the README without a test
fails here."""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from ui_command import WORKBENCH

ROOT = Path(__file__).resolve().parents[2]
SIZE = "24x18"

RUNS = {  # command -> (arguments, files it must write into the output folder, text on stdout)
    "scenes": ([], [], "whitted"),
    "info": (["whitted"], [], "whitted"),
    "methods": ([], [], "raytrace"),
    "render": (["whitted", "-m", "phong", "--size", SIZE, "-o", "{out}/phong.png"], ["phong.png"], ""),
    "compare": (["whitted", "--methods", "phong,raycast", "--size", SIZE, "--out", "{out}"],
                ["report.html", "report.json"], ""),
    "study": (["whitted", "--quick", "--methods", "flat", "--size", SIZE, "--out", "{out}"],
              ["study.csv", "study.json"], ""),
    "stress": (["--only", "shininess-0", "--out", "{out}"], ["stress.json", "stress.csv"], ""),
    "snapshot": (["record", "whitted", "--methods", "phong", "--size", SIZE, "--dir", "{out}"], [], ""),
    "colour": (["display", "whitted", "-o", "{out}/display.png"], ["display.png"], ""),
}
ELSEWHERE = {"ui": "tests/app/ui/test_ui_command.py"}


def test_every_command_the_readme_names_is_run_here():
    named = set(re.findall(r"\bworkbench (\w+)", (ROOT / "README.md").read_text()))
    from workbench.app.cli import COMMANDS
    commands = {c.removeprefix("cmd_") for c in COMMANDS}
    assert commands <= set(RUNS) | set(ELSEWHERE), commands - set(RUNS) - set(ELSEWHERE)
    assert named & commands <= set(RUNS) | set(ELSEWHERE)


@pytest.mark.parametrize("command", sorted(RUNS))
def test_the_console_script_runs(command, tmp_path):
    args, files, text = RUNS[command]
    argv = [WORKBENCH, command, *(a.format(out=tmp_path) for a in args)]
    p = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, (argv, p.stderr[-2000:])
    assert "Traceback" not in p.stderr and "RuntimeWarning" not in p.stderr, p.stderr[-2000:]
    assert text in p.stdout
    for f in files:
        assert (tmp_path / f).stat().st_size > 0, f
    if command == "snapshot":  # the check of what was just recorded passes
        check = [WORKBENCH, "snapshot", "check", "whitted", "--methods", "phong", "--dir", str(tmp_path)]
        c = subprocess.run(check, cwd=tmp_path, capture_output=True, text=True, timeout=600)
        assert c.returncode == 0, c.stderr[-2000:]


def test_a_bad_argument_is_one_line_and_exit_2(tmp_path):
    p = subprocess.run([WORKBENCH, "render", "nosuchscene", "-m", "phong", "-o", str(tmp_path / "x.png")],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("workbench: error: "), p.stderr
    assert not (tmp_path / "x.png").exists()
