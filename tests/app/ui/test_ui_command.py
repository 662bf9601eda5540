"""``workbench ui SCENE``, the README's command, started as a user starts it (the console script,
under Xvfb) on every bundled scene: the window comes up, the X server shows every panel with an
image in it, and SIGTERM closes it with its child processes and shared memory gone."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from ui_command import ui_command
from workbench.app.ui.screenshot import take
from workbench.scene.library import bundled

pytestmark = pytest.mark.gl
ROOT = Path(__file__).resolve().parents[3]
PANEL_SIZE = 96
POLL_SECONDS = 1.0
"""Time between two captures of the window while waiting for its panels."""
SETTLE_TIMEOUT = 300.0
"""Give up waiting for the panels after this long (they are checked anyway): the mesh's ray
trace (82k triangles) took over 120 s on a loaded 2-core machine, 5 s on an idle one."""
CHILD_GRACE_SECONDS = 5.0
"""How long after the window's exit its children may take to end (the resource tracker ends
when it reads the end of its pipe)."""
SHM_PREFIXES = ("psm_", "sem.mp-", "mp-")
"""Names multiprocessing gives its shared memory and semaphores in /dev/shm."""


def test_help_names_the_real_defaults():
    from workbench.app.ui import WINDOW_SIZE
    from workbench.app.ui.state import EMITTER_VIEW, FIRST_VIEW, MAX_PANELS
    p = subprocess.run([*ui_command(), "--help"], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    text = " ".join(p.stdout.split())
    assert f"default: {','.join(FIRST_VIEW)}, plus {','.join(EMITTER_VIEW)}" in text
    assert f"1 to {MAX_PANELS}" in text
    assert f"default: the size the window had when last closed, else {WINDOW_SIZE[0]}x{WINDOW_SIZE[1]}" in text
    assert "longer side" in text  # --size is one number, not "width and height"


@pytest.fixture(scope="module")
def warm_kernels():
    """Compile the CPU methods of the first views once in this process (the window's jobs then
    load them from the numba cache instead of compiling past the wait)."""
    import workbench
    for name, method in (("whitted", "raytrace"), ("cornell", "pathtrace"), ("cornell", "radiosity")):
        workbench.render(workbench.load_scene(name), method, width=8, height=8)


def _children(pid: int) -> list[int]:
    """Every descendant process of ``pid`` (from /proc)."""
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        for task in Path(f"/proc/{p}/task").glob("*"):
            try:
                kids = [int(k) for k in (task / "children").read_text().split()]
            except OSError:
                continue
            out += kids
            todo += kids
    return out


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _left(pids: list[int], grace: float = CHILD_GRACE_SECONDS) -> list[str]:
    """The command lines of ``pids`` still alive ``grace`` seconds from now (or as soon as all
    are gone)."""
    end = time.monotonic() + grace
    while any(_alive(p) for p in pids) and time.monotonic() < end:
        time.sleep(0.1)
    out = []
    for p in pids:
        if _alive(p):
            try:
                out.append(Path(f"/proc/{p}/cmdline").read_bytes().replace(b"\0", b" ").decode())
            except OSError:
                pass
    return out


def _shm() -> set[str]:
    return {n for n in os.listdir("/dev/shm") if n.startswith(SHM_PREFIXES)}


def _in_use(names: set[str]) -> set[str]:
    """Those of the /dev/shm ``names`` that a live process maps or holds open: another test
    process's (the suite runs on every core) or a concurrent program's, not leaked."""
    paths = {f"/dev/shm/{n}": n for n in names}
    used = set()
    for pid in (d for d in os.listdir("/proc") if d.isdigit()):
        try:
            with open(f"/proc/{pid}/maps") as f:
                used |= {paths[p] for line in f if (p := line.rstrip("\n").split(" ")[-1]) in paths}
            for fd in os.listdir(f"/proc/{pid}/fd"):
                target = os.readlink(f"/proc/{pid}/fd/{fd}")
                if target in paths:
                    used.add(paths[target])
        except OSError:  # the process ended, or is not ours to read
            continue
    return used


def _left_shm(before: set[str]) -> set[str]:
    """Segments made since ``before`` that no live process uses and that are still there once
    the processes were read (multiprocessing unlinks a semaphore right after making it): the
    leaked ones."""
    new = _shm() - before
    return (new - _in_use(new)) & _shm()


def _panels_shown(shot: np.ndarray, rects: dict) -> bool:
    """Every rectangle of ``rects`` shows an image: a panel not drawn yet is black (a furnace's
    image is one flat colour, so flatness is no sign)."""
    return all((shot[y0:y1, x0:x1].max(-1) > 8).mean() > 0.2 for x0, y0, x1, y1 in rects.values())


def _settled_capture(title: str, display: str, proc, rects: dict) -> np.ndarray:
    """The window as the X server shows it once every panel of ``rects`` shows an image (a
    capture every :data:`POLL_SECONDS`, at most :data:`SETTLE_TIMEOUT` of waiting: then the
    last capture, which the caller checks)."""
    end = time.monotonic() + SETTLE_TIMEOUT
    while True:
        assert proc.poll() is None, proc.communicate()[1][-2000:]
        try:
            shot = take(title, display)
        except RuntimeError:  # the window is not mapped yet
            shot = None
        if shot is not None and _panels_shown(shot, rects):
            return shot
        if time.monotonic() > end:
            assert shot is not None, "the window never appeared"
            return shot
        time.sleep(POLL_SECONDS)


def _layout(name: str, display: str, out: Path) -> dict:
    """Where each panel's image is (window pixels), from a short run (``--frames``)."""
    p = subprocess.run([*ui_command(name, "--size", str(PANEL_SIZE), "--frames", "4",
                                    "--out", str(out))],
                       cwd=out.parent, env={**os.environ, "DISPLAY": display}, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    summary = json.loads((out / "summary.json").read_text())
    shown = {m: tuple(round(v) for v in r) for m, r in summary["shown"]}
    assert set(summary["methods"]) <= set(shown), shown
    for m in summary["methods"]:
        x0, y0, x1, y1 = shown[m]
        assert x1 - x0 >= PANEL_SIZE // 2 and y1 - y0 >= PANEL_SIZE // 4, (m, shown[m])
    return {m: shown[m] for m in summary["methods"]}


@pytest.mark.parametrize("name", [p.stem for p in bundled()])
def test_workbench_ui_shows_every_panel_and_ends_cleanly_on_sigterm(name, xvfb, warm_kernels,
                                                                    tmp_path):
    rects = _layout(name, xvfb, tmp_path / "layout")
    shm_before = _shm()
    out = tmp_path / "run"
    proc = subprocess.Popen([*ui_command(name, "--size", str(PANEL_SIZE), "--out", str(out))],
                            cwd=tmp_path, env={**os.environ, "DISPLAY": xvfb},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        shot = _settled_capture(f"workbench ui: {name}", xvfb, proc, rects)
        kids = _children(proc.pid)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + signal.SIGTERM, err[-2000:]
    assert "Traceback" not in err, err[-2000:]
    if name == "whitted":  # its plot's reference (a ray trace) is there: so is the plot's worker
        assert kids, "the window starts child processes (the error plot's worker at least)"
    assert not _left(kids), f"child processes left after SIGTERM: {_left(kids, 0)}"
    assert not _left_shm(shm_before), f"shared memory left in /dev/shm: {sorted(_left_shm(shm_before))}"
    assert shot.std() > 10  # not a blank window
    assert _panels_shown(shot, rects), "a panel shows no image"
    summary = json.loads((out / "summary.json").read_text())
    assert {m: tuple(round(v) for v in r) for m, r in summary["shown"]
            if m in rects} == rects  # the layout the panels were checked in
