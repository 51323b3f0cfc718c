"""A Monte Carlo run in two halves: started, then finished, with other work in between.

:func:`start_simulation` checks the arguments, draws what the run shares from ``rng`` (the
robot's accuracy field, every trial's seed) and starts the trials that are not vetted in a cell
on worker processes (:class:`planner.sim.trial_pool.TrialPool`), where there are to be more than
one, with the prediction of the rows (the procedure linearised) as their first task.
:meth:`SimulationRun.finish` runs the vetted trials in this process (they move the cell's part,
which is not shared), waits for the workers and builds the report. Between the two the caller
is free: ``wobjcal validate`` opens the plan's cell and checks the plan there
(:func:`planner.validate.job.validate_plan`) while the workers run, which takes the cell, the
check and the prediction off the run's critical path. A prediction that fails on its worker
stops the run at once, before the first vetted trial or between two of them, not after all of
them.

The numbers do not depend on it: the seeds are drawn before anything runs, each trial is seeded
on its own, and the report puts the trials in seed order (vetted first), exactly as
:func:`planner.sim.montecarlo.simulate` (which is :func:`start_simulation` then
:meth:`~SimulationRun.finish`) always did.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import time
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any

import numpy as np
import trimesh

from calib.errors import ShapeError
from calib.limits import MAX_PROTOCOL_TRIALS
from calib.plan.models import MAX_TRIALS
from planner.sim.error_map import error_map
from planner.sim.predict import Prediction, predict_report
from planner.sim.report import ValidationReport
from planner.sim.rows import RowSpec
from planner.sim.search_events import ReachabilityHook, cell_search_hook
from planner.sim.setup import SimulationSetup
from planner.sim.summary import build_report
from planner.sim.trial import TrialResult, TrialSeed
from planner.sim.trial_pool import TrialPool, run_all

log = logging.getLogger(__name__)

#: progress(done_trials, total_trials)
ProgressCallback = Callable[[int, int], None]
#: Fewer trials than this outside the cell run in this process (workers cost more to start).
MIN_POOL_TRIALS = 50


@dataclass
class SimulationRun:
    """A started run (:func:`start_simulation`); finish it with :meth:`finish` or drop it
    with :meth:`cancel`.

    Attributes:
        setup: what every trial shares, with this run's accuracy field.
        nominal_setup: the setup as given (the prediction's).
        mesh: the true part mesh in wobj, metres.
        n_trials: trials of the report (the protocol's come after them).
        seeds: every trial's seed: the report's trials, then the protocol's.
        protocol: ``(positions, repeats)`` of the paper's protocol, or None.
        n_vetted: the first trials, run in this process to be vetted in a cell.
        n_workers: worker processes of the other trials (1: this process, at finish).
        pool: the workers running the other trials, or None.
        started: ``time.perf_counter()`` at the start.
    """

    setup: SimulationSetup
    nominal_setup: SimulationSetup
    mesh: trimesh.Trimesh
    n_trials: int
    seeds: list[TrialSeed]
    protocol: tuple[int, int] | None
    n_vetted: int
    n_workers: int
    pool: TrialPool | None
    started: float

    def cancel(self) -> None:
        """Kill the workers, if any (nothing left running)."""
        if self.pool is not None:
            self.pool.cancel()
            self.pool = None

    def finish(
        self,
        rows: list[RowSpec],
        *,
        reachability: ReachabilityHook | None = None,
        cell: Any = None,
        paper: Mapping[tuple[str, float], float] | None = None,
        progress: ProgressCallback | None = None,
    ) -> ValidationReport:
        """Predict, run the vetted trials here, wait for the others and report every row.

        Args:
            rows: the report's rows (:func:`planner.sim.report_points.report_rows`).
            reachability: the hook vetting each search of the first :attr:`n_vetted` trials.
            cell: the :class:`planner.cell.cell.Cell` those trials move the part in (the
                hook defaults to :func:`~planner.sim.search_events.cell_search_hook` of it);
                its work object is put back at the end.
            paper: the paper's half-widths by (row key, level), shown beside the rows.
            progress: ``progress(done, total)`` while trials complete.

        Raises:
            InputError: a plan that cannot calibrate even on the ideal part (the prediction),
                raised as soon as the prediction fails: before the first vetted trial, or
                between two of them when the worker's prediction fails meanwhile.
        """
        total = len(self.seeds)
        n_reach = self.n_vetted
        if cell is not None and reachability is None:
            reachability = cell_search_hook(cell)
        T_cell = None if cell is None else cell.T_world_wobj
        done_here = 0

        def report(done_pool: int) -> None:
            if progress is not None:
                progress(done_here + done_pool, total)

        def vetted(done: int, _total: int) -> None:
            nonlocal done_here
            done_here = done
            report(0 if self.pool is None else self.pool.done)

        pool = self.pool
        pending: Future[Prediction] | None = None  # computed on a worker meanwhile

        def prediction_failed() -> None:
            # a plan that cannot work fails at once, not after the vetted trials
            if pending is not None and pending.done():
                pending.result()  # its error, raised here

        try:
            # waits for the workers' start (a Ctrl-C there cancels the run like any other)
            pending = None if pool is None else pool.prediction
            if pending is None:
                prediction = predict_report(self.nominal_setup)  # a plan that cannot work
            results: list[TrialResult] = []
            if n_reach:  # here: they move the cell's part to where it really lies
                results = run_all(
                    self.setup,
                    self.mesh,
                    self.seeds[:n_reach],
                    1,
                    reachability,
                    vetted,
                    cell,
                    before_trial=prediction_failed,
                )
            if pending is not None:
                prediction = pending.result()
            if pool is not None:
                results += pool.results(report)
            elif n_reach < total:
                results += run_all(
                    self.setup,
                    self.mesh,
                    self.seeds[n_reach:],
                    1,
                    None,
                    lambda done, _t: report(done),
                )
        except BaseException:
            self.cancel()
            raise
        finally:
            if cell is not None:
                cell.move_work_object(T_cell)
        elapsed = time.perf_counter() - self.started
        log.info("validated %d trials in %.2f s on %d workers", total, elapsed, self.n_workers)
        main, proto = results[: self.n_trials], results[self.n_trials :]
        setup = self.setup
        out = build_report(
            setup,
            main,
            proto,
            self.protocol,
            rows,
            prediction,
            paper,
            elapsed,
            self.n_workers,
            n_reach,
        )
        pois = {
            r.key: r.points_wobj[0].copy()
            for r in rows
            if r.points_wobj is not None and len(r.points_wobj) == 1
        }
        return dataclasses.replace(
            out,
            points_of_interest=pois,
            probe_points_wobj=np.array([rp.point.position_m for rp in setup.points], dtype=float),
            error_map=error_map(out.delta_procedure, self.mesh),
        )


def pool_workers(n_seeds: int, vetted: int, workers: int | None) -> int:
    """Worker processes a run of ``n_seeds`` trials (the protocol's included) starts, the
    first ``vetted`` of them run in this process: ``workers`` (default ``min(2, cpus)``), or
    1 when fewer than :data:`MIN_POOL_TRIALS` trials would go to them."""
    n_workers = min(2, os.cpu_count() or 1) if workers is None else max(1, int(workers))
    return 1 if n_seeds - min(int(vetted), n_seeds) < MIN_POOL_TRIALS else n_workers


def start_simulation(
    setup: SimulationSetup,
    mesh: trimesh.Trimesh,
    n_trials: int,
    rng: np.random.Generator,
    *,
    vetted: int = 0,
    protocol: tuple[int, int] | None = None,
    workers: int | None = None,
) -> SimulationRun:
    """Start a run of ``n_trials`` trials of ``setup`` (see the module docstring).

    Args:
        setup: what every trial shares (see :mod:`planner.sim.setup`); its accuracy field is
            drawn here, once per run, from ``rng``.
        mesh: the true part mesh in wobj, metres.
        n_trials: number of trials (>= 2).
        rng: source of all randomness; the same seed gives the same report.
        vetted: the first ``vetted`` trials run at :meth:`SimulationRun.finish`, in this
            process, to be vetted in a cell; the others start now.
        protocol: ``(positions, repeats)``: also run the paper's protocol (every position's
            errors centred on that position's mean) beside the default.
        workers: worker processes (default: ``min(2, os.cpu_count())``; 1 runs in-process).

    Raises:
        ShapeError: bad arguments (named in the message), before anything is drawn.
    """
    if not isinstance(n_trials, int) or not 2 <= n_trials <= MAX_TRIALS:
        raise ShapeError(f"n_trials must be an integer 2 to {MAX_TRIALS:,}, got {n_trials!r}")
    if protocol is not None and (min(protocol) < 2 or len(protocol) != 2):
        raise ShapeError(f"protocol must be (positions, repeats), each >= 2, got {protocol!r}")
    if protocol is not None and protocol[0] * protocol[1] > MAX_PROTOCOL_TRIALS:
        raise ShapeError(
            f"protocol: {protocol[0]:,} x {protocol[1]:,} trials, at most "
            f"{MAX_PROTOCOL_TRIALS:,} (every trial's result stays in memory until the report)"
        )
    if int(vetted) < 0:
        raise ShapeError(f"reach_trials must be >= 0, got {vetted!r}")
    started = time.perf_counter()
    run_setup = dataclasses.replace(setup, accuracy_field=setup.robot_error.sample_field(rng))
    seeds: list[TrialSeed] = list(np.random.SeedSequence(int(rng.integers(2**63))).spawn(n_trials))
    if protocol is not None:
        base = np.random.SeedSequence(int(rng.integers(2**63)))
        for pos in base.spawn(protocol[0]):
            seeds += [(noise, pos) for noise in pos.spawn(protocol[1])]
    n_reach = min(int(vetted), n_trials)
    n_workers = pool_workers(len(seeds), n_reach, workers)
    pool = None
    if n_workers > 1:  # the prediction first, on a worker: off this process's critical path
        pool = TrialPool(run_setup, mesh, seeds[n_reach:], n_workers, predict_setup=setup)
    return SimulationRun(
        run_setup, setup, mesh, n_trials, seeds, protocol, n_reach, n_workers, pool, started
    )
