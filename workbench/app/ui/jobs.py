"""Methods that render on the CPU (``ui_kind`` ``"cpu"`` or ``"progressive"``,
:data:`workbench.renderers.base.UI_KINDS`) in background threads.

A :class:`Job` renders one (scene, camera, method, options) request with
:func:`workbench.renderers.base.render`; methods that accept ``on_tile`` fill ``partial`` band
by band, so the UI shows the image as it comes.  A job whose request is superseded is
*cancelled*: its next ``on_tile`` raises :class:`Cancelled`, which ends the render early in its
own thread (methods without ``on_tile`` finish in the background and their result is dropped).
The UI thread never waits on a job except at exit (:func:`join_all`).

The window must not starve while a job runs: each job thread runs numba's parallel loops with
one thread fewer than the machine has cores (``numba.set_num_threads`` is per calling thread;
on 2 cores that is one thread, and with the OpenMP threading layer the loops then run in the
job thread itself) at niceness :data:`JOB_NICE` (Linux nice values are per thread, and OpenMP
workers inherit their creator's), so the UI thread and llvmpipe's threads win every contended
core.  ``Job.version`` grows with every new tile: the UI re-uploads a
job's image only then.

A superseded job is cancelled at once, but the UI's board starts the new one only once the
request has stayed the same for :data:`RESTART_SETTLE_SECONDS` (the camera rests after a drag,
a slider is let go): a ray trace restarted at every frame of a drag is cancelled at its first
band, so it never shows more than one band, yet each restart sets the scene up again (flat
arrays, BVH, the primary rays of every sample) on the cores the window needs.  Meanwhile the
panel shows its previous image marked stale.

Every long job reports how far it is (``Job.meter``, a :class:`.meter.Meter`: a progressive
job's samples per pixel of its target, a tiled job's rows, a shooting radiosity's rounds with
the unshot share of the emitted power), which the panel shows as a progress bar with the time
left.  A method whose options include ``on_pass`` and that is not progressive (radiosity's
progressive refinement) is rendered with ``on_pass(shots, image, unshot, progress)``: each
round's image is shown as it lands.  A method whose options include ``on_progress`` (the
hybrid method's passes, the outside programs POV-Ray and Mitsuba) is rendered with
``on_progress(phase, done, total, unit)``: each phase gets a meter of its own (``total`` None:
not measured, an indeterminate bar with the time elapsed), and a cancelled job's next report
raises :class:`Cancelled` (an outside program is then ended).

The error plot's boards render references (``JobBoard(cached=True, share=...)``): a reference
is first looked up in the CLI's disk cache (:mod:`workbench.compare.reference_cache`, keyed by
the scene as data, the method, its options, the size and the code), stored there once
rendered, and a job of the very same request on another board (the path tracer's panel at its
finest knob is the emitter scenes' reference) is shared rather than rendered twice, whichever
board started it: the reference takes the panel's job, and a panel the reference's (issue #29).
"""
from __future__ import annotations

import os
import threading
import time
from dataclasses import replace

import numpy as np

from ...renderers.base import check_memory, convert_options, get_renderer
from .meter import Meter

PASS_SAMPLES = 1 << 16
"""Samples (over the whole image) per pass of a progressive job: a 256 x 192 panel gets one
sample per pixel per pass, so its image and noise refresh several times a second at first."""
RESTART_SETTLE_SECONDS = 0.15
"""How long a new request must stay unchanged before the UI's board starts its job (0 for the
error plot's reference board, which waits for a still camera itself)."""
JOB_NICE = 10
"""Niceness added to each job thread (0: none; the maximum is 19).  bench/ui_fps.py measures
the frame rate and the ray trace's completion time with it."""


def job_key(scene, camera, method: str, options: dict) -> tuple:
    """What a background render depends on: the scene object (a :class:`Job` keeps it alive, so
    its id is not reused while the job is current), the camera, the method and its options."""
    return (id(scene), camera, method, tuple(sorted(options.items())))


class Cancelled(Exception):
    """Raised inside a superseded job's ``on_tile`` to stop its render."""


