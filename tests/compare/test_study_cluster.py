"""``study`` and ``stress`` on a Dask cluster (``--cluster ADDRESS``): a small study and a small
stress catalogue run through the console script on a ``LocalCluster`` of two worker processes
give the same rows, in the same order, as the local run; a bad address, a missing dask and
workers running other code are each one line ``workbench: error: ...`` with exit 2.

Equality is exact: the same code renders the same inputs (fixed seeds; the reference is
rendered by the command's own process, and read back from the session's reference cache by the
second run), on this machine's CPU, whether in the command's process or in a worker's.  Only
the times (and the Pareto flags, which follow from them) may differ.
"""
from __future__ import annotations

import csv
import json
import os
import socket
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from ui_command import WORKBENCH

distributed = pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[2]
TESTS = Path(__file__).resolve().parent
# the workers import workbench from this checkout, and this module (for the executor tests)
PATH = os.pathsep.join([str(ROOT), str(TESTS)] + [p for p in [os.environ.get("PYTHONPATH")] if p])

STUDY = ["study", "whitted", "--methods", "flat,phong,raycast,radiosity", "--size", "32x24", "--repeat", "1",
         "--reference", "raycast", "--set", "phong:standins=off", "--sweep", "flat:tessellation=1,4",
         "--sweep", "phong:tessellation=2,6", "--sweep", "raycast:spp=1,2",
         "--sweep", "radiosity:hemicube_resolution=8,16"]
"""Cheap methods only (GL raster, the numba ray caster; the ray caster is the reference and the
matched reference of all three); radiosity does not apply (no emitter): both its points say
so, the second one skipped locally and replaced in the grid's order on the cluster."""
TIMING = {"time_s", "warm_s", "cold_s", "compile_s", "pareto", "pareto_rmse", "pareto_flip", "worker"}

CATALOGUE = """
[scenes.ball.scene]
name = "ball"
background = [0.1, 0.1, 0.1]
ambient = [0.2, 0.2, 0.2]
[scenes.ball.camera]
position = [0.0, 0.0, -4.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
[[scenes.ball.lights]]
type = "point"
position = [-3.0, 4.0, -4.0]
[scenes.ball.materials.m]
color = [0.8, 0.4, 0.2]
ks = 0.4
shininess = 20.0
[[scenes.ball.objects]]
type = "sphere"
material = "m"
radius = 1.0

[[case]]
id = "ball-analytic"
title = "a sphere against its exact image"
kind = "scene"
scene = "ball"
size = [32, 24]
methods = ["flat", "phong", "raycast", "no_such_method"]
check = "analytic_spheres"
silhouettes = { "*" = "exclude", raycast = "include" }
tolerance = { "*" = 0.03, raycast = 1e-4 }

[[case]]
id = "ball-shininess-0"
title = "shininess 0"
kind = "scene"
scene = "ball"
size = [32, 24]
set = { "materials.m.shininess" = 0.0 }
methods = ["phong", "raycast"]
check = "finite"

[[case]]
id = "critical-angle-api"
title = "refraction around the critical angle"
kind = "api"
call = "workbench.renderers.raytrace.reference.refraction"
method = "raytrace"
check = "refraction_critical"
tolerance = 1e-12
params = { n1 = 1.5, n2 = 1.0, offsets = [-1e-3, 0.0, 1e-3] }
"""


def _env(**extra) -> dict:
    return {**os.environ, "PYTHONPATH": PATH, **extra}


def _workbench(argv, cwd, timeout=600, **env):
    t = time.perf_counter()
    p = subprocess.run([WORKBENCH, *map(str, argv)], cwd=cwd, capture_output=True, text=True, timeout=timeout,
                       env=_env(**env))
    return p, time.perf_counter() - t


def _one_line_error(p, *words):
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2, p.stderr[-3000:]
    assert len(lines) == 1 and lines[0].startswith("workbench: error: "), p.stderr[-3000:]
    assert "Traceback" not in p.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


@pytest.fixture(scope="module")
def cluster():
    """The address of a LocalCluster: two worker processes of one thread each, started with
    this checkout on their path (workers inherit the environment at their start)."""
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = PATH
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None, silence_logs=40) as c:
            yield c.scheduler_address
    finally:
        if old is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = old


def _ref(reference: dict) -> dict:
    return {k: v for k, v in reference.items() if k not in ("cache", "time_s")}


def _rows(points: list[dict]) -> list[dict]:
    return [{k: v for k, v in p.items() if k not in TIMING} for p in points]


