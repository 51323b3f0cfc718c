"""Exact clearance of probe candidates, part by part, for the parts the broad phase left open.

:mod:`planner.cell.probe.probe_choice` decides probe points from the parts of the clearance query
(:meth:`planner.cell.scene.collision.CollisionChecker.plan`). The broad phase
(:mod:`planner.cell.broad.broad_phase`) shows most parts report nothing; :class:`ProbeClearance`
evaluates the others with Bullet, one part at a time, in the state the part needs:

- tool parts with the tool at the rotation's planned flange pose: a tool part depends only on
  the point and the rotation, so it is computed once per rotation and shared by every branch;
- robot parts with the robot at ``q``; cached by the joint values the link follows (revolute
  joints modulo ``2 pi``), so the ``2 pi`` variants of the wrist share them;
- the self part (the link pairs the broad phase left open) with the robot at ``q`` and the tool
  on PyBullet's flange, as in the whole query.

Merged in the plan's order (:meth:`planner.cell.scene.QueryPlan.merge`) with ``None`` for
the cleared parts, the results are exactly the whole query's, except that the tool stands at
the planned flange pose instead of PyBullet's single-precision forward kinematics of the branch
(they differ by ~1e-7 m). :meth:`ProbeClearance.evaluate_capped` gives a work-object part's
exact result from a cheap query when it is at or below a slack
(:meth:`~planner.cell.scene.collision.CollisionChecker.evaluate_capped`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from planner.cell.scene import Clearance, QueryPart, QueryPlan, set_link_pose

if TYPE_CHECKING:
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]
_TWO_PI = 2.0 * math.pi
#: One point's state in :class:`ProbeClearance`: ``(T_world_flange (R, 4, 4), tool part
#: results by (rotation, part), robot part results by joint key)``.
PointState = tuple[
    FloatArray, dict[tuple[int, int], Clearance | None], dict[tuple[float, ...], Clearance | None]
]


class ProbeClearance:
    """Exact part results of the candidates of probe points (one point at a time).

    Args:
        cell: the cell (its joint state changes; restore it with ``cell.saved_state()``).
        margin_m: required distance to the work object and fixtures, m.
    """

    def __init__(self, cell: CellScene, margin_m: float) -> None:
        self._cell = cell
        self.plan: QueryPlan = cell.checker.plan(margin_m, cell.self_margin_m, None, True, False)
        self.self_part = self.plan.parts[-1]
        chain = cell.chain
        self._revolute = np.array([t != "prismatic" for t in chain.joint_types])
        names = cell.chain.link_attach
        self._follows: dict[int, int] = {}  # robot part index -> joint the link follows
        for part in self.plan.parts:
            if part.kind == "robot":
                name = cell.robot.names[part.link]
                self._follows[part.index] = names[name][0] if name in names else chain.n_joints - 1
        self._T_world_flange = np.zeros((0, 4, 4))
        self._tool: dict[tuple[int, int], Clearance | None] = {}
        self._robot: dict[tuple[float, ...], Clearance | None] = {}
        self._tool_at: int | None = None
        self._q_at: FloatArray | None = None
        self._tool_on_flange = False
        #: parts evaluated in full, and capped queries made (for profiling and tests).
        self.parts_evaluated = 0
        self.parts_certified = 0

    @property
    def look_slack_m(self) -> float:
        """The slack of a candidate whose query finds nothing near, m."""
        return self.plan.look_m - self.plan.margin_m

    def start_point(self, T_base_flange: FloatArray) -> None:
        """Begin a new probe point whose rotations have flange poses ``(R, 4, 4)``, base frame."""
        self._T_world_flange = self._cell.T_world_base @ T_base_flange
        self._tool = {}
        self._robot = {}
        self._tool_at = None

    def point_state(self) -> PointState:
        """The current point's flange poses and cached part results, for :meth:`resume_point`
        (a search set aside while other points are decided)."""
        return (self._T_world_flange, self._tool, self._robot)

    def resume_point(self, state: PointState) -> None:
        """Continue a point set aside with :meth:`point_state`: its flange poses and cached
        results back (the simulator's state is whatever it is now: the tool is placed again
        before a tool part)."""
        self._T_world_flange, self._tool, self._robot = state
        self._tool_at = None

    def known(self, rotation: int, q: FloatArray, part: QueryPart) -> bool:
        """The part's result is cached (evaluating it costs nothing)."""
        if part.kind == "tool":
            return (rotation, part.index) in self._tool
        if part.kind == "robot":
            return self._robot_key(part, q) in self._robot
        return False

    def evaluate(
        self, rotation: int, q: FloatArray, part: QueryPart, pairs: NDArray[np.bool_] | None = None
    ) -> Clearance | None:
        """The exact result of ``part`` for candidate ``(rotation, q)`` (``pairs``: the self
        pairs to query, see :meth:`planner.cell.scene.collision.CollisionChecker.evaluate`)."""
        checker = self._cell.checker
        if part.kind == "tool":
            key = (rotation, part.index)
            if key not in self._tool:
                self._place_tool(rotation)
                self.parts_evaluated += 1
                self._tool[key] = checker.evaluate(part)
            return self._tool[key]
        if part.kind == "robot":
            rkey = self._robot_key(part, q)
            if rkey not in self._robot:
                self._set_q(q)
                self.parts_evaluated += 1
                self._robot[rkey] = checker.evaluate(part)
            return self._robot[rkey]
        self._set_q_and_tool(q)
        self.parts_evaluated += 1
        return checker.evaluate(part, pairs)

    def evaluate_capped(
        self, rotation: int, q: FloatArray, part: QueryPart, slack_m: float
    ) -> Clearance | None:
        """The exact result of a work-object ``part`` when its slack is at most ``slack_m`` (a
        cheap Bullet query that looks only that deep, kept as the part's result); ``None``
        when that is not shown (and for other parts)."""
        checker = self._cell.checker
        if part.env != checker.wobj_body or part.kind == "self":
            return None
        if part.kind == "tool":
            self._place_tool(rotation)
        else:
            self._set_q(q)
        self.parts_certified += 1
        res = checker.evaluate_capped(part, slack_m)
        if res is not None:
            if part.kind == "tool":
                self._tool[(rotation, part.index)] = res
            else:
                self._robot[self._robot_key(part, q)] = res
        return res

    def merge(self, results: dict[int, Clearance | None]) -> Clearance:
        """The query's answer from the results of some parts (the others report nothing)."""
        return self.plan.merge([results.get(p.index) for p in self.plan.parts])

    def _robot_key(self, part: QueryPart, q: FloatArray) -> tuple[float, ...]:
        k = self._follows[part.index] + 1
        qk = q[:k]
        wrapped = np.where(self._revolute[:k], np.mod(qk, _TWO_PI), qk)
        return (float(part.index), *np.round(wrapped, 9).tolist())

    def _set_q(self, q: FloatArray) -> None:
        """The robot at ``q`` (the tool wherever it was: robot parts do not see it)."""
        if self._q_at is None or not np.array_equal(self._q_at, q):
            cell = self._cell
            cell.robot_body.set_q(cell.client, q)
            self._q_at = q
            self._tool_on_flange = False

    def _set_q_and_tool(self, q: FloatArray) -> None:
        """The robot at ``q`` and the tool on PyBullet's flange, as the whole query has them
        (the self part: GJK between two links answers within ~1e-6 m of a pose ~1e-7 m
        away)."""
        if not self._tool_on_flange or self._q_at is None or not np.array_equal(self._q_at, q):
            self._cell.place_robot(q)  # q is a candidate's: checked
            self._q_at = q
            self._tool_on_flange = True
            self._tool_at = None

    def _place_tool(self, rotation: int) -> None:
        tool = self._cell.tool_body
        if tool is not None and self._tool_at != rotation:
            T_world_tool = self._T_world_flange[rotation] @ self._cell.T_flange_tool  # the mount
            set_link_pose(self._cell.client, tool, T_world_tool)
            self._tool_at = rotation
            self._tool_on_flange = False
