"""What every calibration procedure provides: the :class:`ProcedureKind` protocol and its types.

A procedure turns probe points with roles into the work-object frame ``T_base_wobj``, either
step by step with a probe callback (:meth:`ProcedureKind.run`: the robot or the simulation
measures as the procedure commands) or from measurements already taken
(:meth:`ProcedureKind.estimate`: ``wobjcal calibrate``). Implementations live one per module in
:mod:`calib.procedures` and are listed in :data:`calib.procedures.PROCEDURES`.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from calib.errors import PlanError
from calib.probing import Probe, ProbePoint

if TYPE_CHECKING:
    from calib.paper.stator_layout import StatorLayout

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class RolePoint:
    """A probe point with its role in a procedure.

    Attributes:
        role: the role, e.g. ``"A"`` (A-H), ``"primary"`` (3-2-1), ``"fit"`` (best fit).
        point: the nominal point, normal and search, wobj frame, metres (``point.id`` is the
            plan's point id).
    """

    role: str
    point: ProbePoint


@dataclass(frozen=True)
class ProcedureRun:
    """The frame a procedure computed, and from which points.

    Attributes:
        T_base_wobj: ``(4, 4)`` the calibrated work object in the robot base frame, metres.
        used_ids: the plan point ids the frame was computed from, in procedure order.
        measured_m: ``{key: (3,)}`` every measurement the procedure took or used, base frame,
            metres; the key is the point id, or ``"<id>#2"`` for a second measurement of a
            point (the A-H procedure's retakes of C and D).
    """

    T_base_wobj: FloatArray
    used_ids: tuple[str, ...]
    measured_m: Mapping[str, FloatArray] = field(default_factory=dict)


#: ``{point id: (k, 3)}`` the measurements of each point in order (retakes after the first),
#: base frame, metres. Looking up a point that was not measured raises an ``InputError`` that
#: names it (see :class:`planner.calibrate.job.MeasuredPoints`).
Measured = Mapping[str, FloatArray]


class ProcedureKind(Protocol):
    """A calibration procedure: its roles, their checks, and how it computes the frame.

    Attributes:
        method: the procedure's tag in a plan (``procedure.method``), e.g. ``"best_fit"``.
        settings_type: its settings struct (a member of
            :data:`calib.procedures.ProcedureSettings`).
        roles: the roles a point of this procedure may take.
        role_limits: how many points each role takes at most (``None``: any number); an
            editor gives a new point the first role not yet full.
        label: the procedure's short name for humans, e.g. ``"best fit"``, ``"A-H"`` (a
            measuring program is named after it: "RAPID, adaptive A-H").
        summary: one line for humans.
    """

    method: str
    settings_type: type
    roles: tuple[str, ...]
    role_limits: Mapping[str, int | None]
    label: str
    summary: str

    def role_problem(self, roles: Sequence[str], complete: bool) -> str:
        """What is wrong with the points' roles (``""`` when fine); ``complete``: also require
        every role the procedure needs (a plan being edited may be incomplete)."""
        ...

    def assign(self, points: Sequence[RolePoint]) -> list[RolePoint]:
        """The points with roles of this procedure: their own when they fit, else picked from
        their geometry (to calibrate a plan made for another procedure).

        Raises:
            PlanError: the points cannot fill this procedure's roles (the message says why).
        """
        ...

    def run(
        self,
        points: Sequence[RolePoint],
        T_base_wobj_nominal: FloatArray,
        probe: Probe,
        settings: object,
    ) -> ProcedureRun:
        """Measure step by step with ``probe``, each search commanded in the estimate so far."""
        ...

    def estimate(
        self,
        points: Sequence[RolePoint],
        measured: Measured,
        T_base_wobj_nominal: FloatArray,
        settings: object,
    ) -> ProcedureRun:
        """The frame from measurements already taken (``wobjcal calibrate``).

        Raises:
            InputError: a measurement the procedure needs is missing, or the points define no
                frame; ProbeFailedError: the procedure needs a point that was not measured.
        """
        ...

    def adaptive_layout(self, points: Sequence[RolePoint]) -> StatorLayout | None:
        """The layout a robot program needs to run this procedure adaptively (frame updated
        after every step), or ``None`` when programs run every search in the nominal frame."""
        ...


def check_edge_offset(value: float | None) -> None:
    """Raise :class:`calib.errors.PlanError` unless an edge-event offset is finite or None."""
    if value is not None and not math.isfinite(value):
        raise PlanError(f"edge_event_offset_m: must be finite, got {value}")


def edge_offset_of(settings: object) -> float:
    """The edge-event offset a procedure's settings remove from edge searches, metres.

    Every settings struct has ``edge_event_offset_m`` (how far past a face's end the sensor
    reports it; ``None``: not measured, which counts as 0 here; the validation fills it from
    the sensor model, see :func:`planner.sim.setup.resolved_settings`).
    """
    value = getattr(settings, "edge_event_offset_m", None)
    return 0.0 if value is None else float(value)


def edge_corrected(
    points: Sequence[ProbePoint], q_base: FloatArray, T_base_wobj: FloatArray, offset_m: float
) -> FloatArray:
    """``(N, 3)`` recorded points with the edge-event offset removed from the edge searches'
    (moved back along their search direction, taken in ``T_base_wobj``), base frame, m."""
    if not offset_m:
        return q_base
    out = np.array(q_base, dtype=np.float64, copy=True)
    R = np.asarray(T_base_wobj, dtype=np.float64)[:3, :3]
    for i, p in enumerate(points):
        if p.search.kind == "edge" and p.search.edge_direction is not None:
            out[i] -= offset_m * (R @ np.asarray(p.search.edge_direction, dtype=np.float64))
    return out


def count_problem(method: str, roles: Sequence[str], need: Mapping[str, int]) -> str:
    """``""`` when every role in ``need`` occurs exactly that often, else a message."""
    counts = Counter(roles)
    for role, n in need.items():
        if counts[role] != n:
            return f"points: {method} needs {n} {role!r} points, got {counts[role]}"
    return ""


def unknown_role_problem(method: str, roles: Sequence[str], allowed: Sequence[str]) -> str:
    """``""`` when every role is allowed, else a message naming the first bad one."""
    for i, role in enumerate(roles):
        if role not in allowed:
            return f"points[{i}].role: must be one of {list(allowed)} for {method}, got {role!r}"
    return ""
