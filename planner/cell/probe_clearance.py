"""Clearance of probe candidates, staged: tool once per rotation, stop once a candidate is out.

:func:`planner.cell.feasibility.check_probes` checks a point's candidates (rotation about the sensor
axis, IK branch) in a fixed order and keeps the first that passes, else the least-bad one. A
candidate whose slack is shown to be at or below a bound the caller gives (it can neither pass
nor beat the least-bad one so far) changes nothing, so its query stops there.
:class:`ProbeClearance` works part by part (:meth:`planner.cell.collision.CollisionChecker.plan`),
in stages:

1. the tool links against the work object and fixtures, placed at the rotation's flange pose
   (it does not depend on the IK branch): computed once per rotation and shared by every
   branch, so a rotation whose tool collides too deeply drops out for all branches at once;
2. the moving robot links against the environment;
3. the self-collision part.

A first pass tries to settle the candidate cheaply: cached tool results, then certificates
(:meth:`planner.cell.collision.CollisionChecker.certify_below`: a ``getClosestPoints`` that looks
only as deep as the bound). Within a stage the parts that settle candidates for the least work
(contact points computed, a deterministic measure) go first, learned over the batch. A
candidate that is not settled gets every part in full, merged in the canonical order: exactly
the whole query's answer, except that the tool stands at the planned flange pose instead of
PyBullet's single-precision forward kinematics of the branch (they differ by ~1e-7 m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from planner.cell.bodies import set_link_pose
from planner.cell.collision import Clearance, QueryPart
from planner.cell.pybullet_client import pb

if TYPE_CHECKING:
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]


@dataclass
class _PartStats:
    """How often a part settled a candidate, and the work it took (contact points + 1)."""

    tries: int = 0
    hits: int = 0
    work: int = 0

    def expected_work_per_hit(self) -> float:
        p = (self.hits + 1) / (self.tries + 2)
        return (self.work + 1) / (self.tries + 1) / p


class ProbeClearance:
    """Staged clearance queries of the candidates of a batch of probe points.

    Args:
        cell: the cell (its joint state changes; restore it with ``cell.saved_state()``).
        margin_m: required distance to the work object and fixtures, m.
    """

    def __init__(self, cell: CellScene, margin_m: float) -> None:
        self._cell = cell
        self._plan = cell.checker.plan(margin_m, cell.self_margin_m, None, True, False)
        parts = self._plan.parts
        self._stages = (
            [p for p in parts if p.kind == "tool"],
            [p for p in parts if p.kind == "robot"],
            [p for p in parts if p.kind == "self"],
        )
        self._stats = {p.index: _PartStats() for p in parts}
        self._T_world_flange = np.zeros((0, 4, 4))
        self._tool_results: dict[int, dict[int, Clearance | None]] = {}
        self._tool_below: dict[int, float] = {}  # rotation -> its tool surely has slack <= this
        # robot parts by (part, link pose): exact results, and bounds shown by certificates
        self._robot_results: dict[tuple[float, ...], Clearance | None] = {}
        self._robot_below: dict[tuple[float, ...], float] = {}
        self._tool_at: int | None = None
        self._q_at: FloatArray | None = None
        self._link_pose: dict[int, tuple[float, ...]] = {}  # robot link -> rounded pose at q
        #: parts evaluated in full, and certificate queries made (for profiling and tests).
        self.parts_evaluated = 0
        self.parts_certified = 0

    def start_point(self, T_base_flange: FloatArray) -> None:
        """Begin a new probe point whose rotations have flange poses ``(R, 4, 4)``, base frame."""
        self._T_world_flange = self._cell.T_world_base @ T_base_flange
        self._tool_results = {}
        self._tool_below = {}
        self._robot_results = {}
        self._robot_below = {}
        self._tool_at = None
        for stage in self._stages[:2]:
            stage.sort(key=lambda p: self._stats[p.index].expected_work_per_hit())

    def check(self, rotation: int, q: FloatArray, settled_at: float) -> Clearance | None:
        """Clearance of candidate ``(rotation, q)``, or ``None`` once its slack is shown to be
        ``<= settled_at`` (the caller's proof that such a candidate changes nothing).

        Args:
            rotation: index into the point's flange poses.
            q: ``(n,)`` joint values of the candidate, rad (their flange pose is the rotation's).
            settled_at: slack at or below which the candidate is of no further interest, m
                (``-inf``: always compute the full clearance).
        """
        running = self._plan.look_m - self._plan.margin_m  # the slack when nothing is near
        if running <= settled_at:
            return None
        cache = self._tool_results.setdefault(rotation, {})
        if settled_at > -math.inf and self._certified(rotation, q, cache, settled_at):
            return None
        results: dict[int, Clearance | None] = {}
        for stage in self._stages:
            if stage is not self._stages[0]:
                self._set_q(q)
            for part in stage:
                if part.kind == "tool":
                    if part.index not in cache:
                        self._place_tool(rotation)
                        cache[part.index] = self._evaluate(part)
                    res = cache[part.index]
                elif part.kind == "robot":
                    key = self._pose_key(part)
                    if key not in self._robot_results:
                        self._robot_results[key] = self._evaluate(part)
                    res = self._robot_results[key]
                else:
                    res = self._evaluate(part)
                results[part.index] = res
                if res is not None and res.slack_m < running:
                    running = res.slack_m
                if running <= settled_at:
                    return None
        return self._plan.merge([results[p.index] for p in self._plan.parts])

    def _certified(
        self,
        rotation: int,
        q: FloatArray,
        cache: dict[int, Clearance | None],
        settled_at: float,
    ) -> bool:
        """First pass: settle the candidate by cached tool results or by certificates."""
        checker = self._cell.checker
        tools, robot, _ = self._stages
        if self._tool_below.get(rotation, math.inf) <= settled_at:
            return True  # a tool certificate of this rotation, from an earlier branch
        for part in tools:  # cached results cost nothing: all of them first
            res = cache.get(part.index)
            if res is not None and res.slack_m <= settled_at:
                return True
        for stage in (tools, robot):
            for part in stage:
                if part.kind == "tool":
                    if part.index in cache:
                        continue
                    self._place_tool(rotation)
                else:
                    self._set_q(q)
                    key = self._pose_key(part)
                    known = self._robot_results.get(key, False)
                    if known is not False:  # evaluated in full at this very link pose
                        if isinstance(known, Clearance) and known.slack_m <= settled_at:
                            return True
                        continue
                    if self._robot_below.get(key, math.inf) <= settled_at:
                        return True
                self.parts_certified += 1
                hit = checker.certify_below(part, settled_at)
                st = self._stats[part.index]
                st.tries, st.hits = st.tries + 1, st.hits + hit
                st.work += checker.last_points + 1
                if hit:
                    if part.kind == "tool":
                        self._tool_below[rotation] = settled_at
                    else:
                        self._robot_below[key] = settled_at
                    return True
        return False

    def _pose_key(self, part: QueryPart) -> tuple[float, ...]:
        """The part's link pose in the current state, rounded to 1e-9 (m, quaternion with
        w >= 0): the ``2 pi`` variants of the wrist joints share it for the links before."""
        pose = self._link_pose.get(part.link)
        if pose is None:
            state = pb.getLinkState(
                part.body,
                part.link,
                computeForwardKinematics=True,
                physicsClientId=self._cell.client,
            )
            quat = state[5] if state[5][3] >= 0.0 else [-v for v in state[5]]
            pose = self._link_pose[part.link] = tuple(round(v, 9) for v in (*state[4], *quat))
        return (part.index, *pose)

    def _evaluate(self, part: QueryPart) -> Clearance | None:
        self.parts_evaluated += 1
        return self._cell.checker.evaluate(part)

    def _set_q(self, q: FloatArray) -> None:
        if self._q_at is None or not np.array_equal(self._q_at, q):
            self._cell.set_joint_positions(q)
            self._q_at = q
            self._link_pose = {}
            self._tool_at = None  # the tool now sits on PyBullet's flange

    def _place_tool(self, rotation: int) -> None:
        tool = self._cell.tool_body
        if tool is not None and self._tool_at != rotation:
            set_link_pose(self._cell.client, tool, self._T_world_flange[rotation])
            self._tool_at = rotation
            self._q_at = None  # the tool no longer sits on the flange of q
