"""A cache of the window bounded by count and by bytes, least recently used out first.

What the window keeps for later (the resources of panels hidden a moment ago, the error plot's
matched references) must not grow with the length of a session (issue #29, item 3: the resident
size of a window in ordinary use went from 354 MB to 1.18 GB in 11.5 minutes).  Each such cache
is an :class:`LruCache` holding at most ``max_items`` entries and ``max_bytes`` bytes, by
default :func:`cache_budget`: :data:`WINDOW_CACHE_SHARE` of the memory limit every render is
checked against (:func:`workbench.core.memory.memory_limit`: ``--max-memory``,
``WORKBENCH_MAX_MEMORY``, else half the physical memory).
"""
from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Iterator

WINDOW_CACHE_SHARE = 0.25
"""Share of the memory limit that one cache of the window may hold."""


def cache_budget(max_memory=None) -> int:
    """Bytes one cache of the window may hold: :data:`WINDOW_CACHE_SHARE` of the memory limit
    (:func:`workbench.core.memory.memory_limit` of ``max_memory``)."""
    from ...core.memory import memory_limit
    return int(WINDOW_CACHE_SHARE * memory_limit(max_memory))


class LruCache:
    """``{key: value}`` in order of use (the most recent last), bounded by count and bytes.

    ``size_of(value)`` is the bytes an entry holds, asked again whenever the cache is trimmed
    (an entry may grow after it was put: a board whose reference render finished); ``on_evict(key,
    value)`` frees what an evicted entry holds.  :meth:`put` and :meth:`trim` evict the least
    recently used entries until at most ``max_items`` remain holding at most ``max_bytes``
    together; the entry used last is never evicted (alone above ``max_bytes``, it stays alone),
    nor one that ``pinned(key)`` says is in use (the cache then holds more than its bounds until
    it is not).

    Attributes
    ----------
    evictions : entries evicted so far.
    """

    def __init__(self, max_items: int, max_bytes: int | None = None,
                 size_of: Callable[[object], int] = lambda value: 0,
                 on_evict: Callable[[object, object], None] | None = None,
                 pinned: Callable[[object], bool] = lambda key: False):
        if max_items < 1:
            raise ValueError(f"max_items must be at least 1, got {max_items}")
        self.max_items = int(max_items)
        self.max_bytes = cache_budget() if max_bytes is None else int(max_bytes)
        self.size_of, self.on_evict, self.pinned = size_of, on_evict, pinned
        self._entries: OrderedDict = OrderedDict()
        self.evictions = 0

    def put(self, key, value) -> None:
        """Set ``key`` (now the most recently used) and trim."""
        self._entries[key] = value
        self._entries.move_to_end(key)
        self.trim()

    def get(self, key, default=None):
        """``key``'s value, which becomes the most recently used, else ``default``."""
        if key not in self._entries:
            return default
        self._entries.move_to_end(key)
        return self._entries[key]

    def pop(self, key, default=None):
        """Remove ``key`` without evicting it (``on_evict`` is not called)."""
        return self._entries.pop(key, default)

    def nbytes(self) -> int:
        """Bytes held by every entry (``size_of`` summed)."""
        return sum(int(self.size_of(v)) for v in self._entries.values())

    def trim(self) -> None:
        """Evict the least recently used entries beyond ``max_items`` or ``max_bytes``."""
        sizes = {k: int(self.size_of(v)) for k, v in self._entries.items()}
        total = sum(sizes.values())
        last = next(reversed(self._entries), None)
        for key in list(self._entries):  # least recently used first
            if len(self._entries) <= self.max_items and total <= self.max_bytes:
                break
            if key == last or self.pinned(key):
                continue
            value = self._entries.pop(key)
            total -= sizes[key]
            self.evictions += 1
            if self.on_evict is not None:
                self.on_evict(key, value)

    def keys(self) -> list:
        return list(self._entries)

    def values(self) -> list:
        return list(self._entries.values())

    def items(self) -> list:
        return list(self._entries.items())

    def __contains__(self, key) -> bool:
        return key in self._entries

    def __len__(self) -> int:
        return len(self._entries)

    def __iter__(self) -> Iterator:
        return iter(list(self._entries))
