"""A small in-process memo of values computed from content: bounded and safe across threads.

The web UI checks in threads, and the CLI, the UI and scripts open cells of the same robot and
part again and again; what is derived from their content alone (a robot's reach model, a link's
sphere tree, a part's ray caster, a program's landing risk) is kept here under a content hash,
so the next cell or check finds it. A value is kept until ``size`` newer keys push it out.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Generic, TypeVar

K = TypeVar("K")
V = TypeVar("V")


class Memo(Generic[K, V]):
    """At most ``size`` values by key; the oldest stored goes first when it is full."""

    def __init__(self, size: int) -> None:
        if size < 1:
            raise ValueError(f"a memo holds at least one value, not {size}")
        self._size = size
        self._values: OrderedDict[K, V] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: K) -> V | None:
        """The value kept for ``key``, or ``None``."""
        with self._lock:
            return self._values.get(key)

    def put(self, key: K, value: V) -> V:
        """Keep ``value`` for ``key`` and return what is kept: when another thread stored one
        for the same key first, that one (both were computed from the same content)."""
        with self._lock:
            kept = self._values.setdefault(key, value)
            while len(self._values) > self._size:
                self._values.popitem(last=False)
            return kept

    def clear(self) -> None:
        """Forget every value."""
        with self._lock:
            self._values.clear()

    def __len__(self) -> int:
        with self._lock:
            return len(self._values)
