"""Where the runs of a grid (a study's points, the stress catalogue's rows) execute.

Three places, one interface (:class:`Executor`), so the grid code does not care which:

* :class:`Serial`: in this process, one after the other (``--jobs 1``, the default);
* :class:`ProcessPool`: ``--jobs N`` local worker processes (``spawn``: fresh processes, not
  forks of one holding GL contexts and numba threads);
* :class:`DaskCluster`: the workers of a Dask distributed scheduler (``--cluster ADDRESS``).
  Dask is imported only here and only then: it is the optional extra ``workbench[cluster]``.

Two kinds of work:

* :meth:`Executor.map`: untimed work (error metrics, stress cases), spread over the workers;
* :meth:`Executor.map_timed`: work whose wall time is measured (a study's renders).  Local
  executors run it in this process, one item at a time, whatever ``--jobs`` is: on a small
  machine a parallel worker would steal a core from the run being timed.  On a cluster it runs
  on the workers, each timing its own item (one thread per worker: docs/guide/cluster.md).

Both return the results in the order of the items (the grid's order), never in the order they
finished, so a grid's rows are the same whichever executor ran them.  Each function is called
as ``fn(shared, item)``: ``shared`` is sent to a cluster once (scattered), not with every item.

A cluster's workers must run the same workbench code as this process: :func:`code_identity`
(a hash over the package's Python sources and its shaders and scenes) is compared on connect,
and again with every result, and a cluster whose workers differ is refused.
"""
from __future__ import annotations

import hashlib
import os
import pickle
import platform
import socket
import sys
import uuid
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Sequence

from ..core.errors import WorkbenchError

CONNECT_TIMEOUT = 10.0
"""Seconds to wait for a scheduler to answer (and for it to have a worker) before giving up;
the environment variable ``WORKBENCH_CLUSTER_TIMEOUT`` overrides it."""
TIMEOUT_ENV = "WORKBENCH_CLUSTER_TIMEOUT"
PROPAGATED_ENV = ("WORKBENCH_MAX_MEMORY",)
"""Environment variables of this process that hold for its renders on a cluster's workers too
(``--max-memory``); a variable not set here leaves the worker's own value."""
INSTALL_HINT = "pip install 'workbench[cluster]'"
DATA_HASHED = ("shaders", "scenes")
"""Bundled data folders that :func:`code_identity` covers besides the Python sources."""

Done = Callable[[int], None]
"""Called with an item's index when its result is in (progress bars)."""


