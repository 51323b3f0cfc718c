"""The search paths ``wobjcal check`` walks: the ones the exported program runs.

A program moves to a point's safe start and searches from there with the orientation and
configuration of the probe pose the check chose (``wobjcal export`` writes that pose's rotation
and ``confdata`` into every target of the point). So, for a point with a pose, the check walks
:func:`planner.export.searches.program_searches` (from the safe start; for an edge point the
approach to the face, then the edge search) with the pose's sensor x axis and IK branch only:
a path that would pass only with the sensor turned another way, or on another branch, is not
the program's path and does not count. A point without a usable pose is infeasible anyway; its
plan search is walked with any rotation, for the reason it gives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from calib.probing import ProbePoint, SearchCommand
from planner.export.safety import SafetySpec
from planner.export.searches import program_searches

if TYPE_CHECKING:
    from planner.cell.cell import Cell
    from planner.cell.feasibility import ProbeFeasibility

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ProgramPath:
    """The searches of one point as checked (see the module docstring).

    Attributes:
        feasible: every search passes.
        reason: why not, naming the search and the distance from its start (``""``).
        fail_at_m: distance of the first failing sample from the start of its search, m (NaN
            when feasible).
        q_path: ``(M, n)`` joint values of the samples that passed, all searches in order, rad
            (an edge point's face approach up to the nominal face, where the program stops).
        q_safe: ``(n,)`` joint values at the safe start (the program's first target of the
            point, where it leaves from too), rad; ``None`` when that start has no solution.
    """

    feasible: bool
    reason: str
    fail_at_m: float
    q_path: FloatArray
    q_safe: FloatArray | None


def check_program_path(
    cell: Cell,
    point: ProbePoint,
    pose: ProbeFeasibility,
    T_base_wobj: FloatArray,
    safety: SafetySpec,
    T_flange_tcp: FloatArray,
    tcp: str,
) -> ProgramPath:
    """Walk ``point``'s searches in ``cell`` (module docstring).

    Args:
        cell: the plan's open cell.
        point: the point (a plan's: ``PlanPoint.to_probe_point()``).
        pose: its probe pose from :meth:`planner.cell.cell.Cell.check_probes`.
        T_base_wobj: ``(4, 4)`` nominal work object, robot base frame, m.
        safety: the misplacement tolerance of the safe starts.
        T_flange_tcp: ``(4, 4)`` the probing TCP on the flange, m.
        tcp: the probing TCP's name.
    """
    n = cell.chain.n_joints
    if pose.q is None or pose.T_base_flange is None or pose.status == "infeasible":
        cmd = SearchCommand.from_point(point, T_base_wobj)
        res = cell.check_search(cmd, q_ref=pose.q, tcp=tcp)
        q_safe = res.q_path[0].copy() if len(res.q_path) else None
        return ProgramPath(res.feasible, res.reason, res.fail_at_m, res.q_path, q_safe)
    sensor_x = (np.asarray(pose.T_base_flange) @ T_flange_tcp)[:3, 0]
    q_ref = np.asarray(pose.q, dtype=float)
    parts: list[FloatArray] = []
    searches = program_searches(point, T_base_wobj, safety)
    for k, cmd in enumerate(searches):
        res = cell.check_search(
            cmd, q_ref=q_ref, tcp=tcp, sensor_x=sensor_x, branch=int(pose.branch), max_starts=1
        )
        parts.append(res.q_path)
        if not res.feasible:
            what = "approach to the face" if len(searches) == 2 and k == 0 else "search"
            reason = f"{what} from the safe start {res.reason}" if k == 0 else res.reason
            q_path = np.concatenate(parts) if parts else np.zeros((0, n))
            q_safe = q_path[0].copy() if len(q_path) else None
            return ProgramPath(False, reason, res.fail_at_m, q_path, q_safe)
        if k == 0 and len(searches) == 2:  # the face approach stops at the face (nominally)
            at_face = float((cmd.nominal_m - cmd.start_m) @ cmd.direction)
            parts[-1] = res.q_path[res.s_m <= at_face + 1e-9]
        q_ref = parts[-1][-1] if len(parts[-1]) else res.q_path[-1]
    q_path = np.concatenate(parts)
    return ProgramPath(True, "", math.nan, q_path, q_path[0].copy())
