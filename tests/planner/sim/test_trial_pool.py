"""The trial pool starts its workers on a thread of its own (:mod:`planner.sim.trial_pool`):
the caller goes on at once, gets the trials back in seed order, and gets an error of the start
raised where it waits, with nothing left running.

The executor is a stand-in that runs each call on submit (no process is started), so the tests
see the pool's own logic: when it submits, what it raises, what it kills.
"""

from __future__ import annotations

import pickle
import signal
import threading
from collections.abc import Callable
from concurrent.futures import CancelledError, Future
from typing import Any

import pytest

from planner.sim import trial_pool as trial_pool_module
from planner.sim.trial_pool import TrialPool


class _Executor:
    """Runs each submitted call at once, after ``gate`` opens; ``fail`` makes a submit raise."""

    def __init__(self, gate: threading.Event, fail: BaseException | None = None) -> None:
        self.gate, self.fail = gate, fail
        self.submitted = 0
        self.killed = self.shut = False
        self.kills: list[int] = []
        self.open_on_kill = False  # the gate opens at the first kill

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        assert self.gate.wait(30.0), "the test never opened the gate"
        if self.fail is not None:
            raise self.fail
        self.submitted += 1
        f: Future[Any] = Future()
        f.set_result(fn(*args))
        return f

    def shutdown(self, wait: bool = True) -> None:
        self.shut = True


def _pool(monkeypatch: pytest.MonkeyPatch, executor: _Executor, n_seeds: int = 10) -> TrialPool:
    def kill(pool: _Executor) -> None:
        pool.killed = True
        pool.kills.append(pool.submitted)  # how many calls were handed out at each kill
        if pool.open_on_kill:
            pool.gate.set()

    monkeypatch.setattr(trial_pool_module, "open_pool", lambda *a: executor)
    monkeypatch.setattr(trial_pool_module, "kill_pool", kill)
    monkeypatch.setattr(trial_pool_module, "run_chunk_in_worker", lambda seeds: list(seeds))
    monkeypatch.setattr(trial_pool_module, "predict_report", lambda setup: ("predicted", setup))
    return TrialPool(
        "setup",  # type: ignore[arg-type]
        None,  # type: ignore[arg-type]
        list(range(n_seeds)),  # type: ignore[arg-type]
        2,
        predict_setup="nominal",  # type: ignore[arg-type]
    )


def test_the_caller_goes_on_while_the_workers_start(monkeypatch: pytest.MonkeyPatch) -> None:
    """The pool returns before any chunk is handed out (the workers' start blocks here until
    the gate opens); meanwhile no trial counts as done; then every trial comes back in seed
    order and the prediction with them."""
    gate = threading.Event()
    executor = _Executor(gate)
    pool = _pool(monkeypatch, executor, n_seeds=25)
    assert executor.submitted == 0 and pool.done == 0
    gate.set()
    prediction = pool.prediction
    assert prediction is not None and prediction.result() == ("predicted", "nominal")
    seen: list[int] = []
    assert pool.results(seen.append) == list(range(25))
    assert executor.submitted == 1 + len(range(0, 25, 2)) and executor.shut
    assert seen[-1] == 25 and not executor.killed


@pytest.mark.parametrize("ask", ["results", "prediction"])
def test_an_error_starting_the_workers_is_raised_where_the_caller_waits(
    monkeypatch: pytest.MonkeyPatch, ask: str
) -> None:
    """A setup that does not pickle fails on the start thread; the caller gets that error
    (not a hang, not a silent empty run) and the workers are killed."""
    gate = threading.Event()
    gate.set()
    executor = _Executor(gate, pickle.PicklingError("cannot pickle 'generator' object"))
    pool = _pool(monkeypatch, executor)
    with pytest.raises(pickle.PicklingError, match="cannot pickle"):
        pool.results() if ask == "results" else pool.prediction
    assert executor.killed


def test_cancel_while_the_workers_start_leaves_none_running(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Cancelling (an error of the caller) while the start thread is handing out chunks: the
    call in progress ends, nothing more is handed out, and the workers are killed after it."""
    gate = threading.Event()
    executor = _Executor(gate)
    pool = _pool(monkeypatch, executor)
    threading.Timer(0.2, gate.set).start()
    pool.cancel()
    assert executor.submitted == 1 and executor.kills[-1] == 1
    assert not pool._starter.is_alive()
    with pytest.raises(CancelledError):
        pool.results()


class _Interrupt(BaseException):
    """A Ctrl-C of this test's own (SIGUSR1), so that a stray one cannot stop pytest."""


def test_ctrl_c_while_waiting_for_the_start_leaves_none_running(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A signal that interrupts the caller while it waits for the start (``results``): the
    caller gets the interrupt, the start stops after the call in progress, and the workers
    are killed after that call (``Thread.join`` interrupted this way once let the kill run
    before the start had stopped)."""

    def interrupt(signum: int, frame: object) -> None:
        raise _Interrupt

    previous = signal.signal(signal.SIGUSR1, interrupt)
    try:
        gate = threading.Event()
        executor = _Executor(gate)
        executor.open_on_kill = True  # the start is held up until the interrupt's cancel
        pool = _pool(monkeypatch, executor)
        main = threading.main_thread().ident
        assert main is not None
        timer = threading.Timer(0.2, signal.pthread_kill, (main, signal.SIGUSR1))
        timer.start()
        with pytest.raises(_Interrupt):
            pool.results()
        timer.join()
    finally:
        signal.signal(signal.SIGUSR1, previous)
    assert executor.submitted == 1 and executor.kills[-1] == 1
    assert not pool._starter.is_alive()
