"""The document the UI edits: the probe points of the plan, with pure edit functions.

The UI keeps the points as :class:`calib.probing.ProbePoint` values (wobj frame, metres) plus a
role. Each edit returns a new :class:`UiPlan`; :class:`webui.state.SessionState` keeps the old
one for undo. The plan file the points came from (``source``) rides along unchanged so that
saving writes everything else back as it was.
"""

from __future__ import annotations

import dataclasses
import string
from collections import Counter
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from calib.errors import InputError
from calib.paper.stator_layout import STATOR_POINT_IDS
from calib.plan.vias import ViaPoint
from calib.probing import ProbePoint, SearchSpec
from planner.program.build import safety_spec

if TYPE_CHECKING:
    from calib.plan.file import Plan

#: The paper's point names (also the roles of its A-H procedure).
PAPER_IDS: tuple[str, ...] = STATOR_POINT_IDS
#: The role of a point that has none yet (every role of the procedure is full).
NO_ROLE = ""


@dataclass(frozen=True)
class UiPoint:
    """One probe point as the UI shows it.

    Attributes:
        probe: the nominal point, normal and search, wobj frame (metres).
        role: what the point is for in the procedure (e.g. ``"A"`` for the paper's A-H
            procedure, ``"primary"`` for 3-2-1); see :mod:`calib.procedures`.
        speed_m_s: search speed written into robot programs, m/s.
        vias: the joint configurations the robot passes on its way to the point, in order
            (:mod:`calib.plan.vias`; joint values authoritative).
    """

    probe: ProbePoint
    role: str = "A"
    speed_m_s: float = 0.010
    vias: tuple[ViaPoint, ...] = ()

    @property
    def id(self) -> str:
        """The point's id, e.g. ``"A"``."""
        return self.probe.id


@dataclass(frozen=True)
class UiPlan:
    """The probe points being edited, in order, and the plan they came from.

    Attributes:
        points: the probe points, in procedure order.
        name: a short name of the plan for titles and file names.
        roles: the roles the plan's procedure allows, offered in the role dropdown.
        role_limits: how many points each of ``roles`` takes at most (``None``: any number),
            from the procedure's ``role_limits``; ``None``: each role once (the paper's A-H).
        method: the procedure's name (:data:`calib.procedures.PROCEDURES`).
        source: the loaded plan object (``calib.plan.file``) the points came from, or ``None``.
    """

    points: tuple[UiPoint, ...] = ()
    name: str = "plan"
    roles: tuple[str, ...] = PAPER_IDS
    role_limits: tuple[int | None, ...] | None = None
    method: str = "hultman2013"
    source: Plan | None = field(default=None, compare=False)

    def limit_of(self, role: str) -> int | None:
        """How many points ``role`` takes at most (``None``: any number; 0: not a role here)."""
        if role not in self.roles:
            return 0
        return 1 if self.role_limits is None else self.role_limits[self.roles.index(role)]

    @property
    def ids(self) -> tuple[str, ...]:
        """The point ids in order."""
        return tuple(p.id for p in self.points)

    def get(self, point_id: str) -> UiPoint:
        """The point named ``point_id``; :class:`InputError` listing the ids when unknown."""
        for p in self.points:
            if p.id == point_id:
                return p
        raise InputError(f"no point {point_id!r} in the plan (points: {', '.join(self.ids)})")


def next_id(plan: UiPlan) -> str:
    """The first unused id: A-H first, then I, J, ... Z, then P1, P2, ..."""
    used = set(plan.ids)
    for name in string.ascii_uppercase:
        if name not in used:
            return name
    k = 1
    while f"P{k}" in used:
        k += 1
    return f"P{k}"


def next_free_role(plan: UiPlan, prefer: str | None = None) -> str:
    """The role a new point takes: ``prefer`` when it is a role not yet full, else the first
    role of the procedure not yet full, else :data:`NO_ROLE` (never a duplicate)."""
    counts = Counter(p.role for p in plan.points)

    def free(role: str) -> bool:
        limit = plan.limit_of(role)
        return limit is None or counts[role] < limit

    if prefer is not None and prefer in plan.roles and free(prefer):
        return prefer
    return next((r for r in plan.roles if free(r)), NO_ROLE)


