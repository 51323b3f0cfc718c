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
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, wait
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

    Close it with :meth:`results` (waits) or :meth:`cancel` (kills the workers at once).
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
        try:
            #: the prediction computed on a worker (its error raised by ``result()``), or None
            self.prediction: Future[Prediction] | None = (
                None if predict_setup is None else self._pool.submit(predict_report, predict_setup)
            )
            self._futures: list[Future[list[TrialResult]]] = [
                self._pool.submit(run_chunk_in_worker, c) for c in chunks
            ]
        except BaseException:
            kill_pool(self._pool)
            raise
        self._sizes = {id(f): len(c) for f, c in zip(self._futures, chunks, strict=True)}

    @property
    def done(self) -> int:
        """Trials whose chunk has finished so far."""
        return sum(self._sizes[id(f)] for f in self._futures if f.done())

    def results(self, progress: DoneCallback | None = None) -> list[TrialResult]:
        """Wait for every trial and return them in seed order; ``progress(done)`` as chunks
        finish. An error, Ctrl-C or SIGTERM kills the workers (nothing left running)."""
        try:
            pending = set(self._futures)
            while pending:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for f in finished:
                    f.result()  # a worker's error, raised here
                if progress is not None:
                    progress(self.done)
            out = [r for f in self._futures for r in f.result()]
        except BaseException:
            kill_pool(self._pool)
            raise
        self._pool.shutdown(wait=True)
        return out

    def cancel(self) -> None:
        """Kill the workers and drop their trials (no waiting)."""
        kill_pool(self._pool)


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
