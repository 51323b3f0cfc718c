"""Export a plan as robot programs: the one export job the command line and the UI share.

:func:`export_program` checks the plan (:func:`planner.check.job.check_plan`, unless told not to),
builds the :class:`planner.export.job.ExportJob` with each target's sensor orientation and ABB
configuration from the check, and the robot's joint values and configuration at every target
(:func:`with_arm_poses`: IK next to the checked pose; FANUC ``CONFIG`` and KUKA ``S``/``T`` come
from them), and formats it with the writer registered for the format
(:data:`planner.export.FORMATS`). Whether infeasible points stop the export is the caller's
decision (``wobjcal export`` exits 1 unless ``--force``, for every format); the result says
which they are, and the job's :class:`planner.export.job.CheckStatus` (:func:`check_status`)
makes every program's header say it (``CHECKED`` / ``NOT CHECKED``, with the plan's digest),
and the estimated cycle time of each program (:func:`with_cycle_times`) too.

The plan's layout is checked even without the cell check (:func:`planner.check.job.layout_problem`):
an A-H plan that lacks a role would otherwise become a program that runs every search in the
nominal frame, silently not the paper's procedure; the result's ``layout`` says so and the
command line refuses it unless ``--force``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from calib.plan.file import Plan
from planner.check.job import ConfData, PlanCheck, check_plan, layout_problem
from planner.export import export_files
from planner.export.job import TARGET_KINDS, ArmPose, CheckStatus, ExportJob, build_job
from planner.plan_cell import nominal_T_base_wobj, open_cell, plan_controller_base, tool_data

if TYPE_CHECKING:
    from planner.cell.cell import Cell

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ProgramExport:
    """A robot program of a plan.

    Attributes:
        files: ``{suffix: text}`` of the program, e.g. ``{".src": ..., ".dat": ...}``; empty
            when the controller has no program for the plan (``layout`` says why).
        notes: what the user should know (estimated tool load, points without a checked pose).
        check: the plan check the orientations came from, or ``None`` when not run.
        layout: why the plan's procedure refuses its points (e.g. an A-H plan without a
            role: the program is then not adaptive), ``""`` when it does not.
    """

    files: dict[str, str]
    notes: tuple[str, ...]
    check: PlanCheck | None
    layout: str = ""

    @property
    def infeasible(self) -> tuple[str, ...]:
        """Ids of the points the check found infeasible (``()`` without a check)."""
        return () if self.check is None else tuple(p.point_id for p in self.check.infeasible)


def check_status(check: PlanCheck | None, layout: str = "") -> CheckStatus:
    """What the program headers say was checked: ``check`` (``None``: not run), and the
    plan's ``layout`` problem when there was no check (with one, ``check.layout``)."""
    if check is None:
        return CheckStatus(problems=(f"layout: {layout}",) if layout else ())
    problems = [f"error: {check.error}"] if check.error else []
    problems += [f"layout: {check.layout}"] if check.layout else []
    refused = tuple(p.point_id for p in check.infeasible)
    reasons = tuple(f"{p.point_id}: {p.reason}" for p in check.infeasible)
    return CheckStatus(checked=True, refused=refused, problems=tuple(problems), reasons=reasons)


def export_job_for(
    plan: Plan, plan_dir: Path, check: PlanCheck | None
) -> tuple[ExportJob, tuple[str, ...]]:
    """The export job of ``plan``, with orientations and confdata from ``check`` when given
    (and its verdict, :func:`check_status`, for the headers).

    Returns:
        The job and notes for the user.
    """
    T_nom = nominal_T_base_wobj(plan)
    tool, note = tool_data(plan, plan_dir)
    notes = [note] if note else []
    rotations: dict[str, FloatArray] = {}
    confs: dict[str, ConfData] = {}
    if check is None:
        notes.append("no check: default orientations, no confdata")
    else:
        T_wobj_base = invert_transform(T_nom)
        for r in check.points:
            if r.T_base_tcp is not None and r.pose_status != "infeasible":  # chosen pose
                T_wobj_tcp = T_wobj_base @ r.T_base_tcp
                rotations[r.point_id] = T_wobj_tcp[:3, :3]
            if r.confdata is not None:
                confs[r.point_id] = r.confdata
        no_pose = [r.point_id for r in check.points if r.point_id not in rotations]
        blocked = [r.point_id for r in check.infeasible if r.point_id in rotations]
        if no_pose:
            notes.append(f"no feasible pose for {no_pose}: default orientation, no confdata")
        if blocked:
            notes.append(f"points {blocked} are not feasible (see 'wobjcal check')")
    base = plan_controller_base(plan, plan_dir)
    if not base.is_identity:
        notes.append(base.describe())
    job = build_job(
        plan, T_nom, tool, rotations, confs, check=check_status(check),
        T_base_controller=base.T_base_controller,
        controller_base="" if base.is_identity else base.describe(),
    )  # fmt: skip
    return job, tuple(notes)