def test_study_on_the_cluster_gives_the_local_rows(cluster, tmp_path):
    local, t_local = _workbench([*STUDY, "--out", tmp_path / "local"], tmp_path)
    assert local.returncode == 0, local.stderr[-3000:]
    remote, t_remote = _workbench([*STUDY, "--out", tmp_path / "remote", "--cluster", cluster], tmp_path)
    assert remote.returncode == 0, remote.stderr[-3000:]
    assert "Traceback" not in remote.stderr and "warning" not in remote.stderr, remote.stderr[-3000:]
    a = json.loads((tmp_path / "local" / "study.json").read_text())
    b = json.loads((tmp_path / "remote" / "study.json").read_text())
    assert a["executor"] == {"kind": "serial", "workers": 1}
    assert b["executor"]["kind"] == "dask" and b["executor"]["workers"] == 2
    assert b["executor"]["address"] == cluster and "Dask cluster" in b["timing_protocol"]
    # the same references (rendered by the first run, read from the cache by the second)
    assert _ref(a["reference"]) == _ref(b["reference"])
    assert {k: _ref(r) for k, r in a["matched_references"].items()} == {
        k: _ref(r) for k, r in b["matched_references"].items()}
    assert _rows(a["points"]) == _rows(b["points"])  # exact: same code, same inputs, same CPU
    got = [(p["method"], p["value"], p["status"]) for p in b["points"]]  # the grid's order
    assert got == [("flat", "1", "ok"), ("flat", "4", "ok"), ("phong", "2", "ok"), ("phong", "6", "ok"),
                   ("raycast", "1", "ok"), ("raycast", "2", "ok"),
                   ("radiosity", "8", "not_applicable"), ("radiosity", "16", "not_applicable")]
    ok = [p for p in b["points"] if p["status"] == "ok"]
    assert all(p["rmse"] > 0 and p["time_s"] > 0 and ":" in p["worker"] for p in ok)
    assert not any("worker" in p for p in a["points"])
    # the CSV: the same rows but for the time and Pareto columns
    keep = [k for k in next(csv.reader((tmp_path / "local" / "study.csv").open())) if k not in TIMING]
    rows = [[{k: r[k] for k in keep} for r in csv.DictReader((tmp_path / d / "study.csv").open())]
            for d in ("local", "remote")]
    assert rows[0] == rows[1] and len(rows[0]) == 8
    print(f"study: local {t_local:.1f} s, on the cluster {t_remote:.1f} s")


def test_stress_on_the_cluster_gives_the_local_rows(cluster, tmp_path):
    """... and so do two local worker processes (--jobs 2)."""
    cat = tmp_path / "cases.toml"
    cat.write_text(textwrap.dedent(CATALOGUE))
    local, _ = _workbench(["stress", "--catalogue", cat, "--out", tmp_path / "local"], tmp_path)
    assert local.returncode == 0, local.stderr[-3000:]
    remote, _ = _workbench(["stress", "--catalogue", cat, "--out", tmp_path / "remote", "--cluster", cluster],
                           tmp_path)
    assert remote.returncode == 0, remote.stderr[-3000:]
    pool, _ = _workbench(["stress", "--catalogue", cat, "--out", tmp_path / "pool", "--jobs", "2"], tmp_path)
    assert pool.returncode == 0, pool.stderr[-3000:]
    a, b, c = (json.loads((tmp_path / d / "stress.json").read_text()) for d in ("local", "remote", "pool"))
    assert (a["executor"]["kind"], b["executor"]["kind"], c["executor"]) == (
        "serial", "dask", {"kind": "processes", "workers": 2})
    strip = [{k: v for k, v in r.items() if k != "time_s"} for r in a["rows"]]
    assert strip == [{k: v for k, v in r.items() if k != "time_s"} for r in b["rows"]]
    assert strip == [{k: v for k, v in r.items() if k != "time_s"} for r in c["rows"]]
    assert [(r["case"], r["method"]) for r in b["rows"]] == [
        ("ball-analytic", "flat"), ("ball-analytic", "phong"), ("ball-analytic", "raycast"),
        ("ball-analytic", "no_such_method"), ("ball-shininess-0", "phong"), ("ball-shininess-0", "raycast"),
        ("critical-angle-api", "raytrace")]
    verdicts = [r["verdict"] for r in b["rows"]]
    assert verdicts[3] == "unavailable: method no_such_method not registered"
    assert all(v == "ok" for i, v in enumerate(verdicts) if i != 3), verdicts
    assert a["summary"] == b["summary"]


def test_workers_running_other_code_are_refused(cluster, tmp_path):
    """A worker whose code differs (here: its code identity replaced) is named, and nothing runs."""
    with distributed.Client(cluster, set_as_default=False) as client:
        client.run(_pretend_other_code, True)
        try:
            p, _ = _workbench(["study", "whitted", "--methods", "flat", "--size", "16x12", "--quick",
                               "--out", tmp_path / "s", "--cluster", cluster], tmp_path)
        finally:
            client.run(_pretend_other_code, False)
    _one_line_error(p, "2 of 2 worker(s) run other workbench code", "install the same workbench version")
    assert not (tmp_path / "s").exists()


