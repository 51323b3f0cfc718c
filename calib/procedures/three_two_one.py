"""``three_two_one``: general 3-2-1 alignment on three non-parallel faces.

Exactly 3 ``primary`` points on one face, 2 ``secondary`` on a second, 1 ``tertiary`` on a
third (:mod:`calib.estimators.three_two_one` has the closed form). A plan made for another
procedure can still be calibrated by 3-2-1: :meth:`ThreeTwoOneProcedure.assign` picks the roles
from the faces the points lie on.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Literal

import msgspec
import numpy as np

from calib.errors import PlanError
from calib.estimators.runners import run_three_two_one
from calib.estimators.three_two_one import ThreeTwoOneLayout, three_two_one
from calib.paper.stator_layout import StatorLayout
from calib.probing import Probe, ProbePoint
from calib.procedures.base import (
    FloatArray,
    LayoutDesign,
    Measured,
    ProcedureRun,
    RolePoint,
    Steering,
    check_edge_offset,
    count_problem,
    edge_corrected,
    edge_offset_of,
    unknown_role_problem,
)
from calib.tolerances import FACE_MAX_DEVIATION_M, same_direction

#: The roles and how many points each takes.
ROLE_COUNTS = {"primary": 3, "secondary": 2, "tertiary": 1}


class ThreeTwoOne(
    msgspec.Struct,
    tag="three_two_one",
    tag_field="method",
    frozen=True,
    forbid_unknown_fields=True,
    kw_only=True,
):
    """3-2-1 alignment: primary, secondary and tertiary faces.

    Attributes:
        edge_event_offset_m: how far past a face's end the sensor reports it, removed from
            edge searches, metres (``None``: not measured; every face uses the sensor model's
            value: ``planner.program.settings``).
    """

    edge_event_offset_m: float | None = None

    def __post_init__(self) -> None:
        check_edge_offset(self.edge_event_offset_m)


def _faces(p: ProbePoint) -> list[tuple[float, ...]]:
    """The faces a point can stand for: ``(nx, ny, nz, offset)``, own face first."""
    faces = [(*p.normal, float(np.dot(p.normal, p.position_m)))]
    if p.edge_normal is not None:
        faces.append((*p.edge_normal, float(np.dot(p.edge_normal, p.position_m))))
    return [tuple(float(v) for v in f) for f in faces]


def _same_face(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    """Two ``(n, offset)`` faces are one within the tolerances of :mod:`calib.tolerances`."""
    cos = float(np.dot(a[:3], b[:3]))
    return same_direction(cos) and abs(a[3] - b[3]) <= FACE_MAX_DEVIATION_M


def _spread(a: ProbePoint, b: ProbePoint, c: ProbePoint) -> float:
    return float(
        np.linalg.norm(
            np.cross(
                np.subtract(b.position_m, a.position_m), np.subtract(c.position_m, a.position_m)
            )
        )
    )


def pick_roles(points: Sequence[RolePoint]) -> dict[str, list[RolePoint]]:
    """3-2-1 roles picked from the faces of points made for another procedure.

    The primary face is the one most points lie on (three spanning the largest triangle); the
    secondary is the face, not parallel to it, with the most other points (the two farthest
    apart); the tertiary is a remaining point on a third face.

    Raises:
        PlanError: no face holds three points, or no second or third face is left.
    """
    groups: dict[tuple[float, ...], list[RolePoint]] = {}
    for rp in points:
        for f in _faces(rp.point):
            key = next((g for g in groups if _same_face(g, f)), f)
            groups.setdefault(key, []).append(rp)
    ranked = sorted(groups.items(), key=lambda kv: -len(kv[1]))
    if not ranked or len(ranked[0][1]) < 3:
        raise PlanError("three_two_one: no face with 3 points for the primary role")
    primary_face, primary_pts = ranked[0]
    plain = [rp for rp in primary_pts if rp.point.search.kind == "approach"]
    if len(plain) >= 3:  # keep edge points free: they also stand for the face whose end they find
        primary_pts = plain
    best, area = primary_pts[:3], -1.0
    for i, a in enumerate(primary_pts):
        for j in range(i + 1, len(primary_pts)):
            for b in primary_pts[j + 1 :]:
                c = primary_pts[j]
                s = _spread(a.point, c.point, b.point)
                if s > area:
                    best, area = [a, c, b], s
    used = {rp.point.id for rp in best}
    chosen: dict[str, list[RolePoint]] = {"primary": best}
    normals = [np.array(primary_face[:3])]
    for role, need in (("secondary", 2), ("tertiary", 1)):
        for face, pts in ranked:
            n = np.array(face[:3])
            if any(abs(float(n @ m)) > math.cos(math.radians(2.0)) for m in normals):
                continue
            free = [rp for rp in pts if rp.point.id not in used]
            if len(free) >= need:
                if need == 2:
                    pairs = [(a, b) for i, a in enumerate(free) for b in free[i + 1 :]]
                    far = max(
                        pairs,
                        key=lambda ab: float(
                            np.linalg.norm(
                                np.subtract(ab[0].point.position_m, ab[1].point.position_m)
                            )
                        ),
                    )
                    pick = [far[0], far[1]]
                else:
                    pick = free[:1]
                chosen[role] = pick
                used |= {rp.point.id for rp in pick}
                normals.append(n)
                break
        else:
            raise PlanError(f"three_two_one: no face for the {role} role among the plan's points")
    return chosen


class ThreeTwoOneProcedure:
    """3-2-1 alignment as a :class:`~calib.procedures.base.ProcedureKind`."""

    method = "three_two_one"
    settings_type: type = ThreeTwoOne
    roles: tuple[str, ...] = tuple(ROLE_COUNTS)
    role_limits: Mapping[str, int | None] = MappingProxyType(dict(ROLE_COUNTS))
    label = "3-2-1"
    summary = "3 points on a primary face, 2 on a secondary, 1 on a tertiary"
    #: suggest puts 3, 2 and 1 points on three faces far from parallel
    design: LayoutDesign | None = LayoutDesign(face_roles=tuple(ROLE_COUNTS.items()))
    #: an adaptive program updates after the primary, the secondary and the tertiary points
    steering: Steering | None = Steering(tuple(ROLE_COUNTS.values()))
    published: Mapping[tuple[str, float], float] | None = None
    #: Six face constraints, solved exactly: its linearised covariance is the least-squares
    #: one of its searches (a test checks it against the linearisation to 1e-9).
    least_squares = True
    #: an edge point stands on its role's face (see :mod:`calib.estimators.three_two_one`)
    edge_rows: Literal["both", "edge"] = "both"

    def role_problem(self, roles: Sequence[str], complete: bool) -> str:
        """See :meth:`ProcedureKind.role_problem`."""
        problem = unknown_role_problem(self.method, roles, self.roles)
        if problem or not complete:
            return problem
        return count_problem(self.method, roles, ROLE_COUNTS)

    def assign(self, points: Sequence[RolePoint]) -> list[RolePoint]:
        """Primary, secondary, tertiary in that order: the points' own roles when they are
        3-2-1 roles, else picked from their faces (:func:`pick_roles`)."""
        roles = [rp.role for rp in points]
        if not self.role_problem(roles, complete=True):
            return [rp for r in ROLE_COUNTS for rp in points if rp.role == r]
        if not any(r in ROLE_COUNTS for r in roles):
            chosen = pick_roles(points)
            return [RolePoint(r, rp.point) for r in ROLE_COUNTS for rp in chosen[r]]
        raise PlanError(self.role_problem(roles, complete=True))

    def layout(self, points: Sequence[RolePoint]) -> ThreeTwoOneLayout:
        """The 3-2-1 layout of the (assigned) points."""
        ordered = self.assign(points)
        by = {r: [rp.point for rp in ordered if rp.role == r] for r in ROLE_COUNTS}
        return ThreeTwoOneLayout.from_points(by["primary"], by["secondary"], by["tertiary"])

    def run(
        self,
        points: Sequence[RolePoint],
        T_base_wobj_nominal: FloatArray,
        probe: Probe,
        settings: object,
    ) -> ProcedureRun:
        """Primary, then secondary, then tertiary, each commanded in the estimate so far."""
        layout = self.layout(points)
        return run_three_two_one(
            layout, probe, T_base_wobj_nominal, edge_offset_m=edge_offset_of(settings)
        )

    def estimate(
        self,
        points: Sequence[RolePoint],
        measured: Measured,
        T_base_wobj_nominal: FloatArray,
        settings: object,
    ) -> ProcedureRun:
        """The closed-form 3-2-1 of the first measurement of each of the six points."""
        ordered = self.assign(points)
        layout = self.layout(ordered)
        ids = tuple(rp.point.id for rp in ordered)
        raw = np.array([np.asarray(measured[i], dtype=float).reshape(-1, 3)[0] for i in ids])
        q = edge_corrected(layout.points, raw, T_base_wobj_nominal, edge_offset_of(settings))
        T = three_two_one(layout, q, T_base_wobj_nominal).T_base_wobj
        return ProcedureRun(T, ids, dict(zip(ids, raw, strict=True)))

    def adaptive_layout(self, points: Sequence[RolePoint]) -> StatorLayout | None:
        """``None``: programs run the 3-2-1 searches in the nominal frame."""
        return None


THREE_TWO_ONE = ThreeTwoOneProcedure()
