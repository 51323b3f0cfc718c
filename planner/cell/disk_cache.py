"""Per-user disk cache of derived arrays (distance fields), keyed by content hashes.

Files live in ``$WOBJCAL_CACHE_DIR/<kind>`` (default ``~/.cache/wobjcal/<kind>``, the root the
allowed-collision lists use too) as ``<key>.npz``. Writes are atomic (temporary file and
rename); a reader that finds a missing, partial, corrupt or foreign file (its stored key or
version differ) gets ``None`` and the caller rebuilds: a cache can cost time, never an answer.
"""

from __future__ import annotations

import io
import logging
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from calib.atomic_io import write_bytes_atomic

log = logging.getLogger(__name__)


def cache_root() -> Path:
    """``$WOBJCAL_CACHE_DIR`` or ``~/.cache/wobjcal``."""
    return Path(os.environ.get("WOBJCAL_CACHE_DIR") or Path.home() / ".cache" / "wobjcal")


def cache_path(kind: str, key: str) -> Path:
    """The file of entry ``key`` of cache ``kind``."""
    return cache_root() / kind / f"{key}.npz"


def load_arrays(kind: str, key: str, version: int) -> dict[str, NDArray] | None:
    """The arrays stored under ``key``, or ``None`` when absent or unusable (then logged)."""
    path = cache_path(kind, key)
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: data[name] for name in data.files}
        if str(arrays.pop("_key", "")) != key or int(arrays.pop("_version", -1)) != version:
            log.warning("ignoring cache file %s: written for another key or version", path)
            return None
        return arrays
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        log.warning("ignoring unreadable cache file %s: %s", path, exc)
        return None


def save_arrays(kind: str, key: str, version: int, arrays: dict[str, NDArray]) -> None:
    """Store ``arrays`` under ``key`` atomically; a failure to write is logged, not raised."""
    path = cache_path(kind, key)
    buf = io.BytesIO()
    payload: dict[str, Any] = {"_key": np.array(key), "_version": np.array(version), **arrays}
    savez: Any = np.savez  # its stub types keyword arrays as its own flags
    savez(buf, **payload)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bytes_atomic(path, buf.getvalue())
    except OSError as exc:
        log.warning("cannot write cache file %s: %s", path, exc)
