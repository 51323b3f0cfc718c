"""Monte Carlo validation of a plan: the one entry point the CLI, the UI and scripts share.

:func:`validate_plan` validates any plan: every procedure of the registry
(:data:`calib.procedures.PROCEDURES`), every sensor kind (:data:`planner.sim.sensors.SENSORS`),
any work-object mesh (a file in any unit, or a built-in part) and any robot. The plan's own
model objects (sensor, robot error, misplacement), its procedure settings (edge-event offset
filled in from the sensor model when unset) and its report settings go into
:func:`planner.sim.montecarlo.simulate`; ``wobjcal validate`` and the web UI's "Validate" panel
both call it, so a plan validates the same way everywhere.

A plan that cannot work is refused *before* the run, with a message naming the point and why
(:func:`check_simulatable` and :func:`preflight`): roles that do not fit the procedure, a layout
that leaves a degree of freedom free, an edge search with a touch probe, a point off its planar
face or with the sensor's footprint over a hole or an edge, a search too short to reach its
face (or starting too close to it) under the plan's misplacement. A run never crashes half-way:
a search that fails in a trial is counted with its reason.

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
import trimesh

from calib.errors import InputError
from calib.estimators.layout import search_constraint_set
from calib.estimators.observability import analyze_layout
from calib.models import Misplacement, RobotErrorModel
from calib.plan.file import Plan, PlanError, resolve_ref
from calib.procedures import RolePoint, procedure_kind
from planner.export.safety import SafetySpec
from planner.parts.stator import StatorGeometry
from planner.plan_cell import nominal_T_base_wobj, open_cell
from planner.sim.montecarlo import simulate
from planner.sim.report import PAPER_TABLE1, ValidationReport
from planner.sim.report_points import report_rows
from planner.sim.sensitivity import SensitivityTable, sensitivity
from planner.sim.sensors import sensor_kind
from planner.sim.setup import (
    DEFAULT_EDGE_INSET_M,
    SimulationSetup,
    default_pivot,
    face_lookup,
    resolved_settings,
)
from planner.sim.xoffset import xoffset_setup

__all__ = [
    "SIMULATED_PARTS",
    "ValidationModels",
    "check_simulatable",
    "preflight",
    "sensitivity_plan",
    "validate_plan",
    "validation_models",
    "work_object_mesh",
]

#: Built-in stators -> the ``StatorGeometry`` constructor (their slot holes, bulge, epsilon).
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
        sensor: the sensor model (``plan.validation.sensor``, any kind).
        robot_error: the robot error model (``plan.validation.robot_error``).
        misplacement: the part placement tolerance (``plan.validation.misplacement``).
        method: the procedure's registry name.
        settings: the procedure's settings; an unset ``edge_event_offset_m`` is the sensor's
            analytic straight-edge offset at ``edge_inset_m``.
        points: the plan's points with the procedure's roles.
        geometry: the stator geometry of a built-in stator work object, else ``None``.
        edge_inset_m: how far inside the face edge searches run, metres.
    """

    sensor: Any
    robot_error: RobotErrorModel
    misplacement: Misplacement
    method: str
    settings: Any
    points: tuple[RolePoint, ...]
    geometry: StatorGeometry | None
    edge_inset_m: float = DEFAULT_EDGE_INSET_M


def _name(plan: Plan, point_id: str) -> str:
    ids = [p.id for p in plan.points]
    return f"points[{ids.index(point_id)}] ({point_id})" if point_id in ids else point_id


def validation_models(plan: Plan) -> ValidationModels:
    """The models, procedure and roles of ``plan`` (see :func:`check_simulatable`)."""
    return check_simulatable(plan)


