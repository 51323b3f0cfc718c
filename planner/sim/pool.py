"""Worker processes of a validation: die with the parent, leave nothing running on an error.

:func:`open_pool` starts a ``ProcessPoolExecutor`` whose workers ask Linux to kill them when
the parent dies (a parent killed by SIGTERM or SIGKILL would otherwise leave them running);
:func:`kill_pool` stops one at once on Ctrl-C, SIGTERM or an error, without waiting for the
chunks in flight.
"""

from __future__ import annotations

import multiprocessing as mp
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from typing import Any

__all__ = ["kill_pool", "open_pool"]


def open_pool(
    n_workers: int, initializer: Callable[..., None], initargs: tuple[Any, ...]
) -> ProcessPoolExecutor:
    """A pool of ``n_workers`` forked processes (where the platform forks), each running
    ``initializer(*initargs)`` after arranging to die with this process."""
    ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else None
    return ProcessPoolExecutor(n_workers, ctx, _init, (initializer, initargs))


def kill_pool(pool: ProcessPoolExecutor) -> None:
    """Kill every worker of ``pool`` and drop its pending work (no waiting)."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    for proc in procs:
        proc.kill()
    pool.shutdown(wait=False, cancel_futures=True)


def _init(initializer: Callable[..., None], initargs: tuple[Any, ...]) -> None:
    _die_with_parent()
    initializer(*initargs)


def _die_with_parent() -> None:
    """Ask Linux to SIGKILL this process when its parent dies (``prctl(PR_SET_PDEATHSIG)``)."""
    import ctypes
    import signal
    import sys

    if not sys.platform.startswith("linux"):
        return
    parent = os.getppid()
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent died before the call
        os._exit(1)
