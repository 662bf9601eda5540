"""The pyrender panel, rendered in a child process.

PyOpenGL picks one platform per process and the window is GLFW/GLX, while pyrender renders
offscreen through EGL (:func:`workbench.renderers.gl.pyrender_platform`): so one child process
(``multiprocessing``, spawn: a fresh interpreter that never imports GLFW or moderngl) runs the
registered ``pyrender`` method.  The UI sends it (scene, camera, options) whenever they change
and keeps showing the last image ("rendering..." meanwhile); at most one request is in flight
and only the newest waiting one is sent next, so a mouse drag does not queue renders.  The
child is asked to stop, then joined (terminated if it does not end) when the window closes.
"""
from __future__ import annotations

import multiprocessing as mp
import time
from dataclasses import replace

METHOD = "pyrender"
STOP_SECONDS = 5.0
DIED = "the pyrender child process ended unexpectedly"
"""How long closing waits for the child to end by itself before terminating it."""


def _serve(conn) -> None:
    """Child process: render each (scene, camera, options) received until ``None``."""
    from ...renderers import gl
    gl.pyrender_platform()          # before anything imports OpenGL
    from ...renderers.base import render
    while True:
        msg = conn.recv()
        if msg is None:
            break
        key, scene, camera, options = msg
        t0 = time.perf_counter()
        try:
            res = render(replace(scene, camera=camera), METHOD, width=camera.width,
                         height=camera.height, **options)
            conn.send((key, res.image, time.perf_counter() - t0, None))
        except Exception as e:  # shown in the panel
            conn.send((key, None, None, f"{type(e).__name__}: {e}"))
    conn.close()


class PyrenderProcess:
    """The child process and the panel's last result.

    Attributes
    ----------
    image : (H, W, 3) float32 of the last finished request, or None.
    image_key : that request's key; ``wanted`` is the newest key asked for.
    seconds : its wall time in the child (scene build + draw); error : message of a failure.
    """

    def __init__(self):
        ctx = mp.get_context("spawn")
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=_serve, args=(child,), name="ui-pyrender", daemon=True)
        self.process.start()
        child.close()
        self.in_flight = None
        self.wanted = None
        self.waiting = None
        self.image = self.image_key = self.seconds = self.error = None

    def request(self, key, scene, camera, options: dict) -> None:
        """Ask for a render of ``key`` (sent now, or after the one in flight)."""
        if key == self.wanted or self.error == DIED:
            return
        self.wanted, self.waiting = key, (key, scene, camera, dict(options))
        self._send()

    def _send(self) -> None:
        if self.in_flight is None and self.waiting is not None:
            try:
                self.conn.send(self.waiting)
            except OSError:  # the child is gone
                self.error, self.waiting = DIED, None
                return
            self.in_flight, self.waiting = self.waiting[0], None

    def poll(self) -> bool:
        """Take the finished results (never waits); True when a new image arrived."""
        new = False
        while self.in_flight is not None and self.conn.poll():
            try:
                key, image, seconds, error = self.conn.recv()
            except (EOFError, OSError):  # the child ended without answering
                self.error, self.in_flight = DIED, None
                return new
            self.in_flight = None
            if error is None:
                self.image, self.image_key, self.seconds, self.error = image, key, seconds, None
                new = True
            else:
                self.error = error
            self._send()
        return new

    @property
    def busy(self) -> bool:
        return self.in_flight is not None or self.waiting is not None

    def close(self) -> None:
        """Stop the child: ask, wait :data:`STOP_SECONDS`, then terminate; always joined."""
        if self.process.is_alive():
            try:
                self.conn.send(None)
            except OSError:  # the child is already gone
                pass
            # a render in flight blocks the child in send() until its image is read: drain
            end = time.monotonic() + STOP_SECONDS
            while self.process.is_alive() and time.monotonic() < end:
                try:
                    if self.conn.poll(0.05):
                        self.conn.recv()
                except (EOFError, OSError):
                    self.process.join(max(0.0, end - time.monotonic()))
                    break
        if self.process.is_alive():
            self.process.terminate()
        self.process.join()
        self.conn.close()


def refresh_pyrender(state) -> None:
    """Per frame: request the panel's render for the current scene, camera and options, and
    take the child's newest image into ``state.images`` (the child starts on first use)."""
    if state.pyrender is None:
        state.pyrender = PyrenderProcess()
    proc = state.pyrender
    opts = state.options[METHOD]
    proc.request((state.scene_version, state.camera, tuple(sorted(opts.items()))),
                 state.scene, state.camera, opts)
    if proc.poll():
        state.images[METHOD] = proc.image
        version, camera = proc.image_key[:2]  # the scene of another version: never the current
        state.image_requests[METHOD] = (camera, state.scene if version == state.scene_version
                                        else version)
        state.timings[METHOD] = proc.seconds
    if proc.error is not None:
        state.status[METHOD] = proc.error
    else:
        state.status[METHOD] = "rendering (child process)..." if proc.busy else "done"
