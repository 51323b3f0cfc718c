"""What a derived-array cache offers the layers that cannot import the cell's disk cache.

:mod:`planner.cell.disk_cache` keeps arrays on disk by kind, key and version; ``planner.faces``
and ``planner.cad`` sit below ``planner.cell`` and take such a store as an argument typed by
:class:`ArrayCache` (the jobs pass the module itself).
"""

from __future__ import annotations

from typing import Protocol

from numpy.typing import NDArray


class ArrayCache(Protocol):
    """A store of named arrays by kind, key and version (the cell's disk cache,
    :mod:`planner.cell.disk_cache`, which this layer does not import)."""

    def load_arrays(self, kind: str, key: str, version: int) -> dict[str, NDArray] | None:
        """The arrays stored under ``kind`` and ``key`` for ``version``, or ``None``."""
        ...

    def save_arrays(self, kind: str, key: str, version: int, arrays: dict[str, NDArray]) -> None:
        """Store ``arrays``; a failure only costs the next read its time."""
        ...
