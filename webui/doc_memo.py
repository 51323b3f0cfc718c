"""Results worked out for a plan the session had before, kept for when undo or redo brings it
back.

The session plan is immutable (:mod:`webui.state`): an undo or redo makes current again the
very plan object it was before, not an equal copy. What the app worked out from that object
and nothing else that has changed since (its role flags, its cycle time from the same
checks, its layout quality on the same part, the check of a point as it was shown then) is
therefore still right, and :class:`DocMemo` hands it back instead of working it out again:
an undo of a click no longer waits for the cycle-time estimate or the layout quality of the
plan it returns to (``bench/bench_ui_latency.py --demo-browser``).

Entries are keyed by the plan's identity (``is``, never ``==``: two equal plans built apart
may differ in what the key does not hold) and by a ``tag`` compared with ``==`` (e.g. the
point id and the cell's generation); the memo holds its plans, so an identity is never
reused while its entry lives.

The bound is :attr:`DocMemo.size` entries in all, one per (plan, tag) pair, whatever the
number of plans and tags (the oldest used goes first): the memory is bounded by the size, not by
plans times points. A memo keyed by the plan alone (role flags, cycle time, layout quality) so
reaches back ``size`` plans; one keyed by plan and point (the checks) ``size`` point checks, one
per point a step changed (a single-point edit takes one entry, a new sensor one per point).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Hashable
from typing import Generic, TypeVar

V = TypeVar("V")

#: Entries a memo keeps by default, in all (an undo or redo reaches back this many results).
DEFAULT_SIZE = 64


class DocMemo(Generic[V]):
    """Values stored by (plan object, tag) pair, one per pair and at most ``size`` in all;
    thread-safe.

    Args:
        size: how many entries to keep in all, over every plan and tag (the oldest used goes
            first).
    """

    def __init__(self, size: int = DEFAULT_SIZE) -> None:
        if size < 1:
            raise ValueError(f"size: must be >= 1, got {size}")
        self.size = size
        self._items: OrderedDict[tuple[int, Hashable], tuple[object, V]] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, doc: object, tag: Hashable = None) -> V | None:
        """The value stored for this very ``doc`` object and an equal ``tag``, or ``None``."""
        key = (id(doc), tag)
        with self._lock:
            hit = self._items.get(key)
            if hit is None or hit[0] is not doc:
                return None
            self._items.move_to_end(key)
            return hit[1]

    def put(self, doc: object, value: V, tag: Hashable = None) -> None:
        """Store ``value`` for ``doc`` (held by the memo) and ``tag``."""
        key = (id(doc), tag)
        with self._lock:
            self._items[key] = (doc, value)
            self._items.move_to_end(key)
            while len(self._items) > self.size:
                self._items.popitem(last=False)

    def clear(self) -> None:
        """Forget every entry (e.g. a new cell: what was worked out in the old one is not
        right in it)."""
        with self._lock:
            self._items.clear()

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)
