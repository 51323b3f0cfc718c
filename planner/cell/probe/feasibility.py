"""Probe-pose feasibility, batch-first: N surface points in, N answers (with reasons) out.

A probe pose puts the TCP (``sensor`` by default) on the surface point with its +z axis along
``-normal`` (into the surface); the rotation about that axis is free and searched every
``rotation_step_deg``. All ``N x R`` flange poses go to the IK solver in one call
(:mod:`planner.cell.probe.probe_candidates`); candidates (pose, branch) within limits and away from
wrist singularity are then collision-checked in order of least joint motion from ``q_ref``
(candidates near a joint limit last): the first that passes with margin is chosen, else the
least-bad one (:mod:`planner.cell.probe.probe_choice`). A feasible pose whose clearance slack or
joint-limit margin is small is ``"marginal"``. Infeasible poses say why: out of reach, a joint
at its limit, singular wrist, or the limiting collision pair and its clearance.

The clearance of a candidate is the exact Bullet query's; a broad phase
(:mod:`planner.cell.broad.broad_phase`) shows for whole batches which parts of it report nothing, so
Bullet sees only the rest (``staged=True``, the default). ``staged=False`` runs one whole query
per candidate: the plain reference, with the same answers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_positive, check_shape
from calib.errors import DegenerateGeometryError, ShapeError
from planner.cell.probe.probe_candidates import (
    MARGINAL_LIMIT_RAD,
    MIN_SINGULAR_VALUE,
    WRIST_SINGULAR_RAD,
    ProbeCandidates,
    limit_margin,
    probe_candidates,
    singular,
    tcp_frames,
)
from planner.cell.probe.probe_choice import ProbeSearch
from planner.cell.probe.probe_rule import CLEARANCE_TIE_M, Decision, select
from planner.cell.scene import DEFAULT_MARGIN_M, Clearance
from planner.reasons import Reason

if TYPE_CHECKING:
    from planner.cell.scene import CellScene
    from planner.robot.kinematics.chain import KinematicChain

FloatArray = NDArray[np.float64]
Status = Literal["feasible", "marginal", "infeasible"]

__all__ = [
    "CLEARANCE_TIE_M",
    "MARGINAL_LIMIT_RAD",
    "MIN_SINGULAR_VALUE",
    "WRIST_SINGULAR_RAD",
    "ProbeFeasibility",
    "check_probes",
    "feasibility_of",
    "limit_margin",
    "prepare_candidates",
    "singular",
    "tcp_frames",
]


@dataclass(frozen=True)
class ProbeFeasibility:
    """Feasibility of one probe pose.

    Attributes:
        feasible: True when a collision-free, within-limits, non-singular pose was found.
        status: ``"feasible"``, ``"marginal"`` (feasible with small clearance or joint-limit
            margin) or ``"infeasible"``.
        cause: ``None`` when ``status == "feasible"``; otherwise why, with its kind
            (:class:`planner.reasons.Reason`), e.g. ``"out of reach (2.87 m from the
            shoulder, reach 1.92 m)"`` (``reach``), ``"joint 5 at limit"`` (``joint_limit``),
            ``"singular wrist"`` (``singularity``), ``"link_4 hits table (clearance -3.0
            mm)"`` (``collision``, with its pair); a marginal pose's small clearance is a
            ``collision`` with its pair, its joint near a limit a ``joint_limit``.
        q: ``(n,)`` joint values of the chosen pose, rad; for an infeasible pose the least-bad
            candidate checked, ``None`` when there is no IK candidate at all.
        branch: IK branch of ``q`` (OPW configuration 0-7), -1 when unknown or none.
        rotation_rad: chosen rotation about the sensor axis, rad (NaN when none).
        clearance_m: clearance of the limiting pair at ``q``, m, capped at ``2 * margin_m + 5 mm``
            (nothing nearer); NaN when no pose was checked.
        joint_margin_rad: smallest distance of ``q`` to a joint limit, rad (NaN when none).
        T_base_flange: ``(4, 4)`` flange pose of ``q``, base frame, m (``None`` when none).
        clearance_pair: ``(robot or tool link, obstacle)`` that limits ``clearance_m``, or
            ``None`` when nothing came within the query's look-ahead (or no pose was checked).
    """

    feasible: bool
    status: Status
    cause: Reason | None
    q: FloatArray | None
    branch: int
    rotation_rad: float
    clearance_m: float
    joint_margin_rad: float
    T_base_flange: FloatArray | None
    clearance_pair: tuple[str, str] | None = None

    @property
    def reason(self) -> str:
        """The words of :attr:`cause` (``""`` when feasible)."""
        return "" if self.cause is None else str(self.cause)


def _near_limit_reason(chain: KinematicChain, q: FloatArray) -> Reason:
    """E.g. ``joint 3 near its upper limit (joint_3, 4.3 deg to go)`` for one ``q (n,)``."""
    to_lower, to_upper = q - chain.lower, chain.upper - q
    j = int(np.argmin(np.minimum(to_lower, to_upper)))
    side, left = ("lower", to_lower[j]) if to_lower[j] < to_upper[j] else ("upper", to_upper[j])
    return Reason(
        "joint_limit",
        f"joint {j + 1} near its {side} limit ({chain.joint_names[j]}, "
        f"{math.degrees(float(left)):.1f} deg to go)",
    )


def check_probes(
    cell: CellScene,
    points_wobj: ArrayLike,
    normals_wobj: ArrayLike,
    tcp: str = "sensor",
    rotation_step_deg: float = 15.0,
    margin_m: float | None = None,
    q_ref: ArrayLike | None = None,
    max_checks: int = 48,
    staged: bool = True,
) -> list[ProbeFeasibility]:
    """Feasibility of ``N`` probe poses (see the module docstring).

    Args:
        cell: the cell (its current ``T_base_wobj`` places the points).
        points_wobj: ``(N, 3)`` surface points, wobj frame, m.
        normals_wobj: ``(N, 3)`` outward unit normals, wobj frame (normalised here).
        tcp: the TCP put on the point (its +z looks into the surface).
        rotation_step_deg: step of the free rotation about the sensor axis, degrees.
        margin_m: clearance to work object and fixtures, m (default the cell's 5 mm).
        q_ref: ``(n,)`` reference configuration for "least joint motion" (default home).
        max_checks: largest number of candidates collision-checked per point (>= 1).
        staged: decide candidates with :class:`planner.cell.probe.probe_choice.ProbeSearch` (a
            broad phase for the whole batch, Bullet only for the parts it leaves open);
            ``False``: one whole clearance query per candidate, the exact check. Both give
            the same answers.

    Returns:
        One :class:`ProbeFeasibility` per point, in the order given. The cell's joint state is
        restored afterwards.

    Raises:
        ShapeError, NonFiniteError: bad shapes or NaN/inf in points or normals.
        DegenerateGeometryError: a zero normal.
        UnknownFrameError: unknown TCP (the message lists the valid names).
    """

    prep = prepare_candidates(
        cell, points_wobj, normals_wobj, tcp, rotation_step_deg, margin_m, q_ref, max_checks
    )
    if prep is None:
        return []
    cands, margin, max_checks = prep
    with cell.saved_state():
        decisions: list[Decision | None]
        if staged:
            # without statuses_only every answer is a Decision (or None)
            found = ProbeSearch(cell, margin, max_checks).run(cands)
            decisions = cast(list[Decision | None], found)
        else:
            decisions = _reference(cell, cands, margin, max_checks)
    return [
        feasibility_of(cell.chain, cands, i, d, margin) if d is not None else _none(why)
        for i, (d, why) in enumerate(zip(decisions, cands.reasons))
    ]


def prepare_candidates(
    cell: CellScene,
    points_wobj: ArrayLike,
    normals_wobj: ArrayLike,
    tcp: str,
    rotation_step_deg: float,
    margin_m: float | None,
    q_ref: ArrayLike | None,
    max_checks: int,
) -> tuple[ProbeCandidates, float, int] | None:
    """:func:`check_probes`'s arguments validated, and the points' candidates: ``(candidates,
    margin_m, max_checks)``, ``None`` for no points (raises as :func:`check_probes` does)."""
    pts = check_shape(points_wobj, (None, 3), "points_wobj")
    nrm = check_shape(normals_wobj, (None, 3), "normals_wobj")
    if nrm.shape != pts.shape:
        raise ShapeError(f"normals_wobj must be {pts.shape} like points_wobj, got {nrm.shape}")
    length = np.linalg.norm(nrm, axis=1)
    if np.any(length < 1e-9):
        raise DegenerateGeometryError(f"normals_wobj[{int(np.argmin(length))}] is zero")
    nrm = nrm / length[:, None]
    step = math.radians(check_positive(rotation_step_deg, "rotation_step_deg"))
    margin = DEFAULT_MARGIN_M if margin_m is None else check_positive(margin_m, "margin_m", True)
    T_flange_tcp = cell.T_flange_tcp(tcp)
    ref = cell.home_q if q_ref is None else check_shape(q_ref, (cell.chain.n_joints,), "q_ref")
    max_checks = int(max_checks)
    if max_checks < 1:
        raise ShapeError(f"max_checks must be >= 1, got {max_checks}")
    angles = np.arange(0.0, 2 * np.pi - 1e-9, step)
    if pts.shape[0] == 0:
        return None
    return probe_candidates(cell, pts, nrm, T_flange_tcp, angles, ref), margin, max_checks


def _reference(
    cell: CellScene, cands: ProbeCandidates, margin: float, max_checks: int
) -> list[Decision | None]:
    """One whole clearance query per candidate, in order (the plain reference)."""
    out: list[Decision | None] = []
    for i, why in enumerate(cands.reasons):
        if why is not None:
            out.append(None)
            continue

        def clearance(c: int, i: int = i) -> Clearance:
            cell.set_joint_positions(cands.q[i, c])
            return cell.clearance(margin, sensor_wobj_allowed=True)

        out.append(select(cands.order(i, max_checks), cands.near_limit[i], margin, clearance))
    return out


def feasibility_of(
    chain: KinematicChain, cands: ProbeCandidates, i: int, d: Decision, margin: float
) -> ProbeFeasibility:
    """The :class:`ProbeFeasibility` of point ``i``'s decision ``d``."""
    c, cl = d.candidate, d.clearance
    K = cands.per_rotation
    r = c // K
    joint_margin = float(cands.limit_margin[i, c])
    fine = cl.slack_m >= margin and joint_margin >= MARGINAL_LIMIT_RAD
    status: Status = "infeasible" if not d.chosen else "feasible" if fine else "marginal"
    cause: Reason | None
    if status == "feasible":
        cause = None
    elif status == "marginal":
        cause = (
            cl.reason("small clearance: ")
            if cl.slack_m < margin
            else _near_limit_reason(chain, cands.q[i, c])
        )
    else:
        cause = cl.reason()
    return ProbeFeasibility(
        feasible=d.chosen,
        status=status,
        cause=cause,
        q=cands.q[i, c].copy(),
        branch=int(cands.branch[i, c]),
        rotation_rad=float(cands.angles[r]),
        clearance_m=float(cl.clearance_m),
        joint_margin_rad=joint_margin,
        T_base_flange=cands.T_base_flange[i, r].copy(),
        clearance_pair=cl.pair,
    )


def _none(cause: Reason | None) -> ProbeFeasibility:
    nan = float("nan")
    return ProbeFeasibility(False, "infeasible", cause, None, -1, nan, nan, nan, None)