def export_program(
    plan: Plan, plan_dir: Path, fmt: str, *, run_check: bool = True, cell: Cell | None = None
) -> ProgramExport:
    """The robot program of ``plan`` in format ``fmt`` (a key of :data:`planner.export.FORMATS`).

    Args:
        plan: the plan.
        plan_dir: folder the plan's relative file references resolve against.
        fmt: the robot-program format.
        run_check: check the plan in its cell first (orientations and confdata of the chosen
            poses); ``False``: default orientations, no confdata, no cell opened.
        cell: an open cell of the plan to check in (the UI's); ``None`` opens one.

    Raises:
        InputError: unknown format, or a file of the plan cannot be loaded.
    """
    if run_check and cell is None:
        with open_cell(plan, plan_dir) as own:
            return export_program(plan, plan_dir, fmt, run_check=True, cell=own)
    check = check_plan(plan, plan_dir, cell=cell, fmt=fmt) if run_check else None
    layout = check.layout if check is not None else layout_problem(plan, fmt)
    job, notes = export_job_for(plan, plan_dir, check)
    job = replace(job, check=check_status(check, layout))
    if check is not None and cell is not None:
        job = with_arm_poses(job, cell, check, plan.cell.tool.tcp)
        job = with_cycle_times(job, plan, check, cell)
    if layout:
        notes = (*notes, f"layout: {layout}")
    if fmt in job.program_errors:  # no such program for this plan: a refusal, as check's
        return ProgramExport({}, notes, check, layout or job.program_errors[fmt])
    return ProgramExport(export_files(job, fmt), notes, check, layout)


def with_cycle_times(job: ExportJob, plan: Plan, check: PlanCheck, cell: Cell) -> ExportJob:
    """``job`` with the estimated cycle time of every controller's program
    (:func:`planner.check.cycle.plan_cycle_time`, from the poses of ``check`` in ``cell``),
    which every program's header says."""
    from planner.check.cycle import plan_cycle_time

    times = {}
    for name in job.programs:
        cycle = plan_cycle_time(plan, check.points, cell, name)
        if cycle is not None:
            times[name] = cycle
    return replace(job, cycle_times=times)


def with_arm_poses(job: ExportJob, cell: Cell, check: PlanCheck, tcp: str) -> ExportJob:
    """``job`` with the robot's joint values and configuration at every target of each point
    whose pose the check found (:class:`planner.export.job.ArmPose`).

    Each target (start, end, safe start, face end) is solved by IK and the solution nearest the
    checked pose's joint values taken, so every target keeps that pose's branch where it can.
    Robots that are not 6-axis OPW arms get none (the writers then say what they cannot write).
    """
    from planner.robot.kinematics.branches import posture

    opw = cell.solver.opw
    if opw is None or cell.chain.n_joints != 6:
        return job
    T_tcp_flange = invert_transform(cell.T_flange_tcp(tcp))
    checked = {p.point_id: p for p in check.points}
    targets = []
    for t in job.targets:
        c = checked.get(t.point_id)
        if c is None or c.q is None or c.pose_status == "infeasible":
            targets.append(t)
            continue
        poses = np.array([job.T_base_wobj @ t.target(k) @ T_tcp_flange for k in TARGET_KINDS])
        q, found = cell.solver.solve(poses).nearest(c.q)
        arm = {}
        for kind, q_k, ok in zip(TARGET_KINDS, q, found, strict=True):
            if ok:
                flags = posture(opw, q_k)
                arm[kind] = ArmPose(
                    tuple(float(v) for v in q_k), flags.front, flags.elbow_up, flags.wrist_flipped
                )
        targets.append(replace(t, arm=arm))
    return replace(job, targets=tuple(targets))
