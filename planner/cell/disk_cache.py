"""Per-user disk cache of derived arrays (distance fields), keyed by content hashes.

Files live in ``$WOBJCAL_CACHE_DIR/<kind>`` (default ``~/.cache/wobjcal/<kind>``, the root the
allowed-collision lists use too) as ``<key>.npz``. Writes are atomic (temporary file and
rename); a reader that finds a missing, partial, corrupt or foreign file (its stored key or
version differ) gets ``None`` and the caller rebuilds: a cache can cost time, never an answer.
A write that fails (a full disk, a root that is not a directory) is told once per kind
(:func:`warn_once`) and the command goes on without the cache.

Each kind is bounded: after a write, the least recently used files of that kind (a load
refreshes a file's time) are deleted until the kind holds at most ``$WOBJCAL_CACHE_MAX_MB``
(default 1,000 MB; a distance field is 2-30 MB), never the file just written. A user who
opens many parts keeps the recent ones and does not fill the disk.
"""

from __future__ import annotations

import contextlib
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
#: The default bound of one kind's files, MB (``WOBJCAL_CACHE_MAX_MB`` overrides).
DEFAULT_MAX_MB = 1000.0


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
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        log.warning("ignoring unreadable cache file %s: %s", path, exc)
        return None
    with contextlib.suppress(OSError):
        os.utime(path)  # recently used: the last to be evicted
    return arrays


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
        warn_once(kind, f"cannot write cache file {path}: {exc.strerror or exc}")
        return
    evict(kind, keep=path)


#: The caches (root directory, kind) whose failure was already told in this process.
_WARNED: set[tuple[str, str]] = set()


def warn_once(kind: str, message: str) -> None:
    """Log that cache ``kind`` cannot be used (``message`` says which file and why): a
    warning the first time for this kind under the current root in this process, a debug line
    after. A cache is optional: an unwritable or full one slows a command, never fails it, and
    does not fill its output with one line per file either."""
    key = (str(cache_root()), kind)
    if key in _WARNED:
        log.debug("%s", message)
        return
    _WARNED.add(key)
    log.warning("%s; going on without the %s cache (slower)", message, kind)


def max_bytes() -> float:
    """The bound of one kind's files in bytes (``$WOBJCAL_CACHE_MAX_MB``, default
    :data:`DEFAULT_MAX_MB`); an unreadable setting is logged and the default used."""
    text = os.environ.get("WOBJCAL_CACHE_MAX_MB", "")
    try:
        mb = float(text) if text else DEFAULT_MAX_MB
        if not mb >= 0.0:
            raise ValueError(text)
    except ValueError:
        log.warning("WOBJCAL_CACHE_MAX_MB=%r is not a size in MB; using %g", text, DEFAULT_MAX_MB)
        mb = DEFAULT_MAX_MB
    return mb * 1e6


def evict(kind: str, keep: Path | None = None) -> list[Path]:
    """Delete the least recently used ``.npz`` files of ``kind`` (never ``keep``) until the
    rest fit in :func:`max_bytes`; returns the deleted paths. Files that vanish or cannot be
    deleted meanwhile (another process) are skipped."""
    entries = []
    for p in (cache_root() / kind).glob("*.npz"):
        try:
            st = p.stat()
        except OSError:
            continue
        entries.append((st.st_mtime, st.st_size, p))
    total = sum(size for _, size, _ in entries)
    limit = max_bytes()
    removed: list[Path] = []
    for _, size, p in sorted(entries, key=lambda e: e[0]):
        if total <= limit:
            break
        if keep is not None and p == keep:
            continue
        try:
            p.unlink()
        except OSError:
            continue
        total -= size
        removed.append(p)
    if removed:
        log.info("cache %s: removed %d least recently used files", kind, len(removed))
    return removed
