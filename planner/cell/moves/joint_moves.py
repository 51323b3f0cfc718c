"""Joint moves in the cell: limits and collisions along a move, linear in joint space.

The one move check. The Teach tab draws the moves between points with it
(:meth:`webui.backend.CellSession.check_move`), and ``wobjcal check`` checks the moves through a
point's via points with it (:func:`check_via_path`, called by :func:`planner.check.job.check_plan`).
A joint move (RAPID ``MoveAbsJ``/``MoveJ``, KRL ``PTP``, URScript ``movej``, FANUC ``J``) is
linear in joint space on every controller when all axes are synchronised, so the poses checked
here are those the robot passes (up to the controller's blending, which the exported programs
switch off: every via is a fine point).

The move is sampled with at most :data:`MAX_STEP_RAD` between poses (and never fewer than
``min_steps`` poses); each pose's clearance is the cell's full query (robot, tool, work object,
fixtures, self-collision with the ACL; the parts the broad phase clears are not asked of Bullet:
:func:`planner.cell.broad.first_failure`, the same first failing pose and reason), so a thin
obstacle between two samples can be missed: the sampling is the joint step, not a swept volume.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planner.cell.broad import first_failure
from planner.cell.scene import DEFAULT_MARGIN_M
from planner.reasons import Reason

if TYPE_CHECKING:
    from planner.cell.scene import CellScene
    from planner.robot.kinematics.chain import KinematicChain

FloatArray = NDArray[np.float64]

#: Largest joint step between two checked poses of a move, rad (2 degrees).
MAX_STEP_RAD = math.radians(2.0)


@dataclass(frozen=True)
class MoveCheck:
    """A joint move between two poses.

    Attributes:
        tcp_path_world: ``(steps, 3)`` the TCP along the move, world frame, m.
        cause: where and what collides first, a ``move`` reason with the colliding pair
            (``None``: the move is clear).
    """

    tcp_path_world: FloatArray
    cause: Reason | None = None

    @property
    def problem(self) -> str:
        """The words of :attr:`cause` (``""``: the move is clear)."""
        return "" if self.cause is None else str(self.cause)

    @property
    def pair(self) -> tuple[str, str] | None:
        """``(moving link, other)`` of the first collision, or ``None``."""
        return None if self.cause is None else self.cause.pair


def joint_limit_problem(chain: KinematicChain, q: ArrayLike) -> str:
    """Why ``q`` (rad) is not a configuration of ``chain``: a wrong count, a value that is not
    finite, or joints outside their limits (named, in degrees); ``""`` when it is."""
    qa = np.asarray(q, dtype=np.float64).reshape(-1)
    n = chain.n_joints
    if len(qa) != n:
        return f"{len(qa)} joint values, the robot has {n} joints ({', '.join(chain.joint_names)})"
    if not np.all(np.isfinite(qa)):
        return "joint values must be finite"
    bad = []
    for i, name in enumerate(chain.joint_names):
        lo, hi = float(chain.lower[i]), float(chain.upper[i])
        if not lo - 1e-9 <= qa[i] <= hi + 1e-9:
            bad.append(
                f"J{i + 1} ({name}) {math.degrees(qa[i]):.2f} deg outside "
                f"[{math.degrees(lo):.2f}, {math.degrees(hi):.2f}]"
            )
    return "; ".join(bad)


def move_steps(q_from: ArrayLike, q_to: ArrayLike, min_steps: int = 20) -> int:
    """How many poses sample the move: ``MAX_STEP_RAD`` apart at most, at least ``min_steps``."""
    d = np.abs(np.asarray(q_to, dtype=np.float64) - np.asarray(q_from, dtype=np.float64))
    return max(min_steps, math.ceil(float(d.max(initial=0.0)) / MAX_STEP_RAD) + 1)


def check_joint_move(
    cell: CellScene, q_from: ArrayLike, q_to: ArrayLike, tcp: str, min_steps: int = 20
) -> MoveCheck:
    """Check the joint move from ``q_from`` to ``q_to`` (rad, linear in joint space) in ``cell``:
    the TCP's path (world) and the first pose that collides, if any (the cell's state is kept).

    Both ends must be within the joint limits (:func:`joint_limit_problem`); the poses between
    are then too.
    """
    a = np.asarray(q_from, dtype=np.float64).reshape(-1)
    b = np.asarray(q_to, dtype=np.float64).reshape(-1)
    steps = move_steps(a, b, min_steps)
    qs = a + np.linspace(0.0, 1.0, steps)[:, None] * (b - a)
    T_base_flange = np.asarray(cell.chain.fk(qs))
    T = cell.T_world_base @ T_base_flange @ cell.T_flange_tcp(tcp)
    with cell.saved_state():  # each pose's whole query, as a loop would ask, broad phase first
        k, c = first_failure(cell, qs, T_base_flange, np.zeros(steps, dtype=bool), DEFAULT_MARGIN_M)
    if c is not None:
        where = c.reason(f"at {100 * k // (steps - 1)} %: ", kind="move")
        return MoveCheck(T[:, :3, 3].copy(), where)
    return MoveCheck(T[:, :3, 3].copy())


@dataclass(frozen=True)
class ViaPath:
    """The moves of one point's via path: previous pose, vias in order, the point's pose
    (``wobjcal check`` and the Teach tab pass the points' safe starts).

    Attributes:
        legs: ``(from, to, check)`` per move checked, named ``"start"``, ``"via 1"``, ...,
            ``"point"`` (a leg is missing when an end is not known).
        cause: the first problem, a ``move`` reason: a via outside the joint limits or a
            colliding leg, naming the via and the clearance pair (its ``pair``); ``None``: the
            path is clear.
    """

    legs: tuple[tuple[str, str, MoveCheck], ...]
    cause: Reason | None = None

    @property
    def problem(self) -> str:
        """The words of :attr:`cause` (``""``: the path is clear)."""
        return "" if self.cause is None else str(self.cause)


def check_via_path(
    cell: CellScene,
    q_prev: ArrayLike | None,
    vias_q: Sequence[ArrayLike],
    q_point: ArrayLike | None,
    tcp: str,
    prev_name: str = "previous point",
    point_name: str = "point",
) -> ViaPath:
    """Check the moves from ``q_prev`` through ``vias_q`` to ``q_point`` (rad).

    Args:
        cell: the plan's open cell.
        q_prev: joint values where the robot leaves the previous point (its safe start), or
            ``None`` (the first point, or a previous point without a pose): the path starts
            at the first via.
        vias_q: the vias' joint values, in order.
        q_point: joint values where the robot arrives at this point (its safe start), or
            ``None`` (no pose found): the path ends at the last via.
        tcp: the probing TCP (for the drawn path).
        prev_name: what the messages call the previous pose (e.g. the point's id).
        point_name: what they call this point's pose.
    """
    chain = cell.chain
    sliding = [
        n for n, t in zip(chain.joint_names, chain.joint_types, strict=True) if t == "prismatic"
    ]
    if vias_q and sliding:  # the programs write via joint targets in degrees (rad: URScript)
        why = f"vias need a robot of rotary joints; {sliding[0]} is prismatic"
        return ViaPath((), Reason("move", why))
    for k, q in enumerate(vias_q, start=1):
        why = joint_limit_problem(cell.chain, q)
        if why:
            return ViaPath((), Reason("move", f"via {k}: {why}"))
    names = [f"via {k}" for k in range(1, len(vias_q) + 1)]
    stops: list[tuple[str, FloatArray]] = [
        (n, np.asarray(q, dtype=np.float64)) for n, q in zip(names, vias_q, strict=True)
    ]
    if q_prev is not None:
        stops.insert(0, (prev_name, np.asarray(q_prev, dtype=np.float64)))
    if q_point is not None:
        stops.append((point_name, np.asarray(q_point, dtype=np.float64)))
    legs = []
    for (na, qa), (nb, qb) in itertools.pairwise(stops):
        move = check_joint_move(cell, qa, qb, tcp)
        legs.append((na, nb, move))
        if move.cause is not None:
            return ViaPath(tuple(legs), move.cause.worded(f"move {na} -> {nb} "))
    return ViaPath(tuple(legs))
