"""``workbench methods --support`` (issue #27, item 4), run as users run it: the feature x method
grid agrees with every registered method's declared table, and the reasons follow."""
from __future__ import annotations

import subprocess

from ui_command import WORKBENCH
from workbench.renderers.base import available, get_renderer
from workbench.renderers.support import Status
from workbench.scene import features as ft

MARK = {Status.SUPPORTED: "yes", Status.APPROXIMATED: "approx", Status.LEFT_OUT: "no"}


def test_methods_support_prints_every_declared_cell():
    r = subprocess.run([WORKBENCH, "methods", "--support"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].split() == ["feature", *available()]
    grid = {cells[0]: cells[1:] for cells in (line.split() for line in lines[1:1 + len(ft.ALL)])}
    assert list(grid) == list(ft.ALL)
    for i, method in enumerate(available()):
        table = get_renderer(method).support
        assert [grid[f][i] for f in ft.ALL] == [MARK[table[f].status] for f in ft.ALL], method
        for f, cell in table.items():
            if cell.status is not Status.SUPPORTED:
                assert f"    {f}: {cell.status.value}: {cell.reason}" in lines, (method, f)
    # the methods differ: a grid of one column repeated would pass the loop above only by luck
    assert len({tuple(row) for row in zip(*grid.values())}) > 5


def test_methods_support_rejects_a_value():
    r = subprocess.run([WORKBENCH, "methods", "--support=yes"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "--support" in r.stderr.strip().splitlines()[-1]
