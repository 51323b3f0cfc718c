"""Where numba keeps the machine code of the broad phase's kernels: wobjcal's per-user cache.

The kernels (:mod:`~planner.cell.gjk_kernels`, :mod:`~planner.cell.field_kernels`,
:mod:`~planner.cell.mesh_kernels`, :mod:`~planner.cell.broad_kernels`) are compiled with
``cache=True``. By default numba writes its cache next to the source (``__pycache__``), which a
read-only install cannot. :func:`configure` points numba at ``<cache root>/numba``
(``$WOBJCAL_CACHE_DIR/numba``, default ``~/.cache/wobjcal/numba``), beside the distance fields
and allowed-collision lists, so one directory holds every derived file and emptying it is a
true cold start. ``NUMBA_CACHE_DIR``, when set, wins. When the directory cannot be created or
written, numba's own fallbacks apply (next to the source, then its user-wide directory); a
cache only ever costs time, never an answer: numba checks each entry against the source file's
stamp and the CPU before it loads it.

Each kernel module calls :func:`configure` before its first ``@njit``: numba picks the
directory when a function is decorated. The first call also starts the background compile of
:mod:`planner.cell.warmup` when that directory was never warmed.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any

import numba

from planner.cell.disk_cache import cache_root

log = logging.getLogger(__name__)
#: numba's settings (attributes made at run time, so untyped).
_CONFIG: Any = numba.config


def kernel_cache_dir() -> Path | None:
    """The directory numba caches kernels in, or ``None`` when numba chose it itself."""
    return Path(_CONFIG.CACHE_DIR) if _CONFIG.CACHE_DIR else None


def configure() -> Path | None:
    """Point numba's cache at wobjcal's (see the module docstring); idempotent.

    Returns:
        The directory in use, or ``None`` when numba's defaults apply (not writable).
    """
    if _CONFIG.CACHE_DIR:  # NUMBA_CACHE_DIR or an earlier call
        return Path(_CONFIG.CACHE_DIR)
    path = cache_root() / "numba"
    if _writable(path):
        _CONFIG.CACHE_DIR = str(path)
        from planner.cell.warmup import start_background  # the helper imports this module

        start_background(path)
        return path
    return None


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
        if not os.access(path, os.W_OK):
            raise PermissionError(f"{path} is not writable")
    except OSError as exc:
        log.info("numba kernels cached by numba's defaults: %s", exc)
        return False
    return True
