"""The checks before a plan's Monte Carlo validation: what the simulation needs, refused early.

:func:`check_simulatable` needs no mesh: the points' roles fit the procedure, the layout fixes
all six degrees of freedom, the sensor has a simulator and can run the plan's searches, an
x-offset run asks for a part with slot holes. :func:`preflight` checks the plan on the part's
mesh (:func:`work_object_mesh`): every point on a planar face with the sensor's footprint on it,
every search long enough to reach its face under the plan's misplacement. Both raise
:class:`calib.plan.file.PlanError` naming the point and why; :mod:`planner.validate.job` runs them
before any trial.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import trimesh

from calib.errors import InputError
from calib.estimators.layout import search_constraint_set
from calib.estimators.observability import analyze_layout
from calib.models import Misplacement, RobotErrorModel
from calib.plan.file import Plan, PlanError
from calib.procedures import RolePoint, procedure_kind
from planner.builtins import builtin_geometry
from planner.parts.stator import StatorGeometry
from planner.program.build import safety_spec
from planner.program.reach import search_problems
from planner.program.settings import DEFAULT_EDGE_INSET_M, resolved_settings
from planner.sim.sensors import sensor_kind

__all__ = [
    "ProgressCallback",
    "ValidationModels",
    "check_simulatable",
    "preflight",
    "validation_models",
    "work_object_mesh",
]

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
    if plan.work_object.mesh_pose is None:  # a built-in's exact geometry, in its own frame
        exact = builtin_geometry(plan.work_object.mesh)
        geometry = exact if isinstance(exact, StatorGeometry) else None
    if getattr(plan.procedure, "xoffset", None) is not None and geometry is None:
        raise PlanError(
            "procedure.xoffset: the x-offset run is simulated only on a built-in stator "
            f"(its true slot holes) in its own frame (no work_object.T_wobj_mesh), not on "
            f"{plan.work_object.mesh!r}"
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
    plan's file (or built-in) as every job loads it (:func:`planner.plan_cell.plan_work_object`:
    its units, light repair, ``work_object.T_wobj_mesh``).

    Raises:
        InputError: the mesh cannot be loaded (the message names the file).
    """
    if models.geometry is not None:
        from planner.parts.stator_mesh import build_stator_mesh

        return build_stator_mesh(models.geometry)
    from planner.plan_cell import plan_work_object

    return plan_work_object(plan, plan_dir).mesh


def preflight(plan: Plan, models: ValidationModels, mesh: trimesh.Trimesh) -> None:
    """Refuse a plan whose points or searches cannot work on ``mesh``, before any trial.

    Every point must lie on a planar face with the sensor's footprint on it
    (:func:`planner.faces.checks.plan_face_reasons`); every search must reach its face under
    the plan's misplacement as the program runs it (:func:`planner.program.reach.search_problems`,
    which ``wobjcal check`` runs too: an approach starts at the safe start and must run at least
    the face's largest shift past the nominal face; an edge search must start at least the
    shift before the edge and run at least the shift plus the sensor's edge-event offset past
    it). Every problem of every point is named at once.

    Raises:
        PlanError: naming every point that fails, and why.
    """
    from planner.cell import disk_cache  # the faces' footprint test, kept across commands
    from planner.faces.checks import plan_face_reasons

    probes = [p.to_probe_point() for p in plan.points]
    r = max(float(models.sensor.footprint_radius_m), 1e-4)  # a point sensor: a tiny disk
    why = {
        p.id: f"not on a planar face: {reason}"
        for p, reason in zip(
            plan.points,
            plan_face_reasons(mesh, probes, footprint_radius_m=r, cache=disk_cache),
            strict=True,
        )
        if reason
    }
    edge_offset = float(getattr(models.settings, "edge_event_offset_m", 0.0) or 0.0)
    reach = search_problems([p for p in probes if p.id not in why], safety_spec(plan), edge_offset)
    why.update((pid, str(r)) for pid, r in reach.items())
    if why:
        lines = "; ".join(f"{_name(plan, pid)}: {w}" for pid, w in why.items())
        raise PlanError(f"cannot validate this plan: {lines}")
