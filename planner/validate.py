"""Monte Carlo validation of a plan: the one entry point the CLI, the UI and scripts share.

:func:`validate_plan` turns a :class:`calib.plan.file.Plan` into the simulation's models (sensor,
robot error, misplacement, A-H procedure settings, stator geometry) and runs
:func:`planner.sim.montecarlo.validate`. ``wobjcal validate`` and the web UI's "Validate" panel both
call it, so a plan validates the same way everywhere.

Example::

    from calib.plan.file import load_plan
    from planner.validate import validate_plan

    report = validate_plan(load_plan("assets/plans/stator_section_ah.json"), trials=50, seed=1)
    print(report.to_markdown())
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from calib.models import Misplacement, RobotErrorModel
from calib.models.proximity import ProximitySensor
from calib.paper.settings import Hultman2013
from calib.plan.file import Plan, PlanError
from calib.procedures.hultman2013 import points_by_role
from planner.parts.stator import StatorGeometry
from planner.plan_cell import nominal_T_base_wobj, open_cell
from planner.sim.montecarlo import DEFAULT_EDGE_INSET_M, ValidationReport, validate
from planner.sim.trial import resolved_settings

__all__ = [
    "SIMULATED_PARTS",
    "ValidationModels",
    "check_simulatable",
    "validate_plan",
    "validation_models",
]

#: Built-in work objects the validation can simulate -> the ``StatorGeometry`` constructor.
SIMULATED_PARTS: dict[str, str] = {
    "builtin:stator_section": "full_section",
    "builtin:stator_prototype": "prototype",
}

#: progress(done_trials, total_trials)
ProgressCallback = Callable[[int, int], None]


@dataclass(frozen=True)
class ValidationModels:
    """What the simulation of a plan uses, built from the plan by :func:`validation_models`.

    Attributes:
        sensor: the proximity-sensor model (``plan.validation.sensor``).
        robot_error: the robot error model (``plan.validation.robot_error``).
        misplacement: the part placement tolerance (``plan.validation.misplacement``).
        settings: the A-H procedure settings; ``edge_event_offset_m`` is the plan's, or when
            unset the sensor's analytic straight-edge offset at ``edge_inset_m``.
        geometry: the simulated stator geometry (``plan.work_object.mesh``).
        edge_inset_m: how far inside the face edge searches run, metres.
    """

    sensor: ProximitySensor
    robot_error: RobotErrorModel
    misplacement: Misplacement
    settings: Hultman2013
    geometry: StatorGeometry
    edge_inset_m: float = DEFAULT_EDGE_INSET_M


def check_simulatable(plan: Plan) -> Hultman2013:
    """Raise unless the validation can simulate ``plan``; return its A-H settings.

    Raises:
        PlanError: the procedure is not ``hultman2013`` (names ``procedure.method``), or the
            work object is not a built-in stator (names ``work_object.mesh``).
    """
    if not isinstance(plan.procedure, Hultman2013):
        raise PlanError(
            f"procedure.method: validation simulates only hultman2013 (the paper's A-H "
            f"procedure), got {plan.method!r}"
        )
    if plan.work_object.mesh not in SIMULATED_PARTS:
        raise PlanError(
            f"work_object.mesh: validation simulates only the built-in stators "
            f"{sorted(SIMULATED_PARTS)}, got {plan.work_object.mesh!r}"
        )
    return plan.procedure


def validation_models(plan: Plan) -> ValidationModels:
    """The sensor, robot-error, misplacement, procedure and geometry models of ``plan``.

    The sensor, robot error and misplacement are the plan's own objects; the A-H settings are
    the plan's with an unset edge-event offset resolved from the sensor
    (:func:`planner.sim.trial.resolved_settings`).

    Raises:
        PlanError: the plan cannot be simulated (see :func:`check_simulatable`).
    """
    proc = check_simulatable(plan)
    v = plan.validation
    return ValidationModels(
        sensor=v.sensor,
        robot_error=v.robot_error,
        misplacement=v.misplacement,
        settings=resolved_settings(proc, v.sensor, DEFAULT_EDGE_INSET_M),
        geometry=getattr(StatorGeometry, SIMULATED_PARTS[plan.work_object.mesh])(),
        edge_inset_m=DEFAULT_EDGE_INSET_M,
    )


def validate_plan(
    plan: Plan,
    *,
    trials: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
    reach_trials: int = 0,
    plan_dir: Path | None = None,
) -> ValidationReport:
    """Simulate the calibration of ``plan`` many times and summarise it like Table 1.

    Args:
        plan: the plan (``hultman2013`` procedure on a built-in stator work object).
        trials: number of simulated calibrations (>= 2); default ``plan.validation.trials``.
        seed: seed of the ``numpy.random.Generator``; default ``plan.validation.seed``. The
            same plan, trials and seed give the same report, whatever ``workers``.
        workers: worker processes (``None``: up to 2; 1 runs in this process, as the web UI
            does so as not to fork a threaded server).
        progress: ``progress(done_trials, total_trials)``, called as trials finish.
        reach_trials: also vet every commanded search of the first ``reach_trials`` trials
            in the plan's cell (reachability, joint limits, collisions with the part where it
            really lies), so searches that fail because the part moved are counted with their
            reason; about 0.2 s a trial in the demo cell. 0: no cell check.
        plan_dir: folder the plan's relative file references resolve against (for the cell).

    Returns:
        The :class:`planner.sim.report.ValidationReport`.

    Raises:
        PlanError: the plan cannot be simulated (the message names the field), or its points
            lack an A-H role.
        InputError: ``trials`` < 2 or another argument is out of range.
    """
    models = validation_models(plan)
    if reach_trials:
        with open_cell(plan, plan_dir or Path.cwd()) as cell:
            return _run(plan, models, trials, seed, workers, progress, cell, reach_trials)
    return _run(plan, models, trials, seed, workers, progress, None, 0)


def _run(
    plan: Plan,
    models: ValidationModels,
    trials: int | None,
    seed: int | None,
    workers: int | None,
    progress: ProgressCallback | None,
    cell: Any,
    reach_trials: int,
) -> ValidationReport:
    return validate(
        points_by_role(plan.role_points()),
        models.geometry,
        nominal_T_base_wobj(plan),
        plan.validation.trials if trials is None else int(trials),
        np.random.default_rng(plan.validation.seed if seed is None else seed),
        sensor=models.sensor,
        robot_error=models.robot_error,
        misplacement=models.misplacement,
        settings=models.settings,
        edge_inset_m=models.edge_inset_m,
        workers=workers,
        progress=progress,
        cell=cell,
        reach_trials=reach_trials if cell is not None else None,
    )