def _pretend_other_code(on: bool) -> None:
    import workbench.compare.executors as ex
    if on:
        ex._real_code_identity = ex.code_identity
        ex.code_identity = lambda: "0" * 64
    elif hasattr(ex, "_real_code_identity"):
        ex.code_identity = ex._real_code_identity


def _sleep_then_pid(shared, seconds):
    time.sleep(seconds)
    return shared, seconds, os.getpid()


def _status(_, item):
    return {"method": item[0], "status": item[1], "reason": f"{item[0]} {item[2]}"}


def _skip(item, earlier):
    for r in earlier:
        if r["method"] == item[0] and r["status"] == "not_applicable":
            return {"method": item[0], "status": "not_applicable", "reason": r["reason"]}
    return None


def test_results_come_in_the_items_order_not_the_finishing_order(cluster):
    from workbench.compare.executors import DaskCluster, Serial
    items = [0.6, 0.4, 0.2, 0.0]  # the first finishes last
    with DaskCluster(cluster) as ex:
        got = ex.map(_sleep_then_pid, items, shared="s")
        assert [(s, x) for s, x, _ in got] == [("s", x) for x in items]
        assert len(ex.last_where) == 4 and all(":" in w for w in ex.last_where)
        grid = [("a", "ok", 1), ("a", "not_applicable", 2), ("a", "ok", 3), ("b", "ok", 1)]
        assert ex.map_timed(_status, grid, skip=_skip) == Serial().map_timed(_status, grid, skip=_skip) == [
            {"method": "a", "status": "ok", "reason": "a 1"},
            {"method": "a", "status": "not_applicable", "reason": "a 2"},
            {"method": "a", "status": "not_applicable", "reason": "a 2"},
            {"method": "b", "status": "ok", "reason": "b 1"}]
        assert ex.describe()["workers"] == 2


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("command", ["study", "stress"])
def test_nothing_listening_is_one_line_at_once(command, tmp_path):
    argv = (["study", "whitted", "--methods", "flat", "--size", "16x12", "--quick"] if command == "study"
            else ["stress", "--only", "shininess-0"])
    address = f"tcp://127.0.0.1:{_free_port()}"
    p, seconds = _workbench([*argv, "--out", tmp_path / "o", "--cluster", address], tmp_path, timeout=60)
    _one_line_error(p, f"--cluster {address}: connection refused", "dask scheduler")
    assert seconds < 10 and p.stdout == "" and not (tmp_path / "o").exists()


@pytest.mark.parametrize("address, words", [  # (no host names to look up: loopback only)
    ("localhost", ["not a scheduler address", "tcp://HOST:8786"]),
    ("tcp://127.0.0.1", ["not a scheduler address", "missing port"]),
])
def test_bad_addresses_are_one_line(address, words, tmp_path):
    p, _ = _workbench(["stress", "--only", "shininess-0", "--out", tmp_path / "o", "--cluster", address],
                      tmp_path, timeout=60)
    _one_line_error(p, f"--cluster {address}", *words)


def test_a_server_that_is_not_a_scheduler_times_out_in_one_line(tmp_path):
    """Something listens but never answers (Dask's own client would wait for ever): the
    connection gives up after WORKBENCH_CLUSTER_TIMEOUT seconds."""
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
        p, seconds = _workbench(["stress", "--only", "shininess-0", "--out", tmp_path / "o", "--cluster", address],
                                tmp_path, timeout=60, WORKBENCH_CLUSTER_TIMEOUT="2")
    _one_line_error(p, f"--cluster {address}: no Dask scheduler answered within 2 s")
    assert seconds < 15


@pytest.mark.parametrize("argv", [
    ["study", "whitted", "--methods", "flat", "--size", "16x12", "--quick", "--out", "{tmp}/o"],
    ["stress", "--only", "shininess-0", "--out", "{tmp}/o"],
])
def test_without_dask_the_install_hint(argv, tmp_path):
    """dask not installed (its import made to fail): one line naming the extra to install."""
    code = ("import sys; sys.modules['distributed'] = None\n"
            "from workbench.app.cli import main\n"
            f"sys.exit(main({[a.format(tmp=tmp_path) for a in argv] + ['--cluster', 'tcp://127.0.0.1:8786']!r}))")
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                       env=_env())
    line = _one_line_error(p, "--cluster needs dask distributed: pip install 'workbench[cluster]'")
    assert line == "workbench: error: --cluster needs dask distributed: pip install 'workbench[cluster]'"
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", ["study", "stress"])
def test_cluster_and_jobs_together_are_refused(command, tmp_path, capsys):
    from workbench.app.cli import main
    argv = ([command, "whitted", "--methods", "flat"] if command == "study" else [command]) + [
        "--out", str(tmp_path / "o"), "--jobs", "2", "--cluster", "tcp://127.0.0.1:8786"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == ("workbench: error: --cluster and --jobs 2: give one of them (on a cluster, the number of "
                   "workers sets the parallelism)\n")
    assert not (tmp_path / "o").exists()
