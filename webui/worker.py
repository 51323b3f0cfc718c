"""The one worker thread that owns the PyBullet cell.

viser runs GUI and scene callbacks in a thread pool, and PyBullet is not thread-safe. Every call
that touches the cell therefore goes through :class:`CellWorker`: one thread creates the cell,
runs the submitted jobs one after another and closes the cell at the end. Callbacks submit a job
and either wait for its result (short checks) or attach a done-callback (long validation runs),
so other browser tabs keep working while a long job runs.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any, Generic, TypeVar

logger = logging.getLogger(__name__)

C = TypeVar("C")
R = TypeVar("R")

_STOP = object()


class WorkerClosedError(RuntimeError):
    """A job was submitted to a worker that has been closed."""


class ResourceTimeout(TimeoutError):
    """:meth:`CellWorker.replace_resource` gave up waiting (the old resource stays)."""


class CellWorker(Generic[C]):
    """A single thread that owns one resource (the cell) and runs jobs on it in order.

    Args:
        factory: called once, in the worker thread, to create the resource; ``None`` for a
            worker without a resource (jobs then receive ``None``).
        name: thread name, for logs.

    Jobs are callables ``job(resource, *args)``; :meth:`submit` returns a
    :class:`concurrent.futures.Future` with the job's result or exception.
    """

    def __init__(self, factory: Callable[[], C] | None = None, name: str = "wobjcal-cell") -> None:
        self._factory = factory
        self._jobs: queue.Queue[Any] = queue.Queue()
        self._closed = False
        self._lock = threading.Lock()
        self._resource: C | None = None
        self._ready: Future[None] = Future()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    @property
    def thread(self) -> threading.Thread:
        """The worker thread (every job runs on it)."""
        return self._thread

    def wait_ready(self, timeout: float | None = None) -> None:
        """Block until the resource is created; re-raise the factory's exception if it failed."""
        self._ready.result(timeout)

    def submit(self, job: Callable[..., R], *args: Any) -> Future[R]:
        """Queue ``job(resource, *args)``; return a future of its result."""
        fut: Future[R] = Future()
        with self._lock:
            if self._closed:
                raise WorkerClosedError("the cell worker is closed")
            self._jobs.put((job, args, fut))
        return fut

    def call(self, job: Callable[..., R], *args: Any, timeout: float | None = 120.0) -> R:
        """Run ``job(resource, *args)`` on the worker and wait for its result.

        Calling this from the worker thread itself runs the job directly (no deadlock).
        """
        if threading.current_thread() is self._thread:
            return job(self._resource, *args)
        return self.submit(job, *args).result(timeout)

    def replace_resource(self, factory: Callable[[], C], timeout: float | None = None) -> None:
        """Create a new resource with ``factory`` in the worker, make it the worker's and close
        the old one; wait up to ``timeout`` seconds (``None``: as long as it takes).

        If ``factory`` raises, the old resource is kept and the exception is raised here.

        Raises:
            ResourceTimeout: not done within ``timeout``. The old resource stays: a swap that
                has not started is cancelled, and a resource that is still being built is
                closed when it is done, never made the worker's (the caller has given it up;
                an error of that build is logged).
            RuntimeError: called from the worker thread (it would wait for itself).
        """
        if threading.current_thread() is self._thread:
            raise RuntimeError("replace_resource from the worker thread would wait for itself")
        gate = threading.Lock()
        state = {"abandoned": False, "installed": False}

        def swap(old: C | None) -> None:
            try:
                new = factory()
            except BaseException:
                if state["abandoned"]:  # nobody waits for this future any more
                    logger.exception("building a resource given up on failed")
                raise
            with gate:
                if state["abandoned"]:
                    _close(new)
                    return
                self._resource = new
                state["installed"] = True
            _close(old)

        fut = self.submit(swap)
        try:
            fut.result(timeout)
        except TimeoutError:
            if fut.done():  # the factory's own TimeoutError: an error like any other
                raise
            with gate:
                if not state["installed"]:
                    state["abandoned"] = True
                    fut.cancel()
                    raise ResourceTimeout(f"not done within {timeout} s") from None
            fut.result()  # made the worker's just as the wait ended: only the old one's close

    def close(self, timeout: float = 10.0) -> None:
        """Stop the worker after the queued jobs and close the resource."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._jobs.put(_STOP)
        if threading.current_thread() is not self._thread:
            self._thread.join(timeout)

    def _run(self) -> None:
        try:
            self._resource = None if self._factory is None else self._factory()
        except BaseException as exc:  # the future carries it to whoever waits
            logger.exception("creating the cell failed")
            self._ready.set_exception(exc)
        else:
            self._ready.set_result(None)
        while True:
            item = self._jobs.get()
            if item is _STOP:
                break
            job, args, fut = item
            if not fut.set_running_or_notify_cancel():
                continue
            try:
                fut.set_result(job(self._resource, *args))
            except BaseException as exc:
                fut.set_exception(exc)
        _close(self._resource)
        self._resource = None


def _close(resource: Any) -> None:
    close = getattr(resource, "close", None)
    if callable(close):
        try:
            close()
        except Exception:
            logger.exception("closing the cell failed")