class Job:
    """One background render.

    Attributes
    ----------
    partial : (H, W, 3) float32, the image so far (zeros where not rendered yet).
    image : (H, W, 3) float32 or None, the finished image.
    seconds : wall time of the finished render, or None.
    error : message of a failed render, or None.
    version : number of changes of ``partial``/``image``/``error`` so far.
    spp, noise : a progressive job's samples per pixel so far and its noise (RMS standard
    error of the pixel means; None before two samples).
    passes : a progressive job's passes done so far.
    meter : :class:`.meter.Meter` of a job that reports its progress (progressive, tiled or
    with ``on_pass``), else None.
    shoots : the method is not progressive but reports rounds through ``on_pass``
    (radiosity's progressive refinement): each round's image is shown whole.
    phased : the method reports its phases through ``on_progress`` (its meter is the
    current phase's; tiles, if it has them, only bring the image).
    cached : ``stats["cache"]`` of a job rendered through the reference cache (``"hit"``:
    loaded, not rendered; ``"miss"``...), else None.
    """

    def __init__(self, scene, camera, method: str, options: dict, tiled: bool, notify=None,
                 cached: bool = False):
        # the job keeps its scene: while the job is current no later scene can reuse the id
        # in its key (every material or light edit builds a new Scene)
        self.scene = scene
        self.key = job_key(scene, camera, method, options)
        self.camera = camera
        self.partial = np.zeros((camera.height, camera.width, 3), np.float32)
        self.image = None
        self.seconds = None
        self.error = None
        self.rows_done = 0
        self.version = 0
        self.begun = time.perf_counter()  # the elapsed time a job that reports no progress shows
        # a progressive method's job refines one image pass after pass (a session with
        # add_samples(n), image, samples and noise_rmse): the panel shows the running image, its
        # samples per pixel and noise, and the job ends at the method's spp option
        r = get_renderer(method)
        self.progressive = r.ui_kind == "progressive"
        self.spp, self.noise, self.passes = 0, None, 0
        self.shots, self.unshot = 0, 1.0  # a shooting job's rounds so far (radiosity)
        # a non-progressive method with on_pass (radiosity's shooting) shows each round
        self.shoots = not self.progressive and "on_pass" in r.options
        self.phased = "on_progress" in r.options
        target = options.get(r.knob.name, r.knob.default)  # checked in the thread
        self.meter = (Meter("spp", int(target)) if self.progressive
                      else Meter("shots") if self.shoots
                      else Meter("") if self.phased
                      else Meter("rows", camera.height) if tiled else None)
        self.cached = None
        self.options = dict(options)
        self.holders: set[int] = set()
        """Ids of the boards whose current job this is (two when shared)."""
        self.cancelled = threading.Event()
        self.lock = threading.Lock()
        self.notify = notify
        opts = dict(options)
        if tiled:
            opts["on_tile"] = self._on_tile
        if self.shoots:
            opts["on_pass"] = self._on_round
        if self.phased:
            opts["on_progress"] = self._on_progress
        self.thread = threading.Thread(
            target=self._run, args=(replace(scene, camera=camera), method, opts, cached),
            name=f"ui-job-{method}", daemon=False)
        self.thread.start()

    def _on_tile(self, y0, y1, x0, x1, tile):
        if self.cancelled.is_set():
            raise Cancelled
        with self.lock:
            self.partial[y0:y1, x0:x1] = tile
            self.rows_done = max(self.rows_done, y1)
            if not self.phased:
                self.meter.update(self.rows_done)
            self.version += 1
        self._notify()

    def _on_round(self, shots, image, unshot, progress):
        """A shooting round of progressive refinement (radiosity's ``on_pass``): its image
        shown, ``unshot`` (share of the emitted power still unshot) and ``progress`` (the way
        done to the stopping rule, in [0, 1]) in the meter."""
        if self.cancelled.is_set():
            raise Cancelled
        with self.lock:
            self.partial = np.asarray(image, np.float32)
            self.rows_done = self.partial.shape[0]  # every row holds this round
            self.meter.update(shots, progress, f"unshot {100 * unshot:.2g} %")
            self.shots, self.unshot = shots, unshot
            self.version += 1
        self._notify()

    def _on_progress(self, phase: str, done: int, total: int | None, unit: str = ""):
        """A phased method's report (``on_progress``): ``done`` of ``total`` ``unit`` in
        ``phase`` (``total`` None: not measured); a new phase starts a new meter (its own
        rate and time left)."""
        if self.cancelled.is_set():
            raise Cancelled
        with self.lock:
            m = self.meter
            if m.first is None or (m.phase, m.unit, m.target) != (phase, unit, total or None):
                self.meter = Meter(unit, total or None, phase=phase)
            self.meter.update(done)
        self._notify()

    def _on_spp(self, spp, image, std_error):
        """A pass of a progressive method rendered by ``render`` (a reference job): the
        running image and the meter."""
        if self.cancelled.is_set():
            raise Cancelled
        with self.lock:
            self.partial, self.spp = np.asarray(image, np.float32), int(spp)
            self.meter.update(self.spp)
            self.version += 1
        self._notify()

    def _notify(self) -> None:
        if self.notify is not None:
            self.notify()

    def _run(self, scene, method, opts, cached):
        from ...renderers import gl
        try:
            self._render(scene, method, opts, cached)
        finally:  # a GL context the render made in this thread would outlive it (leaked)
            gl.end_thread()

    def _render(self, scene, method, opts, cached):
        import numba

        from ...renderers.base import render
        numba.set_num_threads(max(1, min(numba.config.NUMBA_NUM_THREADS, (os.cpu_count() or 1) - 1)))
        if JOB_NICE and hasattr(os, "setpriority"):
            tid = threading.get_native_id()
            os.setpriority(os.PRIO_PROCESS, tid, min(19, os.getpriority(os.PRIO_PROCESS, tid) + JOB_NICE))
        t0 = time.perf_counter()
        try:
            if cached:
                image = self._cached(scene, method, opts)
            elif self.progressive:
                image = self._refine(scene, method, opts)
            else:
                image = render(scene, method, width=scene.camera.width,
                               height=scene.camera.height, **opts).image
        except Cancelled:
            return
        except Exception as e:  # shown in the panel, never kills the UI
            with self.lock:
                self.error = f"{type(e).__name__}: {e}"
                self.version += 1
            self._notify()
            return
        with self.lock:
            self.image = np.asarray(image, np.float32)
            self.seconds = time.perf_counter() - t0
            self.version += 1
        self._notify()

    def _refine(self, scene, method: str, opts: dict) -> np.ndarray:
        """A progressive render: passes of :data:`PASS_SAMPLES` samples until the knob's
        value (``opts["spp"]``) of samples per pixel, each pass's running image in ``partial`` (cancelled between
        passes); returns the final image."""
        r = get_renderer(method)
        w, h = scene.camera.width, scene.camera.height
        opts = convert_options(r, opts)
        check_memory(r, scene, w, h, opts)  # as render() does first
        target = int(opts[r.knob.name])
        session = r.progressive_session(scene, w, h, **opts)
        per_pass = max(1, PASS_SAMPLES // (w * h))
        while session.samples < target:
            if self.cancelled.is_set():
                raise Cancelled
            image = session.add_samples(min(per_pass, target - session.samples))
            noise = session.noise_rmse
            with self.lock:
                self.partial, self.spp, self.noise = image, session.samples, noise
                self.passes += 1
                self.meter.update(self.spp, detail="" if noise is None else f"noise {noise:.3g}")
                self.version += 1
            self._notify()
        return session.image

    def _cached(self, scene, method: str, opts: dict) -> np.ndarray:
        """The render through the reference cache (:mod:`workbench.compare.reference_cache`,
        the CLI's): loaded if stored for this scene (as data), size, method and options, else
        rendered (a progressive method through ``render`` with ``on_pass``, so the meter
        moves) and stored; ``self.cached`` says which."""
        from ...compare.reference_cache import cache_key, load_entry, store_entry
        from ...renderers.base import render
        w, h = scene.camera.width, scene.camera.height
        key = cache_key(scene, method, w, h, **self.options)
        hit = load_entry(key)
        if hit is not None:
            self.cached = "hit"
            return hit.image
        if self.progressive:
            opts = {**opts, "on_pass": self._on_spp}
        result = render(scene, method, width=w, height=h, **opts)
        try:
            store_entry(key, result, scene.name, convert_options(get_renderer(method), self.options))
            self.cached = "miss"
        except OSError as e:  # a read-only or full disk costs the cache, not the render
            self.cached = f"miss (not stored: {e})"
        return result.image

    def snapshot(self) -> tuple[np.ndarray, dict]:
        """The finished image, else a copy of the partial one, with what it holds, read in the
        same lock as the image (the thread goes on meanwhile): ``done``, ``rows_done``, a
        progressive job's ``spp``, ``passes`` and ``noise``, a shooting job's ``shots`` and
        ``unshot``."""
        with self.lock:
            image = self.image if self.image is not None else self.partial.copy()
            held = {"done": self.image is not None, "rows_done": self.rows_done}
            if self.progressive:
                held.update(spp=self.spp, passes=self.passes, noise=self.noise)
            if self.shoots:
                held.update(shots=self.shots, unshot=self.unshot)
            return image, held

    @property
    def done(self) -> bool:
        return self.image is not None or self.error is not None

    def nbytes(self) -> int:
        """Bytes of the images the job holds (the partial one and the finished one)."""
        with self.lock:
            image = 0 if self.image is None or self.image is self.partial else self.image.nbytes
            return self.partial.nbytes + image


class JobBoard:
    """The current job of each CPU method plus the threads started and not yet ended (joined
    at exit).  An ended job that is no longer current is forgotten at the next start: each job
    holds its scene and two images, so a long session kept them all (hundreds of MB).

    ``settle``: seconds a changed request must stay the same before its job starts (the old
    job is cancelled at once); ``waiting[method]`` is (request key, when it was first seen);
    ``notify``: called with no argument from a job's thread when it has new tiles, its image
    or an error (the window wakes its loop with it), or None; ``count``: jobs started so far;
    ``cached``: its jobs go through the reference cache (:meth:`Job._cached`; the error plot's
    reference boards); ``share``: the other boards whose current job of the same request is
    taken instead of starting one: a board, or a function of no argument giving a list of them
    (the panels' board asks the error plot for its reference boards, which are made later); a
    job two boards hold is not cancelled when one of them moves on to another request (the
    other still wants its image)."""

    def __init__(self, settle: float = 0.0, notify=None, cached: bool = False, share=None):
        self.settle = settle
        self.notify = notify
        self.cached = cached
        self.share = share
        self.current: dict[str, Job] = {}
        self.started: list[Job] = []
        self.waiting: dict[str, tuple] = {}
        self.count = 0

    def request(self, scene, camera, method: str, options: dict, tiled: bool) -> Job:
        """The job for this request: the current one if its key matches (and it was not
        cancelled before it ended: back at a cancelled request, e.g. after a camera reset, the
        render starts again); else the old one is
        cancelled and a new one starts once the old thread has ended and the request has not
        changed for ``settle`` seconds (at most one thread per method, so a mouse drag does not
        pile up renders: meanwhile the old image shows).  The first request of a method
        starts at once."""
        key = job_key(scene, camera, method, options)
        job = self.current.get(method)
        if job is not None and job.key == key:
            if job.cancelled.is_set() and job.done and not job.thread.is_alive():
                job.cancelled.clear()  # it ended before the cancel: its image is the answer
            if not job.cancelled.is_set():  # a cancelled one stopped short: started again
                self.waiting.pop(method, None)
                return job
        now = time.perf_counter()
        seen = self.waiting.get(method)
        if seen is None or seen[0] != key:
            seen = self.waiting[method] = (key, now)
        if job is not None and job.holders - {id(self)}:
            # another board still wants it (a reference taken from a panel): it runs on there
            job.holders.discard(id(self))
            job = None
        if job is not None:
            job.cancelled.set()
            if job.thread.is_alive() or now - seen[1] < self.settle:
                return job
        del self.waiting[method]
        theirs = self._shared(method, key)
        if theirs is not None:  # another board renders this very request: shared
            self.current[method] = theirs
            theirs.holders.add(id(self))
            if theirs.notify is None:  # its new tiles wake this board's window too
                theirs.notify = self.notify
            return theirs
        job = Job(scene, camera, method, options, tiled, self.notify, self.cached)
        job.holders.add(id(self))
        self.current[method] = job
        current = set(map(id, self.current.values()))
        self.started = [j for j in self.started if j.thread.is_alive() or id(j) in current]
        self.started.append(job)
        self.count += 1
        return job

    def _shared(self, method: str, key: tuple):
        """The running (not cancelled) job of request ``key`` that a board of ``share`` holds
        for ``method``, or None."""
        boards = self.share() if callable(self.share) else [] if self.share is None else [self.share]
        for board in boards:
            theirs = board.current.get(method) if board is not self else None
            if theirs is not None and theirs.key == key and not theirs.cancelled.is_set():
                return theirs
        return None

    def keep_only(self, methods) -> None:
        """Cancel and forget the jobs of methods no longer shown (a removed panel's render
        must not run on to its end)."""
        for m in [m for m in self.current if m not in methods]:
            job = self.current.pop(m)
            job.holders.discard(id(self))
            if not job.holders:  # else another board (the error plot's reference) still wants it
                job.cancelled.set()
            self.waiting.pop(m, None)

    def nbytes(self) -> int:
        """Bytes of the images its current jobs hold (:meth:`Job.nbytes`)."""
        return sum(j.nbytes() for j in self.current.values())

    def alive(self) -> bool:
        """A thread it started has not ended."""
        return any(j.thread.is_alive() for j in self.started)

    def busy(self) -> bool:
        """A job is running or its result is stale (a restart is pending)."""
        return any(j.thread.is_alive() or j.cancelled.is_set() for j in self.current.values())

    def join_all(self, timeout: float | None = None) -> None:
        """Cancel everything and join every thread started."""
        for j in self.started:
            j.cancelled.set()
        for j in self.started:
            j.thread.join(timeout)