def role_refusal(plan: UiPlan) -> str:
    """Why the points' roles cannot go into a plan file, naming the points (``""``: they can).

    Points without a role and roles taken by more points than the procedure allows are named,
    e.g. ``role A is taken by points A, I, J (hultman2013 takes 1)``.
    """
    problems = []
    unset = [p.id for p in plan.points if p.role == NO_ROLE]
    if unset:
        problems.append(
            f"point{'s' if len(unset) > 1 else ''} {', '.join(unset)} "
            f"{'have' if len(unset) > 1 else 'has'} no role: give "
            f"{'each' if len(unset) > 1 else 'it'} one of {', '.join(plan.roles)} or delete "
            f"{'them' if len(unset) > 1 else 'it'}"
        )
    for role in plan.roles:
        holders = [p.id for p in plan.points if p.role == role]
        limit = plan.limit_of(role)
        if limit is not None and len(holders) > limit:
            problems.append(
                f"role {role} is taken by points {', '.join(holders)} ({plan.method} takes {limit})"
            )
    other = sorted({p.role for p in plan.points if p.role not in (*plan.roles, NO_ROLE)})
    for role in other:
        holders = [p.id for p in plan.points if p.role == role]
        problems.append(
            f"{plan.method} has no role {role!r} (points {', '.join(holders)}); its roles are "
            f"{', '.join(plan.roles)}"
        )
    return "; ".join(problems)


def _tuple3(v: ArrayLike) -> tuple[float, float, float]:
    a = np.asarray(v, dtype=np.float64).reshape(3)
    return (float(a[0]), float(a[1]), float(a[2]))


def _search_for_normal(search: SearchSpec, normal: ArrayLike) -> SearchSpec:
    """Keep an edge search valid after the normal changed: project its direction into the face."""
    if search.kind != "edge" or search.edge_direction is None:
        return search
    n = np.asarray(normal, float)
    d = np.asarray(search.edge_direction, float)
    d = d - (d @ n) * n
    norm = float(np.linalg.norm(d))
    if norm < 1e-9:  # direction along the new normal: fall back to an approach search
        return SearchSpec(start_offset_m=search.start_offset_m, overtravel_m=search.overtravel_m)
    return dataclasses.replace(search, edge_direction=_tuple3(d / norm))


def _sized_search(
    plan: UiPlan, position_wobj: ArrayLike, max_overtravel_m: float | None = None
) -> SearchSpec:
    """The approach search of a new point, sized to the plan's misplacement, its sensor and
    the part.

    - Start offset: the default (30 mm), or more when the misplacement needs it
      (``wobjcal check`` refuses a search that cannot reach its face wherever the part may
      lie); that need includes the sensor's sensing distance and a margin, so the search
      never starts with the surface already in the sensor's range.
    - Overtravel: the default (20 mm), shortened to ``max_overtravel_m`` (what the part's
      material and a fixture or table behind the point leave, less the sensor's clearance:
      :func:`webui.search_room.overtravel_cap_m`), but never shorter than the misplacement
      needs. When the misplacement needs more than the part allows, the misplacement's value
      is kept: the check then reports the collision, which is the truth about this plan.

    The rotation's lever is taken to the farthest other point, at least the lever to the
    points' centroid, the misplacement's pivot. Without a plan file (``source``) the default.

    Args:
        plan: the plan the point goes into.
        position_wobj: ``(3,)`` the new point, wobj frame, m.
        max_overtravel_m: the longest overtravel the cell leaves behind the point, m
            (``None``: not limited).
    """
    default = SearchSpec()
    src = plan.source
    if src is None:
        return default
    p = np.asarray(position_wobj, dtype=np.float64).reshape(3)
    others = [np.asarray(q.probe.position_m, dtype=np.float64) for q in plan.points]
    far = max(others, key=lambda q: float(np.linalg.norm(q - p)), default=p)
    safety = dataclasses.replace(
        safety_spec(src), pivot_wobj_m=(float(far[0]), float(far[1]), float(far[2]))
    )
    start_need = safety.sensing_distance_m + safety.margin_m
    overtravel = default.overtravel_m
    if max_overtravel_m is not None:
        overtravel = min(overtravel, float(max_overtravel_m))
    return SearchSpec(
        start_offset_m=max(default.start_offset_m, start_need, safety.start_clearance_m(p)),
        overtravel_m=max(overtravel, safety.overtravel_m(p)),
    )


