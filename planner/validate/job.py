"""Monte Carlo validation of a plan: the one entry point the CLI, the UI and scripts share.

:func:`validate_plan` validates any plan: every procedure of the registry
(:data:`calib.procedures.PROCEDURES`), every sensor kind (:data:`planner.sim.sensors.SENSORS`),
any work-object mesh (a file in any unit, or a built-in part) and any robot. The plan's own
model objects (sensor, robot error, misplacement), its procedure settings (edge-event offset
filled in from the sensor model when unset) and its report settings go into
:func:`planner.sim.montecarlo.simulate`; ``wobjcal validate`` and the web UI's "Validate" panel
both call it, so a plan validates the same way everywhere.

A plan that cannot work is refused *before* the run, with a message naming the point and why
(:mod:`planner.check.simulatable`, whose checks are re-exported here): roles that do not fit the
procedure, a layout that leaves a degree of freedom free, an edge search with a touch probe, a
point off its planar face or with the sensor's footprint over a hole or an edge, a search too
short to reach its face (or starting too close to it) under the plan's misplacement. A run
never crashes half-way: a search that fails in a trial is counted with its reason.

Example::

    from calib.plan.file import load_plan
    from planner.validate.job import validate_plan

    report = validate_plan(load_plan("assets/plans/stator_section_ah.json"), trials=50, seed=1)
    print(report.to_markdown())
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import trimesh

from calib.errors import InputError
from calib.plan.file import Plan
from calib.procedures import procedure_kind
from planner.check.simulatable import (
    ProgressCallback,
    ValidationModels,
    check_simulatable,
    preflight,
    validation_models,
    work_object_mesh,
)
from planner.check.simulation_setup import prediction_setup, simulation_setup
from planner.errors import PlanRefused
from planner.plan_cell import nominal_T_base_wobj, open_cell
from planner.program.build import measuring_program
from planner.program.model import search_keys
from planner.sim.budget import check_run_size, run_size, sensitivity_runs
from planner.sim.montecarlo import simulate
from planner.sim.pool import prepare_pool
from planner.sim.report import ValidationReport
from planner.sim.report_points import report_rows
from planner.sim.rows import RowSpec
from planner.sim.search_events import ProgramPose, program_search_hook
from planner.sim.sensitivity import SensitivityTable, sensitivity
from planner.sim.simulation_run import SimulationRun, pool_workers, start_simulation

__all__ = [
    "ValidationModels",
    "check_simulatable",
    "prediction_setup",
    "preflight",
    "sensitivity_plan",
    "simulation_setup",
    "validate_plan",
    "validation_models",
    "work_object_mesh",
]


def validate_plan(
    plan: Plan,
    *,
    trials: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
    reach_trials: int = 0,
    plan_dir: Path | None = None,
    protocol: tuple[int, int] | None = None,
    mesh: trimesh.Trimesh | None = None,
    fmt: str | None = None,
    check: Literal["refuse", "report", "off"] = "off",
    cell: Any = None,
) -> ValidationReport:
    """Simulate the calibration of ``plan`` many times and report it, simulated beside predicted.

    Args:
        plan: the plan (any procedure, sensor, part and robot).
        trials: number of simulated calibrations (>= 2); default ``plan.validation.trials``.
        seed: seed of the ``numpy.random.Generator``; default ``plan.validation.seed``. The
            same plan, trials and seed give the same report, whatever ``workers``.
        workers: worker processes (``None``: up to 2; 1 runs in this process, as the web UI
            does so as not to start processes beside a server).
        progress: ``progress(done_trials, total_trials)``, called as trials finish.
        reach_trials: also vet every commanded search of the first ``reach_trials`` trials
            in the plan's cell (reachability, joint limits, collisions with the part where it
            really lies) with the sensor rotation and IK branch ``wobjcal check`` chose for the
            point (the exported programs' targets), so searches that fail because the part
            moved are counted with their reason; about 0.2 s a trial in the demo cell. 0: no
            cell check.
        plan_dir: folder the plan's relative file references resolve against.
        protocol: ``(positions, repeats)``: also run the paper's protocol beside the default.
        mesh: the work object's mesh (wobj, metres) when the caller has it loaded already
            (the UI); default: loaded from the plan.
        fmt: the controller whose measuring program is simulated (a key of
            :data:`planner.program.controllers.CONTROLLERS`; ``None``: the default, RAPID).
        check: first check the plan as ``wobjcal check --format fmt`` does (in the cell the
            vetting uses): ``"refuse"`` a plan check refuses, naming every problem (what
            ``wobjcal validate`` does); ``"report"``: simulate it anyway, the report lists
            check's problems (``check_problems``; ``validate --force``); ``"off"``: no
            check, unless ``reach_trials`` opens the cell (then as ``"report"``).
        cell: an open cell of the plan (a :class:`planner.cell.cell.Cell`) to check and vet
            in; ``None`` opens the plan's cell when needed and closes it afterwards.

    Returns:
        The :class:`planner.sim.report.ValidationReport`.

    Raises:
        PlanRefused: ``check="refuse"`` and check refuses the plan (every problem named).
        PlanError: the plan cannot be simulated (the message names the point or field).
        InputError: ``trials`` < 2, another argument out of range, or a mesh that cannot load.
    """
    models = check_simulatable(plan)
    size = run_size(plan, trials, protocol, fmt)
    check_run_size(size)  # memory and time, before any work
    folder = plan_dir or Path.cwd()
    part = work_object_mesh(plan, folder, models) if mesh is None else mesh
    check_run_size(dataclasses.replace(size, triangles=len(part.faces)))  # and beside the part
    if check not in ("refuse", "report", "off"):
        raise InputError(f"check must be 'refuse', 'report' or 'off', got {check!r}")
    if check != "off" or reach_trials:
        # the trials outside the cell start on the workers first: they run while the cell
        # opens and check judges the plan (an error of the start waits for check's verdict)
        try:
            started: _Started | InputError = _start(
                plan, models, part, trials, seed, workers, protocol, fmt, reach_trials
            )
        except InputError as exc:
            started = exc
        try:
            if cell is not None:
                return _validate_in_cell(
                    plan, started, cell, fmt, progress, reach_trials, check == "refuse"
                )
            with open_cell(plan, folder) as own:
                return _validate_in_cell(
                    plan, started, own, fmt, progress, reach_trials, check == "refuse"
                )
        finally:
            if isinstance(started, _Started):
                started.run.cancel()  # (nothing left to cancel once finished)
    return _simulate(plan, models, part, trials, seed, workers, progress, protocol, fmt)


@dataclass
class _Started:
    """A validation whose trials outside the cell are running (:func:`_start`)."""

    run: SimulationRun
    rows: list[RowSpec]
    paper: Mapping[tuple[str, float], float] | None


def _start(
    plan: Plan,
    models: ValidationModels,
    part: trimesh.Trimesh,
    trials: int | None,
    seed: int | None,
    workers: int | None,
    protocol: tuple[int, int] | None,
    fmt: str | None,
    vetted: int,
) -> _Started:
    """The preflight, the setup and the start of the Monte Carlo run of ``plan`` on ``part``
    (the first ``vetted`` trials wait to be vetted in the cell)."""
    n = plan.validation.trials if trials is None else int(trials)
    _prepare_workers(n, protocol, vetted, workers)
    preflight(plan, models, part)
    setup = simulation_setup(plan, models, part, fmt)
    rows = report_rows(plan.validation.report, part, models.geometry, setup.xoffset)
    rng = np.random.default_rng(plan.validation.seed if seed is None else seed)
    run = start_simulation(setup, part, n, rng, vetted=vetted, protocol=protocol, workers=workers)
    return _Started(run, rows, _published(models))


def _prepare_workers(
    n_trials: int, protocol: tuple[int, int] | None, vetted: int, workers: int | None
) -> None:
    """Start the workers' fork server now when the run will use workers, so that its imports
    overlap the preflight (:func:`planner.sim.pool.prepare_pool`)."""
    n_seeds = n_trials + (0 if protocol is None else protocol[0] * protocol[1])
    if pool_workers(n_seeds, vetted, workers) > 1:
        prepare_pool()


def _published(models: ValidationModels) -> Mapping[tuple[str, float], float] | None:
    """The procedure's published half-widths (the paper's Table 1 for A-H), on a built-in
    part; else None."""
    return procedure_kind(models.method).published if models.geometry is not None else None


def _validate_in_cell(
    plan: Plan,
    started: _Started | InputError,
    cell: Any,
    fmt: str | None,
    progress: ProgressCallback | None,
    reach_trials: int,
    refuse: bool,
) -> ValidationReport:
    """Check the plan in its open ``cell`` (check's verdict, and the poses the vetting uses)
    while the run's workers go on, then finish the run (the vetted trials here)."""
    from planner.check.job import check_plan

    checked = check_plan(plan, cell=cell, fmt=fmt)
    problems = checked.problems()
    if problems and refuse:
        raise PlanRefused(measuring_program(plan, fmt).name, problems)
    if isinstance(started, InputError):
        raise started
    hook = None
    if reach_trials:
        T_nom = nominal_T_base_wobj(plan)
        poses = {
            c.point_id: ProgramPose(
                np.asarray(c.T_base_tcp)[:3, 0], c.branch, np.asarray(c.q, dtype=float)
            )
            for c in checked.points
            if c.T_base_tcp is not None and c.q is not None
        }
        program = measuring_program(plan, fmt)
        keys = search_keys(program.points)
        # the x-offset run's searches are commanded with D's orientation (A-H programs)
        d = next((rp.point.id for rp in program.points if rp.role == "D"), None)
        hook = program_search_hook(cell, poses, keys, T_nom, plan.cell.tool.tcp, other_searches=d)
    report = started.run.finish(
        started.rows,
        reachability=hook,
        cell=cell if reach_trials else None,
        paper=started.paper,
        progress=progress,
    )
    return dataclasses.replace(report, check_problems=problems)


def _simulate(
    plan: Plan,
    models: ValidationModels,
    part: trimesh.Trimesh,
    trials: int | None,
    seed: int | None,
    workers: int | None,
    progress: ProgressCallback | None,
    protocol: tuple[int, int] | None,
    fmt: str | None,
) -> ValidationReport:
    """The preflight and the Monte Carlo run of ``plan`` on ``part``."""
    n = plan.validation.trials if trials is None else int(trials)
    _prepare_workers(n, protocol, 0, workers)
    preflight(plan, models, part)
    setup = simulation_setup(plan, models, part, fmt)
    rows = report_rows(plan.validation.report, part, models.geometry, setup.xoffset)
    paper = _published(models)
    rng = np.random.default_rng(plan.validation.seed if seed is None else seed)
    return simulate(
        setup, part, rows, n, rng, protocol=protocol, paper=paper, workers=workers,
        progress=progress,
    )  # fmt: skip


def sensitivity_plan(
    plan: Plan,
    *,
    trials: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
    plan_dir: Path | None = None,
    mesh: trimesh.Trimesh | None = None,
    fmt: str | None = None,
) -> SensitivityTable:
    """The sensitivity table of ``plan``: its rows with each noise term off in turn
    (:mod:`planner.sim.sensitivity`), ``trials`` trials per column (default the plan's).

    Raises:
        PlanError, InputError: as :func:`validate_plan`.
    """
    models = check_simulatable(plan)
    size = run_size(plan, trials, None, fmt, runs=sensitivity_runs(plan))
    check_run_size(size, "sensitivity")
    part = work_object_mesh(plan, plan_dir or Path.cwd(), models) if mesh is None else mesh
    check_run_size(dataclasses.replace(size, triangles=len(part.faces)), "sensitivity")
    preflight(plan, models, part)
    setup = simulation_setup(plan, models, part, fmt)
    rows = report_rows(plan.validation.report, part, models.geometry, setup.xoffset)
    n = plan.validation.trials if trials is None else int(trials)
    return sensitivity(
        setup,
        part,
        rows,
        n,
        plan.validation.seed if seed is None else int(seed),
        workers=workers,
        progress=progress,
    )
