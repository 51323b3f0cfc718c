"""The cell worker: one thread owns the resource and runs jobs in order."""

from __future__ import annotations

import threading
import time

import pytest

from webui.worker import CellWorker, WorkerClosedError


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
        w.replace_resource(bad).result(5)
    assert w.call(lambda r: r) is old and not old.closed
    w.replace_resource(_Res).result(5)
    assert w.call(lambda r: r) is not old and old.closed
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