def place_point(
    plan: UiPlan,
    point_id: str,
    position_wobj: ArrayLike,
    normal_wobj: ArrayLike,
    role: str | None = None,
    max_overtravel_m: float | None = None,
) -> UiPlan:
    """Put point ``point_id`` at a surface point with that face's normal (add it if new).

    An existing point keeps its role and search settings (an edge direction is projected into the
    new face); a new one gets an approach search sized for the plan's misplacement, its sensor
    and the room behind the point (:func:`_sized_search`; ``max_overtravel_m``, m: the longest
    overtravel the cell leaves there, ``None``: not limited) and the role ``role`` (default:
    its id when the procedure has such a role and it is free, else the first role not yet
    full, else :data:`NO_ROLE`: never a duplicate, see :func:`next_free_role`).
    """
    if not point_id:
        raise InputError("point id must not be empty")
    n = np.asarray(normal_wobj, float)
    n = n / np.linalg.norm(n)
    existing = {p.id: p for p in plan.points}
    old = existing.get(point_id)
    search = (
        _sized_search(plan, position_wobj, max_overtravel_m)
        if old is None
        else _search_for_normal(old.probe.search, n)
    )
    edge_normal = None if old is None or search.kind != "edge" else old.probe.edge_normal
    probe = ProbePoint(
        id=point_id,
        position_m=_tuple3(position_wobj),
        normal=_tuple3(n),
        search=search,
        edge_normal=edge_normal,
    )
    if role is None:
        role = old.role if old is not None else next_free_role(plan, prefer=point_id)
    speed = 0.010 if old is None else old.speed_m_s
    vias = () if old is None else old.vias
    new = UiPoint(probe=probe, role=role, speed_m_s=speed, vias=vias)
    if old is None:
        return dataclasses.replace(plan, points=(*plan.points, new))
    return dataclasses.replace(
        plan, points=tuple(new if p.id == point_id else p for p in plan.points)
    )


def add_via(plan: UiPlan, point_id: str, via: ViaPoint) -> UiPlan:
    """Add ``via`` as the last via before point ``point_id`` (which must exist).

    Raises:
        InputError: unknown point, or a via whose joint count differs from the plan's others.
    """
    old = plan.get(point_id)
    counts = {len(v.q_rad) for p in plan.points for v in p.vias}
    if counts and len(via.q_rad) not in counts:
        raise InputError(
            f"via of {point_id}: {len(via.q_rad)} joint values, the plan's vias have {counts.pop()}"
        )
    return replace_point(plan, dataclasses.replace(old, vias=(*old.vias, via)))


def remove_last_via(plan: UiPlan, point_id: str) -> UiPlan:
    """Remove the last via before point ``point_id``.

    Raises:
        InputError: unknown point, or a point with no via.
    """
    old = plan.get(point_id)
    if not old.vias:
        raise InputError(f"point {point_id} has no via to remove")
    return replace_point(plan, dataclasses.replace(old, vias=old.vias[:-1]))


def replace_point(plan: UiPlan, point: UiPoint) -> UiPlan:
    """Replace the point with the same id (which must exist)."""
    plan.get(point.id)
    return dataclasses.replace(
        plan, points=tuple(point if p.id == point.id else p for p in plan.points)
    )


def delete_point(plan: UiPlan, point_id: str) -> UiPlan:
    """Remove point ``point_id`` (which must exist)."""
    plan.get(point_id)
    return dataclasses.replace(plan, points=tuple(p for p in plan.points if p.id != point_id))


def edit_search(
    plan: UiPlan,
    point_id: str,
    *,
    kind: str,
    start_offset_m: float,
    overtravel_m: float,
    edge_direction: ArrayLike | None = None,
    role: str | None = None,
) -> UiPlan:
    """Change the search settings (and optionally the role) of one point.

    For an edge search the direction is projected into the point's face and normalised; a
    direction along the normal is refused with a message.

    Raises:
        InputError: unknown point, bad lengths, or an unusable edge direction.
    """
    old = plan.get(point_id)
    direction = None
    if kind == "edge":
        if edge_direction is None:
            raise InputError(f"point {point_id}: an edge search needs an edge direction")
        n = np.asarray(old.probe.normal, float)
        d = np.asarray(edge_direction, float)
        d = d - (d @ n) * n
        if float(np.linalg.norm(d)) < 1e-6:
            raise InputError(
                f"point {point_id}: the edge direction must lie in the face, not along its normal"
            )
        direction = _tuple3(d / np.linalg.norm(d))
    search = SearchSpec(
        kind=kind,  # type: ignore[arg-type]  # SearchSpec validates the value
        start_offset_m=float(start_offset_m),
        overtravel_m=float(overtravel_m),
        edge_direction=direction,
    )
    edge_normal = old.probe.edge_normal if kind == "edge" else None
    probe = dataclasses.replace(old.probe, search=search, edge_normal=edge_normal)
    new_role = old.role if role is None else role
    return replace_point(
        plan, UiPoint(probe=probe, role=new_role, speed_m_s=old.speed_m_s, vias=old.vias)
    )
