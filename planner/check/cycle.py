"""The cycle time of a plan's measuring program, from the check's poses and the robot's URDF.

:func:`plan_cycle_time` gathers what the pure model (:mod:`planner.program.cycle_time`) takes:
the joint values the check chose at every point's safe start
(:attr:`planner.check.results.PointCheck.q_safe`, the poses every exported program is written
with), the plan's vias and search speeds, the joint velocity limits of the robot's URDF
(:func:`urdf_joint_velocities`), the plan's ``validation.cycle`` figures, and for the A-H
program's x-offset run the joint values at each of its starts (IK next to D's checked pose, with
D's sensor orientation, as the exporters write them). ``wobjcal check`` (table and ``--json``),
``wobjcal export`` (every program's header) and the web UI's status line call it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.frames import invert_transform, make_transform
from calib.plan.file import Plan
from planner.check.paths import measured_starts_wobj
from planner.check.results import PointCheck
from planner.plan_cell import nominal_T_base_wobj
from planner.program.build import measuring_program
from planner.program.controllers import controller
from planner.program.cycle_time import (
    CycleTime,
    JointMotionLimits,
    cycle_time,
    joint_motion_limits,
    xoffset_starts_wobj,
)
from planner.program.model import MeasuringProgram

if TYPE_CHECKING:
    from planner.cell.cell import Cell

FloatArray = NDArray[np.float64]

#: Key of the velocity limits in a cell's ``query_cache`` (read from its URDF once per cell).
_CACHE_KEY = "cycle_time.joint_velocities"


def urdf_joint_velocities(cell: Cell) -> tuple[float, ...]:
    """The velocity limit of each of the cell's chain joints from its URDF ``<limit
    velocity>``, rad/s (m/s sliding), chain order; 0.0 where the URDF gives none (or when the
    chain was not read from a file)."""
    cached = cell.query_cache.get(_CACHE_KEY)
    if isinstance(cached, tuple):
        return cached
    from planner.robot.urdf import load_urdf

    chain = cell.chain
    by_name: dict[str, float] = {}
    if chain.urdf_path is not None:
        model = load_urdf(chain.urdf_path, check_meshes=False)
        by_name = {j.name: j.limit.velocity for j in model.joints if j.limit is not None}
    out = tuple(float(by_name.get(n, 0.0)) for n in chain.joint_names)
    cell.query_cache[_CACHE_KEY] = out
    return out


def cell_motion_limits(cell: Cell, plan: Plan, fmt: str | None = None) -> JointMotionLimits:
    """The joint limits of the cycle-time model for ``plan``'s robot in ``cell`` as the
    controller ``fmt`` (``None``: the default) commands its joint moves
    (:attr:`planner.program.controllers.Controller.joint_move`): the URDF's velocities, the
    plan's ``validation.cycle.joint_acceleration_rad_s2``, the TCP of the plan's tool."""
    acc = plan.validation.cycle_settings.joint_acceleration_rad_s2
    T_flange_tcp = cell.T_flange_tcp(plan.cell.tool.tcp)

    def tool_path(qs: FloatArray) -> FloatArray:
        return np.asarray(cell.chain.fk(qs), dtype=np.float64) @ T_flange_tcp

    return joint_motion_limits(
        cell.chain.joint_names,
        urdf_joint_velocities(cell),
        acc,
        controller(fmt).joint_move,
        tool_path,
    )


def plan_cycle_time(
    plan: Plan, checks: Sequence[PointCheck], cell: Cell, fmt: str | None = None
) -> CycleTime | None:
    """The cycle time of the measuring program the controller ``fmt`` (``None``: the default)
    runs for ``plan``, with the poses of ``checks`` (the check of the plan's points, any order),
    in ``cell``; ``None`` when the controller has no program for the plan (its adaptive
    procedure refuses the layout: the check says why)."""
    try:
        program = measuring_program(plan, fmt)
    except InputError:
        return None
    by_id = {c.point_id: c for c in checks}
    q_safe = {p.id: None if (c := by_id.get(p.id)) is None else c.q_safe for p in plan.points}
    vias = {p.id: [v.q_rad for v in p.via_points] for p in plan.points}
    n = len(cell.chain.joint_names)
    for pid, qs in vias.items():  # a via of another robot: the check names it; not timed
        if any(len(q) != n for q in qs):
            q_safe[pid], vias[pid] = None, []
    speeds = {p.id: p.search.speed_m_s for p in plan.points}
    return cycle_time(
        program,
        q_safe,
        vias,
        speeds,
        cell_motion_limits(cell, plan, fmt),
        plan.validation.cycle_settings,
        measured_starts_wobj=measured_starts_wobj(plan),
        xoffset_q=_xoffset_q(program, plan, by_id, cell),
    )


def _xoffset_q(
    program: MeasuringProgram, plan: Plan, by_id: dict[str, PointCheck], cell: Cell
) -> list[FloatArray | None]:
    """Joint values at each start of the x-offset run (``[]`` without one): IK of the sensor
    at the start with D's checked orientation, the solution nearest D's pose (``None`` where
    there is none, or D has no pose)."""
    starts = xoffset_starts_wobj(program)
    if not starts:
        return []
    d = next((by_id.get(p.id) for p in plan.points if p.role == "D"), None)
    if d is None or d.q is None or d.T_base_tcp is None or d.pose_status == "infeasible":
        return [None] * len(starts)
    T = nominal_T_base_wobj(plan)
    R_wobj = (invert_transform(T) @ d.T_base_tcp)[:3, :3]
    T_tcp_flange = invert_transform(cell.T_flange_tcp(plan.cell.tool.tcp))
    poses = np.array([T @ make_transform(R_wobj, p) @ T_tcp_flange for _, p in starts])
    q, found = cell.solver.solve(poses).nearest(d.q)
    return [
        np.asarray(qk, dtype=np.float64) if ok else None for qk, ok in zip(q, found, strict=True)
    ]
