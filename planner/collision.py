"""Collision checking of the cell: the clearance query with its allowed-collision list.

The clearance query (:meth:`CollisionChecker.query`) checks the current PyBullet state: robot
and tool against the work object, the fixtures and themselves, and returns the limiting pair and
its distance. Robot and tool vs the environment are batched ``getClosestPoints`` calls (one per
body pair; the tool link by link against the work object, because the sensor links look less
far). Robot-robot and robot-tool pairs go one by one (a whole-body self query also computes
every allowed, touching neighbour pair), skipped first by the allowed-collision list
(:mod:`planner.acl`, re-exported here) and by their axis-aligned boxes.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from planner.acl import (
    ACL_VERSION,
    ALWAYS_FRACTION,
    AllowedCollisions,
    Pair,
    acl_key,
    cache_dir,
    compute_acl,
    pair,
)
from planner.bodies import BodyLinks
from planner.pybullet_client import pb

log = logging.getLogger(__name__)

__all__ = [
    "ACL_VERSION",
    "ALWAYS_FRACTION",
    "AllowedCollisions",
    "Clearance",
    "CollisionChecker",
    "Pair",
    "acl_key",
    "cache_dir",
    "compute_acl",
    "pair",
]


@dataclass(frozen=True)
class Clearance:
    """Result of a clearance query.

    Attributes:
        ok: True when every checked pair keeps its required distance.
        clearance_m: distance of the limiting pair, m (negative: penetration); capped at the
            query distance when nothing came that close.
        slack_m: ``clearance_m`` minus the limiting pair's required distance, m.
        pair: ``(moving link, other)`` of the limiting pair, or ``None`` when nothing is near.
    """

    ok: bool
    clearance_m: float
    slack_m: float
    pair: tuple[str, str] | None

    def describe(self) -> str:
        """E.g. ``"link_4 hits table (clearance -3.0 mm)"``, ``"... is too near ..."`` (inside
        the margin), ``"... is near ..."`` (the limiting pair of a passing pose)."""
        if self.pair is None:
            return "no collision"
        verb = "hits" if self.clearance_m < 0 else "is too near" if not self.ok else "is near"
        return f"{self.pair[0]} {verb} {self.pair[1]} (clearance {self.clearance_m * 1e3:.1f} mm)"


@dataclass
class CollisionChecker:
    """The fast clearance query of a cell (built by :class:`planner.cell.Cell`).

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
        look = report_m if report_m is not None else 2.0 * margin_m + 0.005
        look = max(look, margin_m, self_margin_m) + 1e-9
        best = Clearance(True, look, look - margin_m, None)
        c = self.client
        for env, env_name in self.environment.items():
            if skip_wobj and env == self.wobj_body:
                continue
            queries = [(self.robot.body_id, -2, look)]
            if self.tool is not None:
                tid = self.tool.body_id
                if env != self.wobj_body:
                    queries.append((tid, -2, look))
                else:  # the sensor needs only contact-free (+ margin to call it marginal)
                    for link in self._tool_links():
                        sensor = link in self.sensor_links and sensor_wobj_allowed
                        queries.append((tid, link, margin_m if sensor else look))
            for bid, link_filter, dist in queries:
                kw = {} if link_filter == -2 else {"linkIndexA": link_filter}
                for pt in pb.getClosestPoints(bid, env, dist, physicsClientId=c, **kw):
                    link = pt[3]
                    if bid == self.robot.body_id and link in self.static_links:
                        continue
                    need = margin_m
                    if (
                        sensor_wobj_allowed
                        and bid != self.robot.body_id
                        and link in self.sensor_links
                        and env == self.wobj_body
                    ):
                        need = 0.0
                    d = pt[8]
                    if d - need < best.slack_m:
                        best = Clearance(d >= need, d, d - need, (self.names(bid, link), env_name))
        self_look = max(self_margin_m, look)
        c = self.client
        # pair by pair, skipped by the ACL and by axis-aligned boxes first: a whole-body query
        # would also compute every allowed, touching neighbour pair (~10x slower)
        bodies, links, pa, pb_ = self._self_pair_table()
        boxes = np.array(
            [pb.getAABB(b, i, physicsClientId=c) for b, i in zip(bodies, links)]
        )  # (L, 2, 3): lower and upper corners
        lo, hi = boxes[:, 0], boxes[:, 1]
        apart = np.any((lo[pa] > hi[pb_] + self_look) | (lo[pb_] > hi[pa] + self_look), axis=1)
        points = []
        for k in np.flatnonzero(~apart).tolist():
            a, b = int(pa[k]), int(pb_[k])
            points += pb.getClosestPoints(
                bodies[a],
                bodies[b],
                self_look,
                linkIndexA=links[a],
                linkIndexB=links[b],
                physicsClientId=c,
            )
        for pt in points:
            na, nb = self.names(pt[1], pt[3]), self.names(pt[2], pt[4])
            if pair(na, nb) in self.acl.allowed:
                continue
            d = pt[8]
            if d - self_margin_m < best.slack_m:
                best = Clearance(d >= self_margin_m, d, d - self_margin_m, (na, nb))
        if best.pair is not None and best.slack_m >= 0:
            best = Clearance(True, best.clearance_m, best.slack_m, best.pair)
        return best
