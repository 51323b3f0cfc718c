"""Trials on worker processes, running in the background while this process does other work.

:class:`TrialPool` starts its worker processes (:func:`planner.sim.pool.open_pool`, each with its
own :class:`~planner.sim.trial.TrialRunner`, built once) and hands them every chunk of its
trials at once, so they run while the caller does something else: ``wobjcal validate`` checks
the plan in its cell, predicts and runs the trials it vets in the cell meanwhile
(:class:`planner.sim.simulation_run.SimulationRun`), and may predict the report's rows first,
on a worker too. :meth:`TrialPool.results` then waits for them
and returns them in the order of the seeds: each trial is seeded on its own, so the results do
not depend on which process ran which chunk, nor when.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, CancelledError, Future, wait
from typing import Any

import trimesh

from planner.sim.pool import kill_pool, open_pool
from planner.sim.predict import Prediction, predict_report
from planner.sim.search_events import ReachabilityHook
from planner.sim.setup import SimulationSetup
from planner.sim.trial import (
    TrialResult,
    TrialRunner,
    TrialSeed,
    init_worker,
    run_chunk_in_worker,
)

#: progress(done_trials): trials of this pool done so far.
DoneCallback = Callable[[int], None]
#: progress(done_trials, total_trials)
ProgressCallback = Callable[[int, int], None]


def chunk_size(total: int, n_workers: int) -> int:
    """Trials per chunk handed to a worker: about 8 chunks per worker, at most 100 trials."""
    return max(1, min(100, math.ceil(total / (8 * n_workers))))


class TrialPool:
    """The trials of ``seeds`` on ``n_workers`` worker processes, started at once.

    Args:
        setup: what every trial shares (pickled to each worker).
        mesh: the true part mesh in wobj, metres.
        seeds: the trials' seeds, in report order.
        n_workers: worker processes (>= 1).
        predict_setup: also predict the rows of this setup on a worker, before the trials
            (:func:`planner.sim.predict.predict_report`; :attr:`prediction`); None: not.

    The workers are started and handed their chunks on a thread of this process
    (``wobjcal-pool-start``): starting one waits for the fork server's imports and for the
    worker to read its setup, about half a second each, which the caller spends on its own
    work meanwhile. An error there (e.g. a setup that does not pickle) is raised by
    :attr:`prediction` and :meth:`results`. Close the pool with :meth:`results` (waits) or
    :meth:`cancel` (kills the workers at once).
    """

    def __init__(
        self,
        setup: SimulationSetup,
        mesh: trimesh.Trimesh,
        seeds: list[TrialSeed],
        n_workers: int,
        predict_setup: SimulationSetup | None = None,
    ) -> None:
        size = chunk_size(len(seeds), n_workers)
        chunks = [seeds[i : i + size] for i in range(0, len(seeds), size)]
        self.total = len(seeds)
        self._pool = open_pool(n_workers, init_worker, (setup, mesh))
        self._futures: list[Future[list[TrialResult]]] = []
        self._sizes: dict[int, int] = {}
        self._prediction: Future[Prediction] | None = None
        self._error: BaseException | None = None
        self._stop = threading.Event()  # cancel(): hand out nothing more
        self._started_all = threading.Event()  # the start thread has returned
        self._starter = threading.Thread(
            target=self._start, args=(chunks, predict_setup), name="wobjcal-pool-start"
        )
        self._starter.daemon = True
        self._starter.start()

    def _start(self, chunks: list[list[TrialSeed]], predict_setup: SimulationSetup | None) -> None:
        """Hand the workers the prediction, then every chunk (on the starter thread), until
        :meth:`cancel` says stop."""
        try:
            calls: list[tuple[Callable[..., Any], Any]] = [(run_chunk_in_worker, c) for c in chunks]
            if predict_setup is not None:
                calls.insert(0, (predict_report, predict_setup))
            futures: list[Future[Any]] = []
            for fn, arg in calls:
                if self._stop.is_set():
                    self._error = CancelledError("the trial pool was cancelled")
                    return
                futures.append(self._pool.submit(fn, arg))
            if predict_setup is not None:
                self._prediction = futures.pop(0)
            self._sizes = {id(f): len(c) for f, c in zip(futures, chunks, strict=True)}
            self._futures = futures
        except BaseException as exc:  # raised in the caller's thread (_started)
            self._error = exc
        finally:
            self._started_all.set()

    def _started(self) -> None:
        """Wait until every chunk is handed out; raise what went wrong there (the workers
        killed first). Waits on an event, not on the thread: a Ctrl-C in ``Thread.join``
        marks a running thread as ended (Python 3.11), and :meth:`cancel` must not believe
        it."""
        self._started_all.wait()
        if self._error is not None:
            self.cancel()
            raise self._error

    @property
    def prediction(self) -> Future[Prediction] | None:
        """The prediction computed on a worker (its error raised by ``result()``), or None
        when none was asked for (waits until the workers are started)."""
        self._started()
        return self._prediction

    @property
    def done(self) -> int:
        """Trials whose chunk has finished so far (0 while the workers are starting)."""
        futures = self._futures
        return sum(self._sizes[id(f)] for f in futures if f.done())

    def results(self, progress: DoneCallback | None = None) -> list[TrialResult]:
        """Wait for every trial and return them in seed order; ``progress(done)`` as chunks
        finish. An error, Ctrl-C or SIGTERM kills the workers (nothing left running)."""
        try:
            self._started()
            pending = set(self._futures)
            while pending:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for f in finished:
                    f.result()  # a worker's error, raised here
                if progress is not None:
                    progress(self.done)
            out = [r for f in self._futures for r in f.result()]
        except BaseException:
            self.cancel()
            raise
        self._pool.shutdown(wait=True)
        return out

    def cancel(self) -> None:
        """Kill the workers and drop their trials (no waiting for the trials). The start
        thread is told to stop; a worker it is starting meanwhile is killed once it returns
        (a second Ctrl-C while waiting for that still kills what is there)."""
        self._stop.set()
        # the executor forgets its processes at shutdown (the first kill): keep them here
        procs: dict[int, Any] | None = getattr(self._pool, "_processes", None)  # (even empty)
        try:
            kill_pool(self._pool)  # the workers started so far; a later submit fails
            self._started_all.wait()
        finally:
            kill_pool(self._pool)
            for proc in list((procs or {}).values()):  # the one being started, if any
                proc.kill()


def run_all(
    setup: SimulationSetup,
    mesh: trimesh.Trimesh,
    seeds: list[TrialSeed],
    n_workers: int,
    reach: ReachabilityHook | None,
    progress: ProgressCallback | None,
    cell: Any = None,
    before_trial: Callable[[], None] | None = None,
) -> list[TrialResult]:
    """Run ``seeds`` in this process (1 worker; the only place a ``reach`` hook or a ``cell``
    is used) or on a :class:`TrialPool`, each process with its own
    :class:`~planner.sim.trial.TrialRunner`, built once per process;
    ``progress(done, total)`` after every chunk. In this process ``before_trial()`` is called
    before every trial: what it raises stops the run there (a prediction that failed
    meanwhile, :meth:`planner.sim.simulation_run.SimulationRun.finish`)."""
    total = len(seeds)
    if n_workers > 1 and before_trial is not None:
        raise ValueError("before_trial is called in this process only: run with n_workers=1")
    if n_workers > 1:
        pool = TrialPool(setup, mesh, seeds, n_workers)
        return pool.results(None if progress is None else lambda done: progress(done, total))
    size = chunk_size(total, n_workers)
    runner = TrialRunner(setup, mesh, cell)
    out: list[TrialResult] = []
    for i in range(0, total, size):
        for seed in seeds[i : i + size]:
            if before_trial is not None:
                before_trial()
            out.append(runner.run_trial(seed, reach))
        if progress is not None:
            progress(len(out), total)
    return out
