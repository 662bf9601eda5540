"""The window's bounded caches (issue #29, item 3): an :class:`LruCache` fed more than its
limits holds at most its bytes and entries, the entries used last surviving; the error plot's
matched boards and the hidden panels are such caches; a thread's GL context is freed when the
thread ends."""
from __future__ import annotations

import threading

import numpy as np
import pytest

from workbench.app.ui.bounded import WINDOW_CACHE_SHARE, LruCache, cache_budget
from workbench.app.ui.state import MATCHED_BOARDS_KEPT, ErrorPlot


def test_fed_more_than_its_bytes_it_keeps_the_most_recent_within_them():
    evicted = []
    cache = LruCache(100, max_bytes=10_000, size_of=lambda a: a.nbytes,
                     on_evict=lambda k, v: evicted.append(k))
    for k in range(40):  # 40 x 1 KB into 10 KB
        cache.put(k, np.zeros(128))
        assert cache.nbytes() <= 10_000
        assert k in cache  # the entry put last always stays
    assert cache.keys() == list(range(31, 40))  # the 9 used last, in order of use
    assert evicted == list(range(31)) and cache.evictions == 31


def test_an_entry_used_again_outlives_the_ones_put_after_it():
    cache = LruCache(3, max_bytes=10**9)
    for k in "abc":
        cache.put(k, k)
    assert cache.get("a") == "a"  # now the most recently used
    cache.put("d", "d")
    assert cache.keys() == ["c", "a", "d"] and "b" not in cache


def test_entries_that_grew_are_evicted_at_the_next_trim():
    sizes = {"a": 10, "b": 10}
    cache = LruCache(5, max_bytes=100, size_of=lambda k: sizes[k])
    cache.put("a", "a")
    cache.put("b", "b")
    sizes["a"] = sizes["b"] = 60  # their renders landed
    cache.trim()
    assert cache.keys() == ["b"] and cache.nbytes() <= 100


def test_one_entry_above_the_budget_stays_alone():
    cache = LruCache(4, max_bytes=10, size_of=len)
    cache.put("small", "x")
    cache.put("big", "y" * 50)
    assert cache.keys() == ["big"]


def test_the_budget_is_a_share_of_the_memory_limit(monkeypatch):
    monkeypatch.setenv("WORKBENCH_MAX_MEMORY", "1G")
    assert cache_budget() == int(WINDOW_CACHE_SHARE * 2**30)
    assert LruCache(2).max_bytes == cache_budget()
    with pytest.raises(ValueError):
        LruCache(0)


class Board:
    """A stand-in for a matched reference's job board: its bytes, its cancel."""

    def __init__(self, nbytes):
        self.bytes, self.kept = nbytes, None

    def nbytes(self):
        return self.bytes

    def keep_only(self, methods):
        self.kept = list(methods)

    def alive(self):
        return False

    def join_all(self, timeout=None):
        pass


def test_the_error_plot_keeps_its_matched_boards_used_last(monkeypatch):
    monkeypatch.setenv("WORKBENCH_MAX_MEMORY", "4M")  # a budget of 1 MiB
    plot = ErrorPlot()
    boards = [Board(300_000) for _ in range(MATCHED_BOARDS_KEPT + 3)]
    for k, b in enumerate(boards):
        plot.matched_boards.put(("pathtrace", k), b)
        assert plot.matched_boards.nbytes() <= cache_budget()
    assert plot.matched_boards.values() == boards[-3:]  # 3 x 300 kB within 1 MiB
    assert all(b.kept == [] for b in boards[:-3])  # evicted: their jobs cancelled
    assert all(b.kept is None for b in boards[-3:])
    assert plot.boards() == boards[-3:]


def test_a_thread_frees_its_gl_context_when_it_ends():
    from workbench.renderers import gl
    made = []

    def work():
        made.append(gl.context())
        gl.end_thread()
        made.append(getattr(gl._local, "ctx", None))

    t = threading.Thread(target=work)
    t.start()
    t.join(60)
    ctx, after = made
    assert after is None
    with pytest.raises(Exception):  # released: no object can be made in it any more
        ctx.buffer(reserve=4)


def _rss() -> int:
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    return 0


def test_threads_that_make_gl_contexts_do_not_grow_the_process():
    """Before: each thread (a background job of the window) that made a context and ended
    left about 2.5 MB behind (Mesa's EGL state of the thread and the context)."""
    from workbench.renderers import gl

    def work():
        ctx = gl.context()
        fbo = ctx.framebuffer([ctx.texture((64, 64), 4)])
        fbo.use()
        ctx.clear(1.0, 0.0, 0.0)
        fbo.read()
        gl.end_thread()

    def threads(n):
        for _ in range(n):
            t = threading.Thread(target=work)
            t.start()
            t.join(60)
    threads(5)  # EGL and llvmpipe loaded, the heap warm
    before = _rss()
    threads(20)
    assert _rss() - before < 15 * 2**20  # without end_thread: about 50 MB


def test_an_entry_in_use_is_not_evicted():
    """The error plot's boards of the current view are pinned: evicted, one would be asked for
    again in the next frame, its render cancelled and started over and over."""
    in_use = {"a", "b"}
    cache = LruCache(2, max_bytes=10**9, pinned=in_use.__contains__)
    for k in "abcd":
        cache.put(k, k)
    assert cache.keys() == ["a", "b", "d"]  # c evicted; a and b in use, d used last
    in_use.clear()
    cache.trim()
    assert cache.keys() == ["b", "d"]


def test_only_the_panels_hidden_last_keep_their_images():
    from workbench.app.ui.panel_memory import HIDDEN_PANELS_KEPT, keep_hidden, window_bytes
    from workbench.app.ui.state import new_state
    state = new_state("whitted", ["phong"], panel_size=32)
    image = np.zeros((24, 32, 3), np.float32)
    hidden = ["flat", "gouraud", "raycast", "raytrace"]
    for m in ["phong", *hidden]:  # each shown, then hidden, in turn
        state.methods[:] = [m]
        state.images[m] = image.copy()
        state.image_requests[m] = (state.camera, state.scene)
        keep_hidden(state)
    kept = hidden[-1 - HIDDEN_PANELS_KEPT:-1]
    assert state.hidden_panels.keys() == kept
    assert set(state.images) == {"raytrace", *kept}  # the older ones' images freed
    assert set(state.image_requests) == {"raytrace", *kept}
    assert window_bytes(state)["hidden"] == HIDDEN_PANELS_KEPT * image.nbytes
    state.methods[:] = [kept[0]]  # shown again: no longer hidden, its image still there
    keep_hidden(state)
    assert kept[0] not in state.hidden_panels and kept[0] in state.images
