"""Worker processes of a validation: die with the parent, leave nothing running on an error.

:func:`open_pool` starts a ``ProcessPoolExecutor`` whose workers end themselves when the
process that opened the pool ends (one killed by SIGTERM or SIGKILL would otherwise leave
them running);
:func:`kill_pool` stops one at once on Ctrl-C, SIGTERM or an error, without waiting for the
chunks in flight.

The workers come from a fork server (a fresh interpreter that imports what a trial needs once
and forks a worker per request), never from a fork of this process. Embree, which casts the
rays, runs on TBB worker threads that stay alive after a ray batch; a child forked while one
of them held TBB's scheduler lock waits for that lock for ever at its own first ray batch.
Seen: ``wobjcal validate`` casts rays in its preflight before it starts the workers, and a
validation in a pytest worker that had cast rays before hung with both workers asleep.
:func:`prepare_pool` starts the server early, so its imports overlap this process's work.
"""

from __future__ import annotations

import multiprocessing as mp
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from typing import Any

__all__ = ["kill_pool", "open_pool", "start_method"]

#: modules a fork server imports once, before it forks workers (what a trial needs)
_FORKSERVER_PRELOAD = ["planner.sim.worker_preload"]


def start_method() -> str | None:
    """How :func:`open_pool` starts its workers: ``"forkserver"`` where the platform has it,
    else None (the platform's default, ``spawn``). Never a plain ``fork`` of this process: its
    threads (Embree's, a progress bar's, a server's) may hold locks the child would wait on."""
    return "forkserver" if "forkserver" in mp.get_all_start_methods() else None


def prepare_pool() -> None:
    """Start the fork server now, if it is not running: it imports what a trial needs while
    this process goes on (a pool opened later then forks its workers at once). Idempotent."""
    if start_method() != "forkserver":
        return
    from multiprocessing import forkserver

    mp.get_context("forkserver").set_forkserver_preload(_FORKSERVER_PRELOAD)
    forkserver.ensure_running()


def open_pool(
    n_workers: int, initializer: Callable[..., None], initargs: tuple[Any, ...]
) -> ProcessPoolExecutor:
    """A pool of ``n_workers`` processes started from the fork server (:func:`start_method`,
    :func:`prepare_pool`), each running ``initializer(*initargs)`` after arranging to die with
    this process. ``initializer`` and ``initargs`` are pickled to every worker."""
    method = start_method()
    if method == "forkserver":
        prepare_pool()
    ctx = None if method is None else mp.get_context(method)
    return ProcessPoolExecutor(n_workers, ctx, _init, (os.getpid(), initializer, initargs))


def kill_pool(pool: ProcessPoolExecutor) -> None:
    """Kill every worker of ``pool`` and drop its pending work (no waiting)."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    for proc in procs:
        proc.kill()
    pool.shutdown(wait=False, cancel_futures=True)


def _init(parent: int, initializer: Callable[..., None], initargs: tuple[Any, ...]) -> None:
    _die_with(parent)
    initializer(*initargs)


def _die_with(parent: int) -> None:
    """End this worker at once when process ``parent`` (the one that opened the pool) ends.

    A worker's own parent is the fork server, and the two keep each other alive: the server
    stops when every holder of its "alive" pipe has closed it, and every worker holds one, as
    it holds both ends of the pool's call queue (a worker never sees its work end). Watching the
    opener itself (a ``pidfd`` where Linux has it, else a poll once a second) ends them when it
    is killed by SIGKILL too; the server then stops by itself.
    """
    import select
    import threading
    import time

    if os.name != "posix":  # (os.kill(pid, 0) would end the process on Windows)
        return

    def alive() -> bool:
        try:
            os.kill(parent, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True

    try:
        fd = os.pidfd_open(parent)
    except ProcessLookupError:
        os._exit(1)  # gone before this worker started
    except (AttributeError, OSError):
        fd = None

    def watch() -> None:
        if fd is not None:
            select.select([fd], [], [])
        else:
            while alive():
                time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="wobjcal-parent-watch", daemon=True).start()
