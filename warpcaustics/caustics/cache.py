"""A process-wide cache bounded in bytes, least recently used out first: the host-side multipliers
of the small-angle transfer and of the sky's cells are computed once per light direction and grid
and kept for the next frames and renderers of the process (a sweep renders each frame with a
renderer of its own)."""

from __future__ import annotations

import collections
from collections.abc import Callable, Hashable
from typing import Any


class BoundedCache:
    """Values by key, up to ``limit_bytes`` in all (each value's size from ``size``); the least
    recently used go first, the newest always stays."""

    def __init__(self, limit_bytes: int, size: Callable[[Any], int]):
        self.limit_bytes = limit_bytes
        self.size = size
        self.entries: collections.OrderedDict = collections.OrderedDict()
        self.total = 0

    def get(self, key: Hashable, make: Callable[[], Any]) -> Any:
        """The value of ``key``, made by ``make()`` (which may use the cache itself) if not kept."""
        if key not in self.entries:
            value = make()
            nbytes = self.size(value)
            self.entries[key] = (value, nbytes)
            self.total += nbytes
            while self.total > self.limit_bytes and len(self.entries) > 1:
                _, (_, dropped) = self.entries.popitem(last=False)
                self.total -= dropped
        self.entries.move_to_end(key)
        return self.entries[key][0]
