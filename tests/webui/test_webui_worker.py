"""The cell worker: one thread owns the resource and runs jobs in order."""

from __future__ import annotations

import threading
import time

import pytest

from webui.worker import CellWorker, ResourceTimeout, WorkerClosedError


class _Res:
    def __init__(self) -> None:
        self.thread = threading.current_thread()
        self.closed = False
        self.log: list[int] = []

    def close(self) -> None:
        self.closed = True


def test_jobs_run_in_order_on_the_owning_thread() -> None:
    w = CellWorker(_Res)
    w.wait_ready(5)
    futs = [
        w.submit(lambda r, i=i: (r.log.append(i), threading.current_thread())[1]) for i in range(20)
    ]
    threads = {f.result(5) for f in futs}
    assert threads == {w.thread}
    res = w.call(lambda r: r)
    assert res.log == list(range(20)) and res.thread is w.thread
    w.close()
    assert res.closed


def test_exceptions_reach_the_caller() -> None:
    w = CellWorker(_Res)

    def boom(_r: _Res) -> None:
        raise ValueError("bad point")

    with pytest.raises(ValueError, match="bad point"):
        w.call(boom)
    assert w.call(lambda r: 3) == 3, "the worker survives a failing job"
    w.close()
    with pytest.raises(WorkerClosedError):
        w.submit(lambda r: 1)


def test_factory_failure_is_reported() -> None:
    def bad() -> _Res:
        raise RuntimeError("no cell")

    w = CellWorker(bad)
    with pytest.raises(RuntimeError, match="no cell"):
        w.wait_ready(5)
    assert w.call(lambda r: r) is None
    w.close()


def test_replace_resource_keeps_old_on_failure() -> None:
    w = CellWorker(_Res)
    old = w.call(lambda r: r)

    def bad() -> _Res:
        raise RuntimeError("broken urdf")

    with pytest.raises(RuntimeError):
        w.replace_resource(bad, 5)
    assert w.call(lambda r: r) is old and not old.closed
    w.replace_resource(_Res, 5)
    assert w.call(lambda r: r) is not old and old.closed
    w.close()


def test_a_resource_given_up_while_it_is_built_is_never_the_workers() -> None:
    """The caller stops waiting (a cell that takes too long to load): the old resource stays
    the worker's, and the new one is closed when it is done, not swapped in behind the caller's
    back (the UI would draw one cell and check in another)."""
    w = CellWorker(_Res)
    old = w.call(lambda r: r)
    started, release = threading.Event(), threading.Event()
    built: list[_Res] = []

    def slow() -> _Res:
        started.set()
        release.wait(5)
        built.append(_Res())
        return built[-1]

    with pytest.raises(ResourceTimeout):
        w.replace_resource(slow, 0.2)
    assert started.is_set()
    release.set()
    assert w.call(lambda r: r) is old and not old.closed  # runs after the abandoned swap
    assert len(built) == 1 and built[0].closed
    w.close()


def test_a_swap_given_up_before_it_starts_is_not_run() -> None:
    w = CellWorker(_Res)
    old = w.call(lambda r: r)
    gate = threading.Event()
    w.submit(lambda _r: gate.wait(5))  # the worker is busy
    calls: list[int] = []

    def new() -> _Res:
        calls.append(1)
        return _Res()

    with pytest.raises(ResourceTimeout):
        w.replace_resource(new, 0.1)
    gate.set()
    assert w.call(lambda r: r) is old and calls == []
    w.close()


def test_long_job_does_not_block_submitters() -> None:
    w = CellWorker(None)
    gate = threading.Event()
    fut = w.submit(lambda _r: gate.wait(5))
    t0 = time.perf_counter()
    quick = w.submit(lambda _r: 1)
    assert time.perf_counter() - t0 < 1.0 and not quick.done()
    gate.set()
    assert fut.result(5) and quick.result(5) == 1
    w.close()


def test_a_factory_s_own_timeout_is_its_error_not_the_wait_s() -> None:
    """A build that raises TimeoutError itself (a socket timeout while reading a file) is its
    error, raised as it is at once; only the wait running out is a ResourceTimeout."""
    w = CellWorker(_Res)
    old = w.call(lambda r: r)

    def times_out() -> _Res:
        raise TimeoutError("reading the mesh timed out")

    with pytest.raises(TimeoutError, match="reading the mesh") as err:
        w.replace_resource(times_out, 5)
    assert not isinstance(err.value, ResourceTimeout)
    assert w.call(lambda r: r) is old
    with pytest.raises(RuntimeError, match="wait for itself"):  # from the worker's own thread
        w.call(lambda _r: w.replace_resource(_Res, 1))
    w.close()
