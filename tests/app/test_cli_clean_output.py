"""What the commands print and write holds no Python/numpy internals: no ``RuntimeWarning``
(or any other warning) on stderr, and no numpy 2 scalar repr such as ``np.float64(3.27)`` in
stdout, stderr or the text files written (JSON, CSV, HTML, Markdown).

Each command runs as the console script, as users run it (issue #26, item 4).  The JSON files
must also parse as strict JSON (no ``NaN``/``Infinity`` tokens).  ``stats_for_display`` (what
``render`` prints and writes) turns numpy scalars into Python numbers: a stat holding numpy
scalars in a list printed as ``[np.float32(0.1), ...]``.
"""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from ui_command import WORKBENCH
from workbench.renderers.base import stats_for_display

SIZE = "24x18"

COMMANDS = {
    "scenes": [["scenes"]],
    "methods": [["methods"]],
    "info": [["info", "kinds"], ["info", "cornell"]],
    "render raster": [["render", "whitted", "-m", "phong", "--size", SIZE, "-o", "{out}/a.png",
                       "--json", "{out}/a.json", "--display", "indexed8-kmeans-fs"],
                      ["render", "kinds", "-m", "zbuffer", "--size", SIZE, "-o", "{out}/b.png",
                       "--json", "{out}/b.json"]],
    "render radiosity": [["render", "cornell", "-m", "radiosity", "--size", SIZE, "-o", "{out}/r.png",
                          "--json", "{out}/r.json"]],
    "render raytrace": [["render", "whitted", "-m", "raytrace", "--size", SIZE, "-o", "{out}/t.png",
                         "--json", "{out}/t.json"]],
    "render pathtrace": [["render", "furnace", "-m", "pathtrace", "--size", SIZE, "-o", "{out}/p.png",
                          "--json", "{out}/p.json", "--set", "spp=2"]],
    "colour": [["colour", "wheel", "--size", "32", "-o", "{out}/w.png"],
               ["colour", "display", "whitted", "--mode", "indexed8-kmeans-fs", "-o", "{out}/d.png"],
               ["colour", "display", "{out}/zeros.npy", "--mode", "indexed4-mediancut-bayer", "-o", "{out}/z.png"]],
    "compare": [["compare", "whitted", "--methods", "flat,gouraud,zbuffer", "--reference", "phong",
                 "--size", SIZE, "--out", "{out}/cmp"]],
    "study": [["study", "whitted", "--quick", "--methods", "flat,phong", "--reference", "phong",
               "--size", SIZE, "--repeat", "1", "--out", "{out}/study"]],
    "snapshot": [["snapshot", "record", "whitted", "--methods", "flat", "--size", SIZE, "--dir", "{out}/snap"],
                 ["snapshot", "check", "whitted", "--methods", "flat", "--dir", "{out}/snap"]],
    "stress": [["stress", "--only", "shininess-*", "--out", "{out}/stress"]],
}


def _text_files(folder: Path):
    for p in sorted(folder.rglob("*")):
        if p.is_file() and p.suffix in (".json", ".csv", ".html", ".md", ".txt"):
            yield p


@pytest.mark.parametrize("command", list(COMMANDS))
def test_no_warning_and_no_numpy_repr(command, tmp_path):
    np.save(tmp_path / "zeros.npy", np.zeros((6, 8, 3), np.float32))  # a black image: 0/0 in the metrics
    env = {**os.environ, "PYTHONWARNINGS": "default"}  # every warning shown, none turned into an error
    for argv in COMMANDS[command]:
        argv = [a.format(out=tmp_path) for a in argv]
        p = subprocess.run([WORKBENCH, *argv], capture_output=True, text=True, cwd=tmp_path, env=env,
                           timeout=600)
        assert p.returncode == 0, (argv, p.stderr[-2000:])
        warned = [line for line in p.stderr.splitlines() if "Warning" in line]
        assert not warned, (argv, warned)
        for where, text in (("stdout", p.stdout), ("stderr", p.stderr)):
            assert "np." not in text, (argv, where, text[-2000:])
    for f in _text_files(tmp_path):
        text = f.read_text()
        assert "np." not in text, (f, text[:2000])
        if f.suffix == ".json":
            json.loads(text, parse_constant=lambda c: pytest.fail(f"{f}: {c} is not JSON"))


def test_stats_for_display_holds_python_numbers_only():
    shown = stats_for_display({"a": np.float32(0.5), "b": [np.float64(1.5), np.int64(2)],
                               "c": (np.float32(0.25),), "d": {"e": np.bool_(True)}, "f": np.array([3.0]),
                               "g": np.zeros((2, 2)), "h": "text"})
    assert repr(shown) == ("{'a': 0.5, 'b': [1.5, 2], 'c': (0.25,), 'd': {'e': True}, 'f': 3.0, "
                           "'g': 'array (2, 2) float64, RMS 0', 'h': 'text'}")
    assert "np." not in f"{shown}"
