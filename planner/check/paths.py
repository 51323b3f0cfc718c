"""The search paths ``wobjcal check`` walks: the ones the exported program runs.

A program moves to a point's safe start and searches from there with the orientation and
configuration of the probe pose the check chose (``wobjcal export`` writes that pose's rotation and
``confdata`` into every target of the point). So, for a point with a pose, the check walks
:func:`planner.program.searches.program_searches` (from the safe start; for an edge point the
approach to the face, the edge search and the straight retreat to the safe start) with the pose's
sensor x axis and IK branch only: a path that would pass only with the sensor turned another way, or
on another branch, is not the program's path and does not count. A point without a usable pose is
infeasible anyway; its plan search is walked with any rotation, for the reason it gives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.plan.file import Plan
from calib.probing import ProbePoint, SearchCommand
from planner.program.safety import SafetySpec
from planner.program.searches import ProgramSearch, program_searches
from planner.reasons import Reason

if TYPE_CHECKING:
    from planner.cell.cell import Cell
    from planner.cell.probe import ProbeFeasibility

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ProgramPath:
    """The searches of one point as checked (see the module docstring).

    Attributes:
        feasible: every search passes.
        cause: why not, naming the search and the distance from its start, with the kind of
            :class:`planner.cell.probe.PathFeasibility`'s (``None`` when feasible).
        fail_at_m: distance of the first failing sample from the start of its search, m (NaN
            when feasible).
        q_path: ``(M, n)`` joint values of the samples that passed, all searches in order, rad
            (an edge point's face approach up to the nominal face, where the program stops).
        q_safe: ``(n,)`` joint values at the safe start (the program's first target of the
            point, where it leaves from too), rad; ``None`` when that start has no solution.
    """

    feasible: bool
    cause: Reason | None
    fail_at_m: float
    q_path: FloatArray
    q_safe: FloatArray | None

    @property
    def reason(self) -> str:
        """The words of :attr:`cause` (``""`` when feasible)."""
        return "" if self.cause is None else str(self.cause)


def check_program_path(
    cell: Cell,
    point: ProbePoint,
    pose: ProbeFeasibility,
    T_base_wobj: FloatArray,
    safety: SafetySpec,
    T_flange_tcp: FloatArray,
    tcp: str,
    measured_start_wobj: ArrayLike | None = None,
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
        measured_start_wobj: for an edge point the adaptive RAPID program starts at an already
            measured point (``edge_start_from_measured``): that start, wobj frame, m. Both
            programs are walked (the other formats approach the face); the path returned is
            the face approach's, a failure of either is the point's.
    """
    if pose.q is None or pose.T_base_flange is None or pose.status == "infeasible":
        cmd = SearchCommand.from_point(point, T_base_wobj)
        res = cell.check_search(cmd, q_ref=pose.q, tcp=tcp)
        return ProgramPath(res.feasible, res.cause, res.fail_at_m, res.q_path, None)
    sensor_x = (np.asarray(pose.T_base_flange) @ T_flange_tcp)[:3, 0]
    path = _walk(cell, pose, sensor_x, tcp, program_searches(point, T_base_wobj, safety))
    if path.feasible and measured_start_wobj is not None:
        measured = program_searches(point, T_base_wobj, safety, measured_start_wobj)
        other = _walk(cell, pose, sensor_x, tcp, measured)
        if not other.feasible:
            why = _named(
                other.cause, "adaptive RAPID program (edge search from the measured point):"
            )
            return ProgramPath(False, why, other.fail_at_m, path.q_path, path.q_safe)
    return path


def _walk(
    cell: Cell, pose: ProbeFeasibility, sensor_x: FloatArray, tcp: str,
    searches: tuple[ProgramSearch, ...],
) -> ProgramPath:  # fmt: skip
    """Walk ``searches`` in order with ``pose``'s sensor x axis and branch, each from where
    the previous one ended (nominally)."""
    q_ref = np.asarray(pose.q, dtype=float)
    parts: list[FloatArray] = []
    for k, (name, cmd) in enumerate(searches):
        res = cell.check_search(
            cmd, q_ref=q_ref, tcp=tcp, sensor_x=sensor_x, branch=int(pose.branch), max_starts=1
        )
        parts.append(res.q_path)
        if not res.feasible:
            q_path = np.concatenate(parts)
            q_safe = q_path[0].copy() if len(q_path) else None
            return ProgramPath(False, _named(res.cause, name), res.fail_at_m, q_path, q_safe)
        if k < len(searches) - 1:  # an approach stops at its nominal point
            at = float((cmd.nominal_m - cmd.start_m) @ cmd.direction)
            parts[-1] = res.q_path[res.s_m <= at + 1e-9]
        q_ref = parts[-1][-1] if len(parts[-1]) else res.q_path[-1]
    q_path = np.concatenate(parts)
    return ProgramPath(True, None, math.nan, q_path, q_path[0].copy())


def measured_starts_wobj(plan: Plan) -> dict[str, FloatArray]:
    """``{point id: start}`` of the edge searches the adaptive RAPID program starts at an
    already measured point (``edge_start_from_measured``: F at E, H at G, plus
    ``edge_start_offset_m`` along the edge point's normal), wobj frame, m; ``{}`` when the
    plan's program is not adaptive or does not."""
    from calib.errors import InputError
    from planner.program.build import adaptive_spec

    try:
        a = adaptive_spec(plan)
    except InputError:  # a layout the adaptive program refuses: it is not exported adaptive
        return {}
    if a is None or not a.settings.edge_start_from_measured:
        return {}
    out = {}
    for edge, source in (("F", "E"), ("H", "G")):
        p, q = plan.points[a.index[edge]], plan.points[a.index[source]]
        n = np.asarray(p.normal, dtype=float)
        out[p.id] = np.asarray(q.position_m, dtype=float) + a.settings.edge_start_offset_m * n
    return out


def _named(cause: Reason | None, search: str) -> Reason | None:
    """``cause`` after the name of the search it is about."""
    return None if cause is None else cause.worded(f"{search} ")