@lru_cache(maxsize=1)
def code_identity() -> str:
    """SHA-256 (hex) over the workbench's Python sources and the bundled shaders and scenes,
    by their path inside the package (the same for a checkout and an installed wheel)."""
    from ..core.resources import data_dir
    root = Path(__file__).resolve().parents[1]
    files = [(f"workbench/{p.relative_to(root).as_posix()}", p) for p in root.rglob("*.py")
             if not {"_data", "__pycache__"} & set(p.relative_to(root).parts)]
    for name in DATA_HASHED:
        d = data_dir(name)
        files += [(f"{name}/{p.relative_to(d).as_posix()}", p) for p in d.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc"]
    h = hashlib.sha256()
    for rel, p in sorted(files):
        h.update(rel.encode() + b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def identity() -> dict:
    """This process: its code's :func:`code_identity` and what else its results depend on."""
    import numpy
    try:
        import numba
        numba_version = numba.__version__
    except ImportError:
        numba_version = "none"
    from .. import __version__
    return {"code": code_identity(), "workbench": __version__, "python": platform.python_version(),
            "numpy": numpy.__version__, "numba": numba_version, "host": socket.gethostname()}


class Executor:
    """Runs ``fn(shared, item)`` for every item; results in the items' order.  This base class
    is the serial one; use as a context manager (``with open_executor(...) as ex``)."""

    kind = "serial"
    workers = 1
    last_where: list = []
    """Where each item of the last :meth:`map` ran (``"host:pid"``); empty for a local executor."""

    def map(self, fn: Callable, items: Sequence, shared: Any = None, done: Done | None = None) -> list:
        """Untimed work: ``[fn(shared, item) for item in items]``, spread over the workers."""
        return self._serial(fn, items, shared, None, done)

    def map_timed(self, fn: Callable, items: Sequence, shared: Any = None,
                  skip: Callable[[Any, list], Any] | None = None, done: Done | None = None) -> list:
        """Timed work: like :meth:`map`, but locally always in this process, one at a time.

        ``skip(item, earlier)`` (optional) is asked before each item, with the results of the
        items before it: a result other than None is used instead of running the item (a
        method that does not apply to the scene is not run again).  Executors that run items
        at once run them all and apply ``skip`` afterwards, in order: the same results."""
        return self._serial(fn, items, shared, skip, done)

    @staticmethod
    def _serial(fn, items, shared, skip, done) -> list:
        out: list = []
        for i, item in enumerate(items):
            r = skip(item, out) if skip is not None else None
            out.append(fn(shared, item) if r is None else r)
            if done is not None:
                done(i)
        return out

    def describe(self) -> dict:
        """What ran the grid, for the result files."""
        return {"kind": self.kind, "workers": self.workers}

    def where_timed(self) -> str:
        """Where :meth:`map_timed` runs, in words (a study's timing protocol)."""
        return "sequential in one process"

    def where_untimed(self) -> str:
        """Where :meth:`map` runs, in words."""
        return "in-process"

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class Serial(Executor):
    """Everything in this process, one item after the other."""


def _call(fn, shared, item):
    return fn(shared, item)


class ProcessPool(Executor):
    """``jobs`` local worker processes (spawned on first use) for untimed work."""

    kind = "processes"

    def __init__(self, jobs: int):
        self.workers = int(jobs)
        self._pool = None

    def map(self, fn, items, shared=None, done=None) -> list:
        if len(items) < 2:  # not worth starting a process
            return self._serial(fn, items, shared, None, done)
        if self._pool is None:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor
            self._pool = ProcessPoolExecutor(max_workers=self.workers,
                                             mp_context=multiprocessing.get_context("spawn"))
        from concurrent.futures import as_completed
        futures = {self._pool.submit(_call, fn, shared, item): i for i, item in enumerate(items)}
        out: list = [None] * len(items)
        for f in as_completed(futures):
            out[futures[f]] = f.result()
            if done is not None:
                done(futures[f])
        return out

    def where_untimed(self) -> str:
        return f"in {self.workers} worker processes"

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None


# --------------------------------------------------------------------------- Dask distributed
def _identity_probe():
    """A function run on every worker on connect (``Client.run``).  Built here, nested, so that
    cloudpickle sends it by value: it must answer even where workbench does not import."""
    def probe():
        try:
            from workbench.compare.executors import identity
            return identity()
        except Exception as e:  # noqa: BLE001 -- reported to the user, worker by worker
            return {"error": f"{type(e).__name__}: {e}"}
    return probe


def _task_runner():
    """The function every cluster task calls, built nested so that cloudpickle sends it by
    value: recent Dask schedulers unpickle a task's function and arguments, and this one names
    nothing of workbench.  The workbench function and the item travel as pickled
    bytes, unpickled on the worker only: the scheduler needs no workbench installed."""
    def run(payload: bytes, shared):
        import pickle
        fn, env, item = pickle.loads(payload)
        from workbench.compare.executors import _remote_call
        return _remote_call(fn, env, shared, item)
    return run


def _remote_call(fn, env: dict, shared, item):
    """One item on a worker: this process's propagated environment set for its duration;
    returns ``(code identity, "host:pid", result)``."""
    old = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        result = fn(shared, item)
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    return code_identity(), f"{socket.gethostname()}:{os.getpid()}", result


def _probe_scheduler(address: str, timeout: float) -> dict:
    """The scheduler's ``identity`` reply, within ``timeout`` seconds in all (a port where
    something else listens never answers: ``Client`` alone would wait on it for ever)."""
    import asyncio
    import threading

    import distributed.comm
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        if scheme == "tcp":  # said at once: Dask retries a refused connection until the timeout
            host, port = parse_host_port(location)
            socket.create_connection((host, port), timeout=timeout).close()
    except ValueError as e:
        raise WorkbenchError(f"--cluster {address}: not a scheduler address ({e}); expected e.g. "
                             "tcp://HOST:8786") from None
    except socket.gaierror as e:
        raise WorkbenchError(f"--cluster {address}: unknown host ({e.strerror or e})") from None
    except ConnectionRefusedError:
        raise WorkbenchError(f"--cluster {address}: connection refused (no scheduler listens there; start "
                             "one with: dask scheduler)") from None
    except (TimeoutError, socket.timeout):
        raise WorkbenchError(f"--cluster {address}: no answer within {timeout:g} s") from None
    except OSError as e:
        raise WorkbenchError(f"--cluster {address}: cannot connect ({e.strerror or e})") from None

    async def ask():
        comm = await distributed.comm.connect(address, timeout=timeout)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    box: dict = {}

    def run():  # its own thread and event loop: the caller may be inside one (a notebook)
        try:
            box["reply"] = asyncio.run(asyncio.wait_for(ask(), timeout))
        except BaseException as e:  # noqa: BLE001 -- handed to the caller
            box["error"] = e

    t = threading.Thread(target=run, name="workbench-cluster-probe", daemon=True)
    t.start()
    t.join(timeout + 5)
    if "reply" in box:
        return box["reply"]
    e = box.get("error")
    if e is None or isinstance(e, (TimeoutError, asyncio.TimeoutError)):
        why = f"no Dask scheduler answered within {timeout:g} s"
    elif isinstance(e, ValueError):  # a malformed address
        why = f"not a scheduler address ({e}); expected e.g. tcp://HOST:8786"
    else:
        why = f"cannot connect ({' '.join(str(e).split()) or type(e).__name__})"
    raise WorkbenchError(f"--cluster {address}: {why}")


class DaskCluster(Executor):
    """The workers of the Dask scheduler at ``address`` (``tcp://HOST:8786``)."""

    kind = "dask"

    def __init__(self, address: str, timeout: float = CONNECT_TIMEOUT):
        self.client = None
        try:
            import distributed
        except ImportError:
            raise WorkbenchError(f"--cluster needs dask distributed: {INSTALL_HINT}") from None
        self._distributed = distributed
        self.address = address
        reply = _probe_scheduler(address, timeout)
        if not isinstance(reply, dict) or reply.get("type") != "Scheduler":
            raise WorkbenchError(f"--cluster {address}: the server there is not a Dask scheduler "
                                 f"(it says it is {reply.get('type') if isinstance(reply, dict) else reply!r})")
        try:
            self.client = distributed.Client(address, timeout=timeout, set_as_default=False)
        except (OSError, ValueError) as e:
            raise WorkbenchError(f"--cluster {address}: cannot connect ({' '.join(str(e).split())})") from None
        try:
            self._check_workers(timeout)
        except BaseException:
            self.close()
            raise
        self._token = uuid.uuid4().hex[:8]

    def _check_workers(self, timeout: float) -> None:
        try:
            self.client.wait_for_workers(1, timeout=timeout)
        except (TimeoutError, OSError):
            raise WorkbenchError(f"--cluster {self.address}: the scheduler has no worker after {timeout:g} s; "
                                 f"start some with: dask worker {self.address} --nthreads 1") from None
        here = identity()
        answers = self.client.run(_identity_probe())
        self.identities = answers
        broken = {w: a["error"] for w, a in answers.items() if "error" in a}
        if broken:
            w, why = sorted(broken.items())[0]
            raise WorkbenchError(f"--cluster {self.address}: {len(broken)} of {len(answers)} worker(s) cannot "
                                 f"load workbench (worker {w}: {why}): install workbench, the same version "
                                 f"as here, on every worker")
        other = {w: a for w, a in answers.items() if a["code"] != here["code"]}
        if other:
            w, a = sorted(other.items())[0]
            raise WorkbenchError(
                f"--cluster {self.address}: {len(other)} of {len(answers)} worker(s) run other workbench code "
                f"than this process (code {a['code'][:12]} workbench {a['workbench']} on {w}; here "
                f"{here['code'][:12]} workbench {here['workbench']}): install the same workbench version on "
                f"every worker")
        versions = {k: sorted({a[k] for a in answers.values()} | {here[k]}) for k in ("python", "numpy", "numba")}
        mixed = {k: v for k, v in versions.items() if len(v) > 1}
        if mixed:  # same code, other libraries: errors may differ in the last digits
            print("workbench: warning: --cluster: the workers' libraries differ from this process's ("
                  + "; ".join(f"{k} {', '.join(v)}" for k, v in mixed.items()) + "): results may differ "
                  "in the last digits from a local run", file=sys.stderr)
        self.workers = len(answers)
        self.code = here["code"]

    def map(self, fn, items, shared=None, done=None) -> list:
        if not items:
            return []
        client = self.client
        env = {k: os.environ[k] for k in PROPAGATED_ENV if k in os.environ}
        # on every worker: one that dies (a nanny's restart past its memory limit) takes no
        # item's input with it
        shared_f = client.scatter([shared], hash=False, broadcast=True)[0]
        name = getattr(fn, "__name__", "task").strip("_")
        run, batch = _task_runner(), uuid.uuid4().hex[:6]
        futures = [client.submit(run, pickle.dumps((fn, env, item), protocol=pickle.HIGHEST_PROTOCOL),
                                 shared_f, pure=False, key=f"workbench-{name}-{self._token}-{batch}-{i}")
                   for i, item in enumerate(items)]
        index = {f.key: i for i, f in enumerate(futures)}
        out: list = [None] * len(items)
        self.last_where = [None] * len(items)
        try:
            for f in self._distributed.as_completed(futures, loop=client.loop):
                i = index[f.key]
                code, where, result = self._result(f)
                if code != self.code:
                    raise WorkbenchError(f"--cluster {self.address}: worker {where} runs other workbench code "
                                         f"than this process (joined after the check?): install the same "
                                         f"workbench version on every worker")
                out[i], self.last_where[i] = result, where
                if done is not None:
                    done(i)
        finally:
            client.cancel([f for f in futures if not f.done()])
            del shared_f
        return out

    def _result(self, future):
        try:
            return future.result()
        except WorkbenchError:
            raise
        except ModuleNotFoundError as e:
            raise WorkbenchError(f"--cluster {self.address}: a worker cannot import {e.name or 'a module'} "
                                 f"({e}): install workbench, the same version as here, on every worker") from None
        except Exception as e:  # the cluster's failure (a worker died, the scheduler went away)
            if type(e).__module__.split(".")[0] in ("distributed", "tornado", "asyncio", "concurrent") \
                    or isinstance(e, (OSError, TimeoutError)):
                raise WorkbenchError(f"--cluster {self.address}: task {future.key} was lost on the cluster (a "
                                     f"worker died or left, or the scheduler went away): {type(e).__name__}: "
                                     f"{' '.join(str(e).split())}") from None
            raise  # the grid's own code failed: its traceback, as in a local run

    def map_timed(self, fn, items, shared=None, skip=None, done=None) -> list:
        results = self.map(fn, items, shared, done)
        if skip is None:
            return results
        out: list = []
        for item, r in zip(items, results):
            s = skip(item, out)
            out.append(r if s is None else s)
        return out

    def where_timed(self) -> str:
        return (f"on the {self.workers} worker(s) of the Dask cluster {self.address}, each point's calls on one "
                "worker (named in the point's `worker`)")

    def where_untimed(self) -> str:
        return f"on the {self.workers} worker(s) of the Dask cluster {self.address}"

    def describe(self) -> dict:
        hosts = sorted({a.get("host", "?") for a in getattr(self, "identities", {}).values()})
        return {"kind": self.kind, "address": self.address, "workers": self.workers, "hosts": hosts,
                "code": self.code[:16]}

    def close(self) -> None:
        client = getattr(self, "client", None)
        if client is not None:
            self.client = None
            try:
                client.close(timeout=CONNECT_TIMEOUT)
            except Exception:  # noqa: BLE001 -- closing a connection already lost
                pass


def check_options(jobs: int, cluster: str | None) -> None:
    """``--jobs`` at least 1, and not above 1 together with ``--cluster`` (the cluster's workers
    set the parallelism there)."""
    if int(jobs) < 1:
        raise WorkbenchError(f"--jobs must be >= 1, got {jobs}")
    if cluster and int(jobs) > 1:
        raise WorkbenchError(f"--cluster and --jobs {jobs}: give one of them (on a cluster, the number of "
                             "workers sets the parallelism)")


def connect_timeout() -> float:
    """:data:`CONNECT_TIMEOUT`, or the value of ``WORKBENCH_CLUSTER_TIMEOUT`` (seconds)."""
    text = os.environ.get(TIMEOUT_ENV, "").strip()
    if not text:
        return CONNECT_TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value < float("inf"):
        raise WorkbenchError(f"{TIMEOUT_ENV} must be a positive number of seconds, got {text!r}")
    return value


def open_executor(jobs: int = 1, cluster: str | None = None, timeout: float | None = None) -> Executor:
    """The executor for ``--jobs`` and ``--cluster``: a cluster when an address is given (then
    ``jobs`` must be 1), else a local pool when ``jobs > 1``, else this process.  ``timeout``:
    seconds to wait for the scheduler (default :func:`connect_timeout`)."""
    check_options(jobs, cluster)
    if cluster:
        return DaskCluster(cluster, connect_timeout() if timeout is None else timeout)
    return ProcessPool(int(jobs)) if int(jobs) > 1 else Serial()
