"""What every calibration procedure provides: the :class:`ProcedureKind` protocol and its types.

A procedure turns probe points with roles into the work-object frame ``T_base_wobj``, either
step by step with a probe callback (:meth:`ProcedureKind.run`: the robot or the simulation
measures as the procedure commands) or from measurements already taken
(:meth:`ProcedureKind.estimate`: ``wobjcal calibrate``). Implementations live one per module in
:mod:`calib.procedures` and are listed in :data:`calib.procedures.PROCEDURES`.
"""

from __future__ import annotations

import itertools
import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from calib.errors import PlanError
from calib.probing import Probe, ProbePoint
from calib.procedure_run import ProcedureRun

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
class LayoutDesign:
    """How ``wobjcal suggest`` designs a layout for a procedure (:mod:`planner.suggest`): what
    differs between procedures there, so suggest reads it from the registry and tests no name.

    Attributes:
        role: the role of every point of a *grown* design (``face_roles`` empty): any number
            of points from 6 up, added until the target holds (best fit: ``"fit"``); such a
            procedure also takes ``--add`` (more points to a plan) and ``--objective time``.
        face_roles: ``((role, n), ...)``: a *face* design instead, exactly ``n`` points of
            each role, the points of one role on one planar face, the faces pairwise far from
            parallel, the roles in measuring order (3-2-1: primary 3, secondary 2, tertiary 1).
            The counts differ from each other, so a face's count names its role.
    """

    role: str = ""
    face_roles: tuple[tuple[str, int], ...] = ()

    def __post_init__(self) -> None:
        counts = [n for _, n in self.face_roles]
        if self.face_roles and (len(set(counts)) != len(counts) or min(counts) < 1):
            raise ValueError(f"face_roles: distinct counts >= 1, got {self.face_roles}")
        if not self.face_roles and not self.role:
            raise ValueError("a grown design needs the role of its points")

    @property
    def grows(self) -> bool:
        """True: any number of points, grown until the target holds (``role`` each)."""
        return not self.face_roles

    @property
    def n_points(self) -> int | None:
        """The points of a face design, ``None`` for a grown one."""
        return sum(n for _, n in self.face_roles) if self.face_roles else None

    def roles_of(self, face_counts: Sequence[int]) -> list[str]:
        """The role of each point of a design, from how many of the design's points lie on
        that point's face (a face design), or ``role`` (a grown one)."""
        if self.grows:
            return [self.role] * len(face_counts)
        by_count = {n: r for r, n in self.face_roles}
        return [by_count[n] for n in face_counts]


@dataclass(frozen=True)
class Steering:
    """How a program that steers a procedure search by search updates its frame
    (:mod:`planner.program.steering`: the smallest motion that puts the points measured so far
    on their nominal faces, the later searches commanded in that estimate).

    Attributes:
        group_sizes: how many points each update adds, in measuring order (3-2-1: ``(3, 2,
            1)``, after the primary, secondary and tertiary points); ``()``: an update after
            every point (the progressive best fit).
    """

    group_sizes: tuple[int, ...] = ()

    def update_counts(self, n_points: int) -> tuple[int, ...]:
        """How many of the first points each update fits, for ``n_points`` in measuring order
        (``()``: a layout of another size, which this steering does not update)."""
        if not self.group_sizes:
            return tuple(range(1, n_points + 1))
        if n_points != sum(self.group_sizes):
            return ()
        return tuple(itertools.accumulate(self.group_sizes))


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
        design: how ``wobjcal suggest`` designs its layouts; ``None``: suggest does not
            (the A-H layout follows the stator's geometry, section 3.2 of the paper).
        steering: how a program that steers it search by search updates its frame (a
            controller that runs it adaptively, :attr:`planner.program.controllers.Controller.
            adaptive_methods`); ``None``: no such program (it runs in the nominal frame, or
            adapts by its own layout, :meth:`adaptive_layout`).
        published: the published half-widths of this procedure on the part it was published
            for, display units, by ``(report row key, confidence percent)`` (the paper's Table
            1 for A-H), shown beside a validation of a built-in part with exact geometry;
            ``None``: none.
        edge_rows: what an edge search's point counts for in this procedure's frame, and so in
            the gross-error screen of its measurements
            (:func:`calib.estimators.layout.constraint_set`): ``"edge"``, its edge coordinate
            only (its coordinate across the face it slides over is the command's); ``"both"``,
            also that coordinate (A-H and 3-2-1 put an edge point on its face by role).
    """

    method: str
    settings_type: type
    roles: tuple[str, ...]
    role_limits: Mapping[str, int | None]
    label: str
    summary: str
    design: LayoutDesign | None
    steering: Steering | None
    published: Mapping[tuple[str, float], float] | None
    edge_rows: Literal["both", "edge"]

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
