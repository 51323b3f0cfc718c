"""Results and parts of clearance queries (see :mod:`planner.cell.scene.collision`).

:class:`Clearance` is the answer of a query: the limiting pair and its distance. A query is
made of :class:`QueryPart` s (one moving link against one environment body, or the
self-collision pairs) listed in a canonical order by a :class:`QueryPlan`, whose
:meth:`QueryPlan.merge` turns the parts' results into the query's answer.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from planner.reasons import Reason, ReasonKind


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

    def reason(self, prefix: str = "", kind: ReasonKind = "collision") -> Reason:
        """:meth:`describe` as a :class:`~planner.reasons.Reason` of ``kind`` (a collision;
        ``"move"`` for a move between points) with the limiting pair, after ``prefix``."""
        return Reason(kind, prefix + self.describe(), self.pair)


@dataclass(frozen=True)
class QueryPart:
    """One unit of a clearance query (see :meth:`CollisionChecker.plan`).

    Attributes:
        index: position in the canonical order; of equal distances the lower index limits.
        kind: ``"robot"`` (a moving robot link vs an environment body), ``"tool"`` (a tool link
            vs an environment body: depends only on the flange pose) or ``"self"`` (every
            robot-robot and robot-tool pair not in the ACL).
        body: PyBullet body of the link (-1 for ``"self"``).
        link: link index in ``body`` (-1 for ``"self"``).
        env: environment body id (-1 for ``"self"``).
        env_name: name of ``env`` as reported (empty for ``"self"``).
        dist_m: how far the part looks, m.
        need_m: required distance of the part, m (its slack is distance minus this).
    """

    index: int
    kind: str
    body: int
    link: int
    env: int
    env_name: str
    dist_m: float
    need_m: float


@dataclass(frozen=True)
class QueryPlan:
    """The parts of one clearance query and how to merge their results.

    Attributes:
        parts: the parts in canonical order (``parts[i].index == i``).
        look_m: the clearance reported when nothing is nearer, m.
        margin_m: required distance to the work object and fixtures, m.
    """

    parts: tuple[QueryPart, ...]
    look_m: float
    margin_m: float

    def merge(self, results: Sequence[Clearance | None]) -> Clearance:
        """The query's :class:`Clearance` from every part's result, in canonical order."""
        best = Clearance(True, self.look_m, self.look_m - self.margin_m, None)
        for r in results:
            if r is not None and r.slack_m < best.slack_m:
                best = r
        if best.pair is not None and best.slack_m >= 0:
            best = Clearance(True, best.clearance_m, best.slack_m, best.pair)
        return best