def check_simulatable(plan: Plan) -> ValidationModels:
    """Raise unless the validation can simulate ``plan`` (checks that need no mesh).

    Returns:
        The plan's :class:`ValidationModels`.

    Raises:
        PlanError: the points lack a role the procedure needs, the procedure cannot use them
            (e.g. an A-H layout against the paper's conditions, 3-2-1 faces parallel), the
            layout leaves a degree of freedom free, the sensor has no simulator, a touch probe
            is asked for an edge search, or an x-offset run is asked for on a part without
            slot holes; the message names the point or field.
    """
    plan.require_complete()
    kind = procedure_kind(plan.procedure)
    v = plan.validation
    sensor_kind(v.sensor)  # a simulator for this sensor
    try:
        points = tuple(kind.assign(plan.role_points()))
    except PlanError:
        raise
    except InputError as exc:
        raise PlanError(f"points: {plan.method} cannot use this layout: {exc}") from None
    if not v.sensor.runs_edge_searches:
        for p in plan.points:
            if p.search.kind == "edge":
                raise PlanError(
                    f"{_name(plan, p.id)}.search.kind: a {v.sensor.KIND} sensor cannot run an "
                    "edge search (it cannot find where a face ends while sliding over it)"
                )
    report = analyze_layout(search_constraint_set([rp.point for rp in points]))
    if report.rating == "unobservable":
        free = "; ".join(m.message for m in report.unconstrained)
        raise PlanError(
            f"points: the layout does not fix all 6 degrees of freedom (an edge search counts "
            f"by its edge coordinate only): {free}"
        )
    geometry = None
    if plan.work_object.mesh in SIMULATED_PARTS:
        geometry = getattr(StatorGeometry, SIMULATED_PARTS[plan.work_object.mesh])()
    if getattr(plan.procedure, "xoffset", None) is not None and geometry is None:
        raise PlanError(
            "procedure.xoffset: the x-offset run is simulated only on a built-in stator "
            f"(its true slot holes), not on {plan.work_object.mesh!r}"
        )
    return ValidationModels(
        sensor=v.sensor,
        robot_error=v.robot_error,
        misplacement=v.misplacement,
        method=plan.method,
        settings=resolved_settings(plan.procedure, v.sensor, DEFAULT_EDGE_INSET_M),
        points=points,
        geometry=geometry,
        edge_inset_m=DEFAULT_EDGE_INSET_M,
    )


def work_object_mesh(plan: Plan, plan_dir: Path, models: ValidationModels) -> trimesh.Trimesh:
    """The true part's mesh in wobj, metres: a built-in stator's from its geometry, else the
    plan's file (or built-in) loaded in its units and lightly repaired, as the cell does.

    Raises:
        InputError: the mesh cannot be loaded (the message names the file).
    """
    if models.geometry is not None:
        from planner.parts.stator_mesh import build_stator_mesh

        return build_stator_mesh(models.geometry)
    from planner.cell.workobject import load_work_object

    wo = plan.work_object
    return load_work_object(resolve_ref(wo.mesh, plan_dir), units=wo.units).mesh


