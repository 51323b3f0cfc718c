"""Collision checking of the cell: the allowed-collision list and the clearance query.

The allowed-collision list (ACL) is worked out once per robot + tool by sampling random
in-limit configurations (pybullet-planning's ``get_collision_fn`` idea: compute once, return a
fast predicate). A pair of robot/tool links is *allowed* (never reported) when it is adjacent
(parent and child, or the tool's root on the flange link) or when it is closer than the self
margin in at least :data:`ALWAYS_FRACTION` of the samples (e.g. vendor wrist meshes that
overlap in every pose). Pairs that never came near are recorded as ``never`` but are still
checked: Bullet's broadphase already skips far pairs inside one batched call, so skipping them
would save nothing and could hide a rare real collision. The list is cached in memory and on disk
(JSON, ``$WOBJCAL_CACHE_DIR`` or ``~/.cache/wobjcal``), keyed by a hash of the URDF texts.

The clearance query (:meth:`CollisionChecker.query`) checks the current PyBullet state: robot
and tool against the work object, the fixtures and themselves, with batched
``getClosestPoints`` calls (one per body pair), and returns the limiting pair and its distance.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pybullet as pb

from calib.atomic_io import write_bytes_atomic
from planner.bodies import BodyLinks

log = logging.getLogger(__name__)

#: A pair closer than the self margin in at least this fraction of the samples is allowed.
ALWAYS_FRACTION = 0.95
#: Bump when the ACL rule changes, so cached lists are recomputed.
ACL_VERSION = 1

Pair = tuple[str, str]
_MEMORY_CACHE: dict[str, AllowedCollisions] = {}


def pair(a: str, b: str) -> Pair:
    """The canonical (sorted) form of a link pair."""
    return (a, b) if a <= b else (b, a)


@dataclass(frozen=True)
class AllowedCollisions:
    """The allowed-collision list of one robot + tool.

    Attributes:
        allowed: link pairs never reported (adjacent, or near in almost every sample).
        never: pairs never closer than the self margin in the samples (still checked).
        near_fraction: pair -> fraction of samples closer than the self margin.
        n_samples: number of random configurations sampled.
        key: the cache key (hash of the URDF texts and settings).
    """

    allowed: frozenset[Pair]
    never: frozenset[Pair]
    near_fraction: dict[Pair, float] = field(repr=False)
    n_samples: int
    key: str

    def to_json(self) -> str:
        """Canonical JSON text of the list."""
        return json.dumps(
            {
                "schema": f"wobjcal.acl/{ACL_VERSION}",
                "allowed": sorted(self.allowed),
                "never": sorted(self.never),
                "near_fraction": sorted([*k, v] for k, v in self.near_fraction.items()),
                "n_samples": self.n_samples,
                "key": self.key,
            },
            indent=1,
            sort_keys=True,
        )

    @classmethod
    def from_json(cls, text: str) -> AllowedCollisions:
        """Inverse of :meth:`to_json`."""
        d = json.loads(text)
        return cls(
            allowed=frozenset(pair(*p) for p in d["allowed"]),
            never=frozenset(pair(*p) for p in d["never"]),
            near_fraction={pair(a, b): float(f) for a, b, f in d["near_fraction"]},
            n_samples=int(d["n_samples"]),
            key=str(d["key"]),
        )


def cache_dir() -> Path:
    """Directory of cached ACLs: ``$WOBJCAL_CACHE_DIR/acl`` or ``~/.cache/wobjcal/acl``."""
    root = os.environ.get("WOBJCAL_CACHE_DIR") or Path.home() / ".cache" / "wobjcal"
    return Path(root) / "acl"


def acl_key(texts: Iterable[bytes], settings: str) -> str:
    """Cache key: sha256 of the URDF texts and the settings string."""
    h = hashlib.sha256(f"acl{ACL_VERSION}:{settings}".encode())
    for t in texts:
        h.update(hashlib.sha256(t).digest())
    return h.hexdigest()[:32]


def compute_acl(
    client: int,
    robot: BodyLinks,
    tool: BodyLinks | None,
    names: Callable[[int, int], str],
    set_config: Callable[[np.ndarray], None],
    samples: np.ndarray,
    adjacent: Iterable[Pair],
    self_margin_m: float,
    key: str,
    use_cache: bool = True,
) -> AllowedCollisions:
    """Sample configurations and classify robot/tool link pairs (see the module docstring).

    Args:
        client: PyBullet client id.
        robot: the robot body; ``tool``: the tool body, or ``None``.
        names: ``(body_id, link_index) -> link name`` as used in reports.
        set_config: puts the robot (and tool) in configuration ``q (n,)``.
        samples: ``(S, n)`` random in-limit configurations, rad.
        adjacent: pairs always allowed (parent-child links, tool root on the flange link).
        self_margin_m: a pair closer than this counts as near, m.
        key: cache key (see :func:`acl_key`).
        use_cache: read and write the memory and disk caches.
    """
    if use_cache and key in _MEMORY_CACHE:
        return _MEMORY_CACHE[key]
    path = cache_dir() / f"{key}.json"
    if use_cache and path.is_file():
        try:
            acl = AllowedCollisions.from_json(path.read_text())
            _MEMORY_CACHE[key] = acl
            return acl
        except (ValueError, KeyError, TypeError):
            log.warning("ignoring unreadable ACL cache %s", path)
    counts: dict[Pair, int] = {}
    bodies = [(robot.body_id, robot.body_id)]
    if tool is not None:
        bodies.append((robot.body_id, tool.body_id))
    for q in samples:
        set_config(q)
        seen: set[Pair] = set()
        for a, b in bodies:
            for pt in pb.getClosestPoints(a, b, self_margin_m, physicsClientId=client):
                if a == b and pt[3] == pt[4]:
                    continue
                seen.add(pair(names(a, pt[3]), names(b, pt[4])))
        for p in seen:
            counts[p] = counts.get(p, 0) + 1
    all_pairs = _all_pairs(robot, tool, names)
    n = max(len(samples), 1)
    frac = {p: counts.get(p, 0) / n for p in all_pairs}
    allowed = {pair(*p) for p in adjacent} | {p for p, f in frac.items() if f >= ALWAYS_FRACTION}
    never = {p for p, f in frac.items() if f == 0.0 and p not in allowed}
    acl = AllowedCollisions(frozenset(allowed), frozenset(never), frac, len(samples), key)
    if use_cache:
        _MEMORY_CACHE[key] = acl
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_bytes_atomic(path, acl.to_json().encode())
        except OSError as exc:
            log.warning("cannot write ACL cache %s: %s", path, exc)
    return acl


def _all_pairs(robot: BodyLinks, tool: BodyLinks | None, names: Callable[[int, int], str]):
    r = [names(robot.body_id, i) for i in robot.names]
    t = [names(tool.body_id, i) for i in tool.names] if tool is not None else []
    out = {pair(a, b) for i, a in enumerate(r) for b in r[i + 1 :]}
    out |= {pair(a, b) for a in r for b in t}
    return out


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

    def _robot_pairs(self) -> list[tuple[int, int]]:
        """Robot link pairs to check: both have collision shapes, not both static, not in
        the ACL (computed once)."""
        if self._pairs is None:
            rid, c = self.robot.body_id, self.client
            solid = [
                i for i in self.robot.names if pb.getCollisionShapeData(rid, i, physicsClientId=c)
            ]
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
        rid = self.robot.body_id
        # robot vs itself pair by pair (a whole-body query also computes every allowed,
        # touching neighbour pair: ~10x slower); robot vs tool in one batched call
        points = [
            pt
            for a, b in self._robot_pairs()
            for pt in pb.getClosestPoints(
                rid, rid, self_look, linkIndexA=a, linkIndexB=b, physicsClientId=self.client
            )
        ]
        if self.tool is not None:
            points += pb.getClosestPoints(
                rid, self.tool.body_id, self_look, physicsClientId=self.client
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
