"""A prediction that fails stops the run at once (:mod:`planner.sim.simulation_run`).

With worker processes the prediction runs on a worker while this process runs the vetted
trials; its failure used to surface only after every vetted trial had run (minutes with
``--reach-trials`` in the hundreds). The trials are counted, not timed: the real trials are
replaced by a counting stub (the run never reaches its report). The prediction fails where a
real one does, in its run of the plan's program on the ideal part, patched in this process.

The pool's workers normally come from a fork server, which knows nothing of a patch made here;
these tests fork this process instead, so that the workers carry the patch, and stub the
workers' trials out, so that no worker casts a ray (a forked child's first ray batch can hang
on a lock that Embree's threads in this process held: :mod:`planner.sim.pool`).
"""

from __future__ import annotations

import multiprocessing as mp
from concurrent.futures import wait
from multiprocessing.synchronize import Event

import numpy as np
import pytest
import trimesh

from bench.box_plans import POINT_SENSOR, box_mesh, box_plans
from calib.errors import InputError, ProbeFailedError
from planner.sim import pool as pool_module
from planner.sim import predict as predict_module
from planner.sim import trial_pool as trial_pool_module
from planner.sim.report_points import report_rows
from planner.sim.rows import RowSpec
from planner.sim.setup import SimulationSetup
from planner.sim.simulation_run import MIN_POOL_TRIALS, SimulationRun, start_simulation
from planner.sim.trial import TrialRunner, TrialSeed
from planner.validate.job import check_simulatable, simulation_setup

VETTED = 6
NOT_SMOOTH = InputError("linearisation: moving search 3 (C) changed the number of searches")
PROBE_FAILED = ProbeFailedError("C", "no surface within the search length")


def _box() -> tuple[SimulationSetup, trimesh.Trimesh, list[RowSpec]]:
    """The 3-2-1 plan on the ideal box: a setup built in milliseconds."""
    mesh = box_mesh()
    plan = box_plans(POINT_SENSOR)["three_two_one"]
    models = check_simulatable(plan)
    setup = simulation_setup(plan, models, mesh, None)
    return setup, mesh, report_rows(plan.validation.report, mesh, models.geometry, setup.xoffset)


def _prediction_raises(
    monkeypatch: pytest.MonkeyPatch, exc: Exception, gate: Event | None = None
) -> None:
    """Make the prediction's run of the program on the ideal part raise ``exc``, once ``gate``
    is set (in whichever process runs it: a forked worker shares the event)."""

    def execute(*args: object, **kwargs: object) -> None:
        if gate is not None and not gate.wait(60.0):
            raise AssertionError("the test never let the prediction fail")
        raise exc

    monkeypatch.setattr(predict_module, "execute", execute)


def _no_trials(*args: object) -> list[object]:
    """A worker's set-up and chunks, stubbed: the workers only predict."""
    return []


def _start(
    monkeypatch: pytest.MonkeyPatch,
    calls: list[TrialSeed],
    first_trial_waits: bool,
    exc: Exception = NOT_SMOOTH,
) -> tuple[SimulationRun, list[RowSpec]]:
    """A started two-worker run whose prediction raises ``exc`` and whose trials only count
    themselves into ``calls`` (in this process; the forked workers run none).

    With ``first_trial_waits`` the prediction fails only once the first vetted trial has
    begun (a gate the trial opens), so the run meets the failure between two trials, never
    before the first: the order is fixed, not left to how fast the worker starts."""
    started: list[SimulationRun] = []
    gate = mp.get_context("fork").Event()
    if not first_trial_waits:
        gate.set()

    def counted(self: TrialRunner, seed: TrialSeed, reach: object) -> None:
        calls.append(seed)
        if first_trial_waits and len(calls) == 1 and started:
            pool = started[0].pool
            assert pool is not None and pool.prediction is not None
            gate.set()
            wait([pool.prediction])  # the prediction fails while the vetted trials run

    _prediction_raises(monkeypatch, exc, gate)
    monkeypatch.setattr(TrialRunner, "run_trial", counted)
    monkeypatch.setattr(pool_module, "start_method", lambda: "fork")
    monkeypatch.setattr(trial_pool_module, "init_worker", _no_trials)
    monkeypatch.setattr(trial_pool_module, "run_chunk_in_worker", _no_trials)
    setup, mesh, rows = _box()
    n_trials = MIN_POOL_TRIALS + VETTED
    run = start_simulation(
        setup, mesh, n_trials, np.random.default_rng(5), vetted=VETTED, workers=2
    )
    started.append(run)
    assert run.pool is not None and run.pool.prediction is not None, "expected workers"
    return run, rows


def test_a_prediction_failed_before_finish_runs_no_vetted_trial(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls: list[TrialSeed] = []
    run, rows = _start(monkeypatch, calls, first_trial_waits=False)
    try:
        assert run.pool is not None and run.pool.prediction is not None
        wait([run.pool.prediction])  # failed on its worker while the caller did other work
        with pytest.raises(InputError, match="changed the number of searches"):
            run.finish(rows)
    finally:
        run.cancel()
    assert calls == [], f"{len(calls)} of {VETTED} vetted trials ran after the prediction failed"


def test_a_prediction_failing_during_the_vetted_trials_stops_them(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls: list[TrialSeed] = []
    run, rows = _start(monkeypatch, calls, first_trial_waits=True)
    try:
        with pytest.raises(InputError, match="changed the number of searches"):
            run.finish(rows)
    finally:
        run.cancel()
    assert len(calls) == 1, f"{len(calls)} of {VETTED} vetted trials ran, expected 1"
    assert run.pool is None  # its workers were killed with it


def test_a_failed_search_of_the_prediction_on_a_worker_is_one_clear_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A :class:`ProbeFailedError` does not pickle back from a worker (it came back as a
    broken pool, an internal error): it comes back as one line naming the prediction, which
    the CLI prints as an error (exit 2, no traceback)."""
    calls: list[TrialSeed] = []
    run, rows = _start(monkeypatch, calls, first_trial_waits=True, exc=PROBE_FAILED)
    try:
        with pytest.raises(InputError) as err:
            run.finish(rows)
    finally:
        run.cancel()
    assert str(err.value) == (
        "the prediction (the plan's procedure linearised on the ideal part) failed: "
        "probe 'C' failed: no surface within the search length"
    )
    assert len(calls) == 1, f"{len(calls)} of {VETTED} vetted trials ran, expected 1"


def test_a_prediction_failure_in_process_comes_before_any_trial(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """One worker: predicted here first, the same message, no trial run."""
    calls: list[TrialSeed] = []
    _prediction_raises(monkeypatch, PROBE_FAILED)
    monkeypatch.setattr(TrialRunner, "run_trial", lambda self, seed, reach: calls.append(seed))
    setup, mesh, rows = _box()
    run = start_simulation(setup, mesh, 8, np.random.default_rng(5), vetted=2, workers=1)
    assert run.pool is None
    with pytest.raises(InputError, match=r"the prediction \(.*\) failed: probe 'C' failed"):
        run.finish(rows)
    assert calls == []