def preflight(plan: Plan, models: ValidationModels, mesh: trimesh.Trimesh) -> None:
    """Refuse a plan whose points or searches cannot work on ``mesh``, before any trial.

    Every point must lie on a planar face with the sensor's footprint on it
    (:func:`planner.faces.checks.plan_face_reasons`); every search must reach its face under
    the plan's misplacement (the bound of :class:`planner.export.safety.SafetySpec`, the same
    the exported programs use): an approach must start at least the face's largest shift plus
    the sensor's standoff out, and run at least the shift past it; an edge search must start
    at least the shift before the edge and run at least the shift plus the sensor's edge-event
    offset past it.

    Raises:
        PlanError: naming every point that fails, and why.
    """
    from planner.faces.checks import plan_face_reasons

    probes = [p.to_probe_point() for p in plan.points]
    r = max(float(models.sensor.footprint_radius_m), 1e-4)  # a point sensor: a tiny disk
    why = {
        p.id: f"not on a planar face: {reason}"
        for p, reason in zip(
            plan.points, plan_face_reasons(mesh, probes, footprint_radius_m=r), strict=True
        )
        if reason
    }
    m = models.misplacement
    pivot = default_pivot(list(models.points))
    safety = SafetySpec(
        max_translation_m=m.max_translation_m,
        max_angle_rad=m.max_angle_rad,
        pivot_wobj_m=(float(pivot[0]), float(pivot[1]), float(pivot[2])),
        sensing_distance_m=models.sensor.standoff_m,
        margin_m=0.0,
    )
    edge_offset = float(getattr(models.settings, "edge_event_offset_m", 0.0) or 0.0)
    for p in probes:
        if p.id in why:
            continue
        shift = safety.surface_shift_bound_m(p.position_m)
        s = p.search
        if s.kind == "approach":
            start_needed = safety.start_clearance_m(p.position_m)
            run_needed = shift
        else:
            start_needed = shift
            run_needed = shift + edge_offset
        if s.start_offset_m < start_needed:
            why[p.id] = (
                f"the search starts {s.start_offset_m * 1e3:.1f} mm "
                f"{'out' if s.kind == 'approach' else 'before the edge'}, but the part may lie "
                f"up to {shift * 1e3:.1f} mm closer; it needs at least "
                f"{start_needed * 1e3:.1f} mm"
            )
        elif s.overtravel_m < run_needed:
            why[p.id] = (
                f"the search runs {s.overtravel_m * 1e3:.1f} mm past the nominal "
                f"{'face' if s.kind == 'approach' else 'edge'}, but the part may lie up to "
                f"{shift * 1e3:.1f} mm farther; it needs at least {run_needed * 1e3:.1f} mm"
            )
    if why:
        lines = "; ".join(f"{_name(plan, pid)}: {w}" for pid, w in why.items())
        raise PlanError(f"cannot validate this plan: {lines}")


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
) -> ValidationReport:
    """Simulate the calibration of ``plan`` many times and report it, simulated beside predicted.

    Args:
        plan: the plan (any procedure, sensor, part and robot).
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
        plan_dir: folder the plan's relative file references resolve against.
        protocol: ``(positions, repeats)``: also run the paper's protocol beside the default.
        mesh: the work object's mesh (wobj, metres) when the caller has it loaded already
            (the UI); default: loaded from the plan.

    Returns:
        The :class:`planner.sim.report.ValidationReport`.

    Raises:
        PlanError: the plan cannot be simulated (the message names the point or field).
        InputError: ``trials`` < 2, another argument out of range, or a mesh that cannot load.
    """
    models = check_simulatable(plan)
    folder = plan_dir or Path.cwd()
    part = work_object_mesh(plan, folder, models) if mesh is None else mesh
    preflight(plan, models, part)
    setup = _setup(plan, models, part)
    rows = report_rows(plan.validation.report, part, models.geometry, setup.xoffset)
    paper = PAPER_TABLE1 if models.geometry is not None and models.method == "hultman2013" else None
    n = plan.validation.trials if trials is None else int(trials)
    rng = np.random.default_rng(plan.validation.seed if seed is None else seed)
    kwargs: dict[str, Any] = {
        "protocol": protocol,
        "paper": paper,
        "workers": workers,
        "progress": progress,
    }
    if reach_trials:
        with open_cell(plan, folder) as cell:
            return simulate(
                setup, part, rows, n, rng, cell=cell, reach_trials=reach_trials, **kwargs
            )
    return simulate(setup, part, rows, n, rng, **kwargs)


def sensitivity_plan(
    plan: Plan,
    *,
    trials: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
    plan_dir: Path | None = None,
    mesh: trimesh.Trimesh | None = None,
) -> SensitivityTable:
    """The sensitivity table of ``plan``: its rows with each noise term off in turn
    (:mod:`planner.sim.sensitivity`), ``trials`` trials per column (default the plan's).

    Raises:
        PlanError, InputError: as :func:`validate_plan`.
    """
    models = check_simulatable(plan)
    part = work_object_mesh(plan, plan_dir or Path.cwd(), models) if mesh is None else mesh
    preflight(plan, models, part)
    setup = _setup(plan, models, part)
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


def _setup(plan: Plan, models: ValidationModels, mesh: trimesh.Trimesh) -> SimulationSetup:
    xo = getattr(models.settings, "xoffset", None)
    xs = None
    if xo is not None and models.geometry is not None:
        g = models.geometry
        grid = xo.grid
        y, z = np.meshgrid(grid.slot_y_m, grid.layer_z_m, indexing="xy")  # (layers, slots)
        if not np.all(g.hole_near(y, z)):
            raise PlanError(
                "procedure.xoffset: the slot grid does not lie on the stator's slot holes"
            )
        # the true hole of each target: at its y and z, pushed out by the bolts' bulge
        xs = xoffset_setup(xo, np.stack([g.side_face_offset_m(y, z), y, z], axis=-1))
    px = tuple(RolePoint("xoffset", p) for row in (xs.points if xs else ()) for p in row)
    return SimulationSetup(
        points=models.points,
        method=models.method,
        settings=models.settings,
        T_base_wobj_nominal=nominal_T_base_wobj(plan),
        sensor=models.sensor,
        robot_error=models.robot_error,
        misplacement=models.misplacement,
        pivot_wobj_m=default_pivot(list(models.points)),
        faces=face_lookup(mesh, models.points + px, models.sensor.footprint_radius_m),
        xoffset=xs,
        edge_inset_m=models.edge_inset_m,
    )
