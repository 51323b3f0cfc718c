"""Collision checking of the cell: the clearance query with its allowed-collision list.

The clearance query (:meth:`CollisionChecker.query`) checks the current PyBullet state: robot
and tool against the work object, the fixtures and themselves, and returns the limiting pair and
its distance. It is made of parts (:meth:`CollisionChecker.plan`): each moving robot link and
each tool link against each environment body (one ``getClosestPoints`` call, skipped when the
axis-aligned boxes lie farther apart than the part looks; the sensor links look less far at the
work object), and one self-collision part: robot-robot and robot-tool pairs one by one (a
whole-body self query also computes every allowed, touching neighbour pair), skipped first by
the allowed-collision list (:mod:`planner.cell.scene.acl`, re-exported here) and by their boxes. The
parts can be evaluated one at a time in any order and merged (:meth:`QueryPlan.merge`) into exactly
the answer of the whole query: :mod:`planner.cell.probe.probe_clearance` uses this to stop early.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from planner.cell.scene.acl import (
    ACL_VERSION,
    ALWAYS_FRACTION,
    AllowedCollisions,
    Pair,
    acl_key,
    cache_dir,
    compute_acl,
    pair,
)
from planner.cell.scene.bodies import BodyLinks
from planner.cell.scene.clearance import Clearance, QueryPart, QueryPlan
from planner.cell.scene.pybullet_client import pb

log = logging.getLogger(__name__)

__all__ = [
    "ACL_VERSION",
    "ALWAYS_FRACTION",
    "AllowedCollisions",
    "Clearance",
    "CollisionChecker",
    "Pair",
    "QueryPart",
    "QueryPlan",
    "acl_key",
    "cache_dir",
    "compute_acl",
    "pair",
]


#: Default clearance of robot and tool to the work object and fixtures, m.
DEFAULT_MARGIN_M = 0.005
#: Default clearance between robot/tool links that the ACL does not allow, m.
DEFAULT_SELF_MARGIN_M = 0.002
#: A self part with at most this many pairs to query tests their boxes in plain Python.
FEW_SELF_PAIRS = 8


def report_distance_m(margin_m: float) -> float:
    """How far clearance queries look, metres: ``2 * margin_m + 5 mm``.

    Clearances are exact below it; a clearance equal to it means "at least this much" (nothing
    nearer was found), which reports should show as ``>= ...``.
    """
    return 2.0 * margin_m + 0.005


@dataclass
class CollisionChecker:
    """The fast clearance query of a cell (built by :class:`planner.cell.cell.Cell`).

    Attributes:
        client: PyBullet client id.
        robot: robot body; ``tool``: tool body or ``None``.
        names: ``(body_id, link) -> name``.
        static_links: robot link indices that no joint moves (checked once against fixtures).
        acl: the allowed-collision list.
        sensor_links: tool link indices allowed down to contact with the work object.
        environment: ``{body_id: name}`` of the work object and fixtures.
        wobj_body: body id of the work object, or ``None``.
        allowed_static: ``(robot link, body id)`` static contacts accepted at setup.
    """

    client: int
    robot: BodyLinks
    tool: BodyLinks | None
    names: Callable[[int, int], str]
    static_links: frozenset[int]
    acl: AllowedCollisions
    sensor_links: frozenset[int] = frozenset()
    environment: dict[int, str] = field(default_factory=dict)
    wobj_body: int | None = None
    _pairs: list[tuple[int, int]] | None = field(default=None, repr=False)
    _solid_tool: list[int] | None = field(default=None, repr=False)
    _solid_robot: list[int] | None = field(default=None, repr=False)
    _tool_pairs: list[tuple[int, int]] | None = field(default=None, repr=False)
    _table: tuple[list[int], list[int], np.ndarray, np.ndarray] | None = field(
        default=None, repr=False
    )
    #: contact points the last part query returned (a deterministic measure of its work).
    last_points: int = field(default=0, repr=False)

    def log_static_contacts(self, body: int) -> list[str]:
        """Robot links no joint moves that touch ``body`` (logged; never checked, as a robot
        standing on a table touches it in every pose)."""
        touching = [
            self.names(self.robot.body_id, i)
            for i in sorted(self.static_links)
            if pb.getClosestPoints(
                self.robot.body_id, body, 0.0, linkIndexA=i, physicsClientId=self.client
            )
        ]
        for name in touching:
            log.info(
                "robot %s touches %s: static contact, not checked", name, self.environment[body]
            )
        return touching

    def _tool_links(self) -> list[int]:
        """Tool links that have collision shapes (computed once)."""
        if self._solid_tool is None:
            t = self.tool
            self._solid_tool = (
                []
                if t is None
                else [
                    i
                    for i in t.names
                    if pb.getCollisionShapeData(t.body_id, i, physicsClientId=self.client)
                ]
            )
        return self._solid_tool

    def _self_pair_table(self) -> tuple[list[int], list[int], np.ndarray, np.ndarray]:
        """Bodies and link indices of every solid robot and tool link, and index arrays of
        the pairs to check among them (robot-robot and robot-tool; computed once)."""
        if self._table is None:
            rid = self.robot.body_id
            entries = [(rid, i) for i in self._robot_links()]
            if self.tool is not None:
                entries += [(self.tool.body_id, i) for i in self._tool_links()]
            pos = {e: n for n, e in enumerate(entries)}
            pairs = [(pos[(rid, a)], pos[(rid, b)]) for a, b in self._robot_pairs()]
            if self.tool is not None:
                tid = self.tool.body_id
                pairs += [(pos[(rid, a)], pos[(tid, b)]) for a, b in self._robot_tool_pairs()]
            idx = np.array(pairs, dtype=int).reshape(-1, 2)
            self._table = ([e[0] for e in entries], [e[1] for e in entries], idx[:, 0], idx[:, 1])
        return self._table

    def _robot_links(self) -> list[int]:
        """Robot links that have collision shapes (computed once)."""
        if self._solid_robot is None:
            rid = self.robot.body_id
            self._solid_robot = [
                i
                for i in self.robot.names
                if pb.getCollisionShapeData(rid, i, physicsClientId=self.client)
            ]
        return self._solid_robot

    def _robot_tool_pairs(self) -> list[tuple[int, int]]:
        """(robot link, tool link) pairs with shapes on both sides and not in the ACL."""
        if self._tool_pairs is None:
            rid = self.robot.body_id
            tid = self.tool.body_id if self.tool is not None else -1
            self._tool_pairs = [
                (a, b)
                for a in self._robot_links()
                for b in self._tool_links()
                if pair(self.names(rid, a), self.names(tid, b)) not in self.acl.allowed
            ]
        return self._tool_pairs

    def _robot_pairs(self) -> list[tuple[int, int]]:
        """Robot link pairs to check: both have collision shapes, not both static, not in
        the ACL (computed once)."""
        if self._pairs is None:
            rid, solid = self.robot.body_id, self._robot_links()
            self._pairs = [
                (a, b)
                for k, a in enumerate(solid)
                for b in solid[k + 1 :]
                if not (a in self.static_links and b in self.static_links)
                and pair(self.names(rid, a), self.names(rid, b)) not in self.acl.allowed
            ]
        return self._pairs

    def plan(
        self,
        margin_m: float,
        self_margin_m: float,
        report_m: float | None = None,
        sensor_wobj_allowed: bool = True,
        skip_wobj: bool = False,
    ) -> QueryPlan:
        """The parts of a clearance query in their canonical order (arguments as :meth:`query`).

        Per environment body: each moving robot link, then each tool link; then the
        self-collision part. Static robot links are left out (they were never reported).
        """
        look = report_m if report_m is not None else report_distance_m(margin_m)
        look = max(look, margin_m, self_margin_m) + 1e-9
        moving = [i for i in self._robot_links() if i not in self.static_links]
        parts: list[QueryPart] = []
        for env, env_name in self.environment.items():
            if skip_wobj and env == self.wobj_body:
                continue
            for link in moving:
                parts.append(
                    QueryPart(
                        len(parts), "robot", self.robot.body_id, link, env, env_name, look, margin_m
                    )
                )
            if self.tool is None:
                continue
            for link in self._tool_links():
                sensor = sensor_wobj_allowed and env == self.wobj_body and link in self.sensor_links
                dist, need = (margin_m, 0.0) if sensor else (look, margin_m)
                parts.append(
                    QueryPart(
                        len(parts), "tool", self.tool.body_id, link, env, env_name, dist, need
                    )
                )
        self_look = max(self_margin_m, look)
        parts.append(QueryPart(len(parts), "self", -1, -1, -1, "", self_look, self_margin_m))
        return QueryPlan(tuple(parts), look, margin_m)

    def evaluate(self, part: QueryPart, pairs: np.ndarray | None = None) -> Clearance | None:
        """The limiting point of one part in the current state (``None``: nothing within its
        distance). Link pairs whose axis-aligned boxes lie farther apart are not queried.

        ``pairs``: for the self part, a mask over :meth:`_self_pair_table`'s pairs to query
        (the others are known to report nothing); default all."""
        self.last_points = 0
        if part.kind == "self":
            return self._self_part(part, pairs)
        c = self.client
        lo, hi = pb.getAABB(part.body, part.link, physicsClientId=c)
        elo, ehi = pb.getAABB(part.env, -1, physicsClientId=c)  # cheap; bodies get replaced
        d = part.dist_m
        if any(lo[k] > ehi[k] + d or elo[k] > hi[k] + d for k in range(3)):
            return None
        best: Clearance | None = None
        points = pb.getClosestPoints(
            part.body, part.env, d, linkIndexA=part.link, physicsClientId=c
        )
        self.last_points = len(points)
        for pt in points:
            slack = pt[8] - part.need_m
            if best is None or slack < best.slack_m:
                best = Clearance(pt[8] >= part.need_m, pt[8], slack, None)
        if best is None:
            return None
        pair_ = (self.names(part.body, part.link), part.env_name)
        return Clearance(best.ok, best.clearance_m, best.slack_m, pair_)

    def certify_below(self, part: QueryPart, slack_m: float) -> bool:
        """True when part ``part`` surely has a point with slack ``<= slack_m`` in the current
        state; False when that is not shown (then evaluate it in full). See
        :meth:`evaluate_capped`."""
        return self.evaluate_capped(part, slack_m) is not None

    def evaluate_capped(self, part: QueryPart, slack_m: float) -> Clearance | None:
        """The part's exact result (:meth:`evaluate`'s, bit for bit) when its slack is at most
        ``slack_m``; ``None`` when that is not shown.

        A cheap query for a deep collision with the work object: ``getClosestPoints`` with the
        distance ``slack_m + need_m`` (negative for a penetration) looks only at the triangles
        near enough to go that deep. Bullet computes each triangle's contact on its own, so
        this returns a subset of the full query's points, bit for bit (checked in
        ``tests/planner/cell/probe/test_probe_clearance.py``); when its deepest point is within
        ``slack_m`` it is
        the full query's deepest. Only parts against the work object (a concave triangle mesh)
        are capped: between convex shapes the contact depends on the query distance (up to
        0.4 mm deeper was seen between two boxes).
        """
        self.last_points = 0
        dist = slack_m + part.need_m
        if part.env != self.wobj_body or part.kind == "self" or not dist < part.dist_m:
            return None
        c = self.client
        lo, hi = pb.getAABB(part.body, part.link, physicsClientId=c)
        elo, ehi = pb.getAABB(part.env, -1, physicsClientId=c)
        if any(lo[k] > ehi[k] + dist or elo[k] > hi[k] + dist for k in range(3)):
            return None
        points = pb.getClosestPoints(
            part.body, part.env, dist, linkIndexA=part.link, physicsClientId=c
        )
        self.last_points = len(points)
        best: Clearance | None = None
        for pt in points:
            slack = pt[8] - part.need_m
            if best is None or slack < best.slack_m:
                best = Clearance(pt[8] >= part.need_m, pt[8], slack, None)
        if best is None or not best.slack_m <= slack_m:
            return None
        pair_ = (self.names(part.body, part.link), part.env_name)
        return Clearance(best.ok, best.clearance_m, best.slack_m, pair_)

    def _self_part(self, part: QueryPart, pairs: np.ndarray | None = None) -> Clearance | None:
        """Robot-robot and robot-tool pairs not in the ACL (or those of ``pairs``), pair by
        pair, skipped by their axis-aligned boxes first (a whole-body self query would also
        compute every allowed, touching neighbour pair, ~10x slower)."""
        c, look = self.client, part.dist_m
        bodies, links, pa, pb_ = self._self_pair_table()
        if pairs is not None:
            keep = np.flatnonzero(pairs)
            if keep.size == 0:
                return None
            if keep.size <= FEW_SELF_PAIRS:
                return self._few_self_pairs(part, keep.tolist())
            used = np.unique(np.concatenate([pa[keep], pb_[keep]]))
            boxes = np.zeros((len(bodies), 2, 3))
            for i in used.tolist():
                boxes[i] = pb.getAABB(bodies[i], links[i], physicsClientId=c)
        else:
            keep = np.arange(pa.size)
            boxes = np.array(
                [pb.getAABB(b, i, physicsClientId=c) for b, i in zip(bodies, links)]
            )  # (L, 2, 3): lower and upper corners
        lo, hi = boxes[:, 0], boxes[:, 1]
        a_, b_ = pa[keep], pb_[keep]
        apart = np.any((lo[a_] > hi[b_] + look) | (lo[b_] > hi[a_] + look), axis=1)
        return self._closest_self(part, keep[~apart].tolist())

    def _few_self_pairs(self, part: QueryPart, keep: list[int]) -> Clearance | None:
        """:meth:`_self_part` of a few pairs (ascending indices ``keep`` into
        :meth:`_self_pair_table`) in plain Python: the same boxes, tests and queries in the
        same order, without numpy's per-call cost on arrays of a few elements."""
        c, look = self.client, part.dist_m
        bodies, links, pa, pb_ = self._self_pair_table()
        boxes: dict[int, tuple[Sequence[float], Sequence[float]]] = {}
        near: list[int] = []
        for k in keep:
            a, b = int(pa[k]), int(pb_[k])
            for i in (a, b):
                if i not in boxes:
                    boxes[i] = pb.getAABB(bodies[i], links[i], physicsClientId=c)
            (lo_a, hi_a), (lo_b, hi_b) = boxes[a], boxes[b]
            if not any(lo_a[x] > hi_b[x] + look or lo_b[x] > hi_a[x] + look for x in range(3)):
                near.append(k)
        return self._closest_self(part, near)

    def _closest_self(self, part: QueryPart, near: list[int]) -> Clearance | None:
        """The limiting point of the self pairs ``near`` (indices into
        :meth:`_self_pair_table`), in that order (``None``: nothing within the look)."""
        c, look = self.client, part.dist_m
        bodies, links, pa, pb_ = self._self_pair_table()
        best: Clearance | None = None
        for k in near:
            a, b = int(pa[k]), int(pb_[k])
            for pt in pb.getClosestPoints(
                bodies[a],
                bodies[b],
                look,
                linkIndexA=links[a],
                linkIndexB=links[b],
                physicsClientId=c,
            ):
                na, nb = self.names(pt[1], pt[3]), self.names(pt[2], pt[4])
                if pair(na, nb) in self.acl.allowed:
                    continue
                slack = pt[8] - part.need_m
                if best is None or slack < best.slack_m:
                    best = Clearance(pt[8] >= part.need_m, pt[8], slack, (na, nb))
        return best

    def query(
        self,
        margin_m: float,
        self_margin_m: float,
        report_m: float | None = None,
        sensor_wobj_allowed: bool = True,
        skip_wobj: bool = False,
    ) -> Clearance:
        """Clearance of the current state.

        Args:
            margin_m: required distance of robot and tool to the work object and fixtures, m.
            self_margin_m: required distance between robot/tool links not in the ACL, m.
            report_m: look this far for the limiting pair (default ``2 * margin_m + 5 mm``: far
                enough to tell a marginal pose, whose slack is below ``margin_m``); the sensor
                links look only ``margin_m`` far at the work object, as they need no clearance.
            sensor_wobj_allowed: the sensor links need only stay out of contact (distance
                >= 0) with the work object, not the margin.
            skip_wobj: do not check against the work object at all (an approach search past
                its nominal point: the real search stops at the surface, wherever it is).
        """
        plan = self.plan(margin_m, self_margin_m, report_m, sensor_wobj_allowed, skip_wobj)
        return plan.merge([self.evaluate(p) for p in plan.parts])
