"""The cycle time of a measuring program: how long the robot takes to run it.

The model (``docs/cycle_time.md``), step by step as the program runs (:class:`MeasuringProgram`):

- a **joint move** into each point, from the safe start of the point the program probed before
  it, through the point's vias in order, to its safe start: each leg synchronised, every joint
  with a trapezoidal velocity profile (accelerate at ``a``, cruise at ``v``, decelerate at
  ``a``: the joint's limits as the controller's program commands its joint moves,
  :class:`planner.program.controllers.JointMoveSpeed`, with RAPID's TCP and tool speed
  caps; a triangle when the leg is too short to reach ``v``), and the slowest joint sets the
  leg's time (the others are slowed to arrive with it, which needs no
  more speed or acceleration): ``t = d / v + v / a`` when ``d >= v^2 / a``, else
  ``t = 2 sqrt(d / a)``, for the joint's travel ``d``. Every leg ends in a fine point (the
  programs move through their vias with fine points): no blending;
- each **search** at its programmed speed (``points[i].search.speed_m_s``) from where the
  program starts it (the safe start; an edge search from the measured face point or the
  measured point the procedure names), for the travel to the nominal face or edge (the part
  where it should be: the nominal time) and for its whole commanded length (the part as far
  as the search allows, or a miss: the upper bound);
- the **linear moves that are no search** (the retreat to the safe start after a point, the
  move to a measured start) at :data:`LINEAR_SPEED_M_S`, what every exporter commands;
- a **settle** time per search stop and an **I/O** time per recorded measurement
  (:class:`calib.models.cycle.CycleSettings`, the plan's ``validation.cycle``);
- the A-H program's **x-offset run** after its frame (:attr:`MeasuringProgram.xoffset_run`):
  per measurement a joint move to its start, a search along -x of the calibrated frame at D's
  speed, the retreat, a settle and an I/O time.

Left out: the move to the first point (from wherever the robot stands) and any move after the
last one, the time the controller computes (the estimate updates: milliseconds), the linear
moves' acceleration ramps and the controller's own path planning (zone data, blending, speed
overrides; see ``docs/cycle_time.md``).

Pure: this module takes joint values and limits; :mod:`planner.check.cycle` gathers them from
the check and the robot's URDF.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.models.cycle import CycleSettings
from calib.paper.xoffset import xoffset_probe_points
from calib.procedures import procedure_kind
from planner.program.controllers import JointMoveSpeed
from planner.program.model import FACE_APPROACH, MeasuringProgram, MoveStep, SearchStep
from planner.program.searches import ProgramSearch, program_searches

FloatArray = NDArray[np.float64]

#: Speed of the linear moves that are no search, m/s: what every exporter commands for them
#: (RAPID ``vApproach`` 100 mm/s, KRL ``$VEL.CP=0.1``, URScript ``movel`` ``v=0.1``, FANUC
#: ``100mm/sec``).
LINEAR_SPEED_M_S = 0.1
#: Velocity limit of a joint whose URDF ``<limit>`` gives none (or 0), rad/s (m/s for a sliding
#: joint): 1 rad/s (57 deg/s) is below every axis of an industrial arm, so a robot without
#: limits is not made to look faster than it is.
DEFAULT_JOINT_VELOCITY_RAD_S = 1.0


@dataclass(frozen=True)
class JointMotionLimits:
    """What bounds the joint moves, as the controller's program commands them.

    Attributes:
        joint_names: ``(n,)`` the moving joints, base to tip.
        velocity: ``(n,)`` each joint's velocity, rad/s (m/s sliding): its limit, scaled and
            capped as the program commands it.
        acceleration: ``(n,)`` each joint's acceleration, rad/s^2 (m/s^2 sliding).
        defaulted: the joints whose URDF gives no velocity limit
            (:data:`DEFAULT_JOINT_VELOCITY_RAD_S` used for them).
        tcp_speed_m_s: a cap on the TCP's speed along its path, m/s (``None``: none).
        tool_speed_rad_s: a cap on the tool's reorientation speed, rad/s (``None``: none).
        tool_path: ``(N, n)`` joint values -> ``(N, 4, 4)`` TCP frames (any fixed frame),
            for the two caps; ``None``: they are not applied.
        how: the controller's joint-move command, for the report.
    """

    joint_names: tuple[str, ...]
    velocity: FloatArray
    acceleration: FloatArray
    defaulted: tuple[str, ...] = ()
    tcp_speed_m_s: float | None = None
    tool_speed_rad_s: float | None = None
    tool_path: Callable[[FloatArray], FloatArray] | None = None
    how: str = ""


def joint_motion_limits(
    joint_names: Sequence[str],
    velocities: Sequence[float],
    acceleration: float,
    speed: JointMoveSpeed | None = None,
    tool_path: Callable[[FloatArray], FloatArray] | None = None,
) -> JointMotionLimits:
    """The limits of joints ``joint_names`` with the URDF's ``velocities`` (rad/s; 0 or not
    finite: none given, :data:`DEFAULT_JOINT_VELOCITY_RAD_S` used) and one ``acceleration``
    for all (rad/s^2, the plan's ``validation.cycle.joint_acceleration_rad_s2``), as the
    controller's joint-move command ``speed`` scales and caps them
    (:attr:`planner.program.controllers.Controller.joint_move`; ``None``: the limits as they
    are); ``tool_path`` gives the TCP frames its TCP and tool speed caps need.

    Raises:
        InputError: the counts differ, or the acceleration is not a positive number.
    """
    names = tuple(joint_names)
    if len(velocities) != len(names):
        raise InputError(f"{len(velocities)} joint velocities for {len(names)} joints {names}")
    if not (math.isfinite(acceleration) and acceleration > 0.0):
        raise InputError(f"joint acceleration must be > 0 rad/s^2, got {acceleration!r}")
    v = np.array([float(x) for x in velocities], dtype=np.float64)
    missing = ~np.isfinite(v) | (v <= 0.0)
    v[missing] = DEFAULT_JOINT_VELOCITY_RAD_S
    defaulted = tuple(n for n, m in zip(names, missing, strict=True) if m)
    speed = speed or JointMoveSpeed()
    v = v * speed.velocity_fraction
    if speed.velocity_rad_s is not None:
        v = np.minimum(v, speed.velocity_rad_s)
    acc = speed.acceleration_rad_s2 if speed.acceleration_rad_s2 is not None else acceleration
    return JointMotionLimits(
        names,
        v,
        np.full(len(names), float(acc)),
        defaulted,
        speed.tcp_speed_m_s,
        speed.tool_speed_rad_s,
        tool_path,
        speed.how,
    )


#: Joint-space step of the TCP path sampled for the TCP and tool speed caps, rad.
PATH_STEP_RAD = math.radians(1.0)


def tool_path_time(q_from: FloatArray, q_to: FloatArray, limits: JointMotionLimits) -> float:
    """The time the TCP and tool speed caps need for the joint move from ``q_from`` to
    ``q_to`` (rad), s: its TCP path length over ``tcp_speed_m_s`` and its tool rotation over
    ``tool_speed_rad_s`` (the path sampled every :data:`PATH_STEP_RAD` of the largest joint
    travel; 0 without caps)."""
    if limits.tool_path is None or (
        limits.tcp_speed_m_s is None and limits.tool_speed_rad_s is None
    ):
        return 0.0
    steps = max(1, math.ceil(float(np.abs(q_to - q_from).max(initial=0.0)) / PATH_STEP_RAD))
    qs = q_from + np.linspace(0.0, 1.0, steps + 1)[:, None] * (q_to - q_from)
    T = np.asarray(limits.tool_path(qs), dtype=np.float64)
    t = 0.0
    if limits.tcp_speed_m_s:
        length = float(np.linalg.norm(np.diff(T[:, :3, 3], axis=0), axis=1).sum())
        t = length / limits.tcp_speed_m_s
    if limits.tool_speed_rad_s:
        R = T[:, :3, :3]
        rel = np.einsum("kji,kjl->kil", R[:-1], R[1:])  # R_k^T R_{k+1}
        cos = np.clip((np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
        t = max(t, float(np.arccos(cos).sum()) / limits.tool_speed_rad_s)
    return t


def trapezoid_time(distance: ArrayLike, v_max: ArrayLike, a_max: ArrayLike) -> FloatArray:
    """Shortest time to travel ``distance`` from rest to rest, s (elementwise): accelerate at
    ``a_max``, cruise at ``v_max``, decelerate at ``a_max`` (``d / v + v / a``), or a triangle
    when ``d < v^2 / a`` (``2 sqrt(d / a)``). Units: rad, rad/s, rad/s^2 (or m)."""
    d = np.abs(np.asarray(distance, dtype=np.float64))
    v = np.asarray(v_max, dtype=np.float64)
    a = np.asarray(a_max, dtype=np.float64)
    cruise = d >= v * v / a
    t = np.where(cruise, d / v + v / a, 2.0 * np.sqrt(d / a))
    out: FloatArray = np.asarray(t, dtype=np.float64)
    return out


def joint_move_time(q_from: ArrayLike, q_to: ArrayLike, limits: JointMotionLimits) -> float:
    """Time of the synchronised joint move from ``q_from`` to ``q_to`` (rad), s: the slowest
    joint's :func:`trapezoid_time`.

    Raises:
        InputError: a configuration does not have one value per joint.
    """
    a = np.asarray(q_from, dtype=np.float64).reshape(-1)
    b = np.asarray(q_to, dtype=np.float64).reshape(-1)
    n = len(limits.joint_names)
    if len(a) != n or len(b) != n:
        raise InputError(f"joint moves need {n} joint values, got {len(a)} and {len(b)}")
    t = trapezoid_time(b - a, limits.velocity, limits.acceleration)
    return max(float(t.max(initial=0.0)), tool_path_time(a, b, limits))


@dataclass(frozen=True)
class CycleRow:
    """One visit of the program (the joint move into a point and its searches), or the x-offset
    run, timed.

    Attributes:
        key: the visit's search key (``"C2"`` for a retake) or ``"x-offset run"``.
        point_id: the plan's point id (``""`` for the x-offset run).
        searches: how many searches the visit runs.
        move_s: its joint moves (through the vias), s; ``None`` when a pose is not known (a
            point the check found no pose for): not timed.
        linear_s: its linear moves that are no search (retreats, the move to a measured start),
            for searches stopping at the nominal face, s.
        linear_max_s: the same for searches running their whole length, s.
        search_s: its searches to the nominal face or edge, s.
        search_max_s: its searches over their whole commanded length, s.
        settle_s: its settle times (one per search stop), s.
        io_s: its I/O times (one per recorded measurement), s.
    """

    key: str
    point_id: str
    searches: int
    move_s: float | None
    linear_s: float
    linear_max_s: float
    search_s: float
    search_max_s: float
    settle_s: float
    io_s: float

    @property
    def total_s(self) -> float:
        """The row's time with searches stopping at the nominal face, s (an untimed move
        counted 0)."""
        return (self.move_s or 0.0) + self.linear_s + self.search_s + self.settle_s + self.io_s

    @property
    def total_max_s(self) -> float:
        """The row's time with every search running its whole length, s."""
        moves = (self.move_s or 0.0) + self.linear_max_s
        return moves + self.search_max_s + self.settle_s + self.io_s

    def to_json(self) -> dict[str, Any]:
        """The row, times in s."""
        return {
            "key": self.key,
            "point": self.point_id,
            "searches": self.searches,
            "move_s": self.move_s,
            "linear_s": self.linear_s,
            "linear_max_s": self.linear_max_s,
            "search_s": self.search_s,
            "search_max_s": self.search_max_s,
            "settle_s": self.settle_s,
            "io_s": self.io_s,
            "total_s": self.total_s,
            "total_max_s": self.total_max_s,
        }


@dataclass(frozen=True)
class CycleTime:
    """The cycle time of one measuring program.

    Attributes:
        program: the program's name, e.g. ``"RAPID, adaptive A-H"``.
        rows: one :class:`CycleRow` per visit, in program order, then the x-offset run.
        settings: the timing figures used (the plan's ``validation.cycle``).
        limits: the joint limits used.
        linear_speed_m_s: speed of the linear moves that are no search, m/s.
        notes: what the estimate leaves out or assumes beyond the model (joints without a
            URDF velocity limit, moves not timed), one line each.
    """

    program: str
    rows: tuple[CycleRow, ...]
    settings: CycleSettings
    limits: JointMotionLimits
    linear_speed_m_s: float = LINEAR_SPEED_M_S
    notes: tuple[str, ...] = ()

    @property
    def total_s(self) -> float:
        """The program's time with every search stopping at the nominal face, s."""
        return float(sum(r.total_s for r in self.rows))

    @property
    def total_max_s(self) -> float:
        """The program's time with every search running its whole length, s."""
        return float(sum(r.total_max_s for r in self.rows))

    @property
    def untimed(self) -> tuple[str, ...]:
        """Keys of the visits whose joint moves are not timed (no pose)."""
        return tuple(r.key for r in self.rows if r.move_s is None)

    def model_text(self) -> str:
        """The model in one line, with its constants (what a program header says)."""
        v = self.limits
        dflt = ""
        if v.defaulted:
            dflt = f", {DEFAULT_JOINT_VELOCITY_RAD_S:g} rad/s where it gives none"
        s = self.settings
        how = v.how or "at the URDF limits"
        return (
            f"synchronised trapezoidal joint moves as the program commands them ({how}: "
            f"joints at {_joint_speeds(v)}{dflt}, {float(v.acceleration.max()):g} rad/s^2"
            f"{_caps(v)}), fine points, no blending; "
            "searches at their programmed speed to the nominal face; other linear moves at "
            f"{self.linear_speed_m_s * 1e3:g} mm/s; settle {s.settle_s:g} s per search, "
            f"I/O {s.io_s:g} s per recorded point; the move to the first point not counted"
        )

    def summary(self) -> str:
        """One line for a program's header: ``"estimated cycle time 207 s (up to 370 s when
        every search runs its whole length; model: ...)"``, the model's constants in short."""
        s = self.settings
        head = f"estimated cycle time {self.total_s:.0f} s"
        upper = f"up to {self.total_max_s:.0f} s when every search runs its whole length"
        untimed = (
            f"; moves into {', '.join(self.untimed)} not timed (no pose)" if self.untimed else ""
        )
        dflt = " (some assumed)" if self.limits.defaulted else ""
        how = self.limits.how or "at the URDF's velocity limits"
        if "rad/s^2" not in how:  # the plan's acceleration, where the command sets none
            how += f", {float(self.limits.acceleration.max()):g} rad/s^2"
        model = (
            f"joint moves trapezoidal, {how}{dflt}, searches at their speed to the nominal "
            f"face, linear moves {self.linear_speed_m_s * 1e3:g} mm/s, settle {s.settle_s:g} s "
            f"per search, I/O {s.io_s:g} s per point, no blending, first move not counted; "
            "see wobjcal docs/cycle_time.md"
        )
        return f"{head} ({upper}{untimed}; model: {model})"

    def to_json(self) -> dict[str, Any]:
        """The breakdown as ``wobjcal check --json`` gives it (times in s)."""
        return {
            "program": self.program,
            "total_s": self.total_s,
            "total_max_s": self.total_max_s,
            "move_s": float(sum(r.move_s or 0.0 for r in self.rows)),
            "linear_s": float(sum(r.linear_s for r in self.rows)),
            "search_s": float(sum(r.search_s for r in self.rows)),
            "settle_s": float(sum(r.settle_s for r in self.rows)),
            "io_s": float(sum(r.io_s for r in self.rows)),
            "searches": int(sum(r.searches for r in self.rows)),
            "untimed": list(self.untimed),
            "model": self.model_text(),
            "constants": {
                "joint_move": self.limits.how,
                "joint_velocity_rad_s": [float(x) for x in self.limits.velocity],
                "joint_acceleration_rad_s2": float(self.limits.acceleration.max()),
                "tcp_speed_m_s": self.limits.tcp_speed_m_s,
                "tool_speed_rad_s": self.limits.tool_speed_rad_s,
                "linear_speed_m_s": self.linear_speed_m_s,
                "settle_s": self.settings.settle_s,
                "io_s": self.settings.io_s,
            },
            "notes": list(self.notes),
            "rows": [r.to_json() for r in self.rows],
        }


def _joint_speeds(v: JointMotionLimits) -> str:
    """The joints' commanded speeds in short, deg/s."""
    deg = [f"{math.degrees(x):.0f}" for x in v.velocity]
    return (deg[0] if len(set(deg)) == 1 else "/".join(deg)) + " deg/s"


def _caps(v: JointMotionLimits) -> str:
    """The TCP and tool speed caps in short (``""`` without)."""
    out = ""
    if v.tcp_speed_m_s:
        out += f", TCP at most {v.tcp_speed_m_s * 1e3:g} mm/s"
    if v.tool_speed_rad_s:
        out += f", tool at most {math.degrees(v.tool_speed_rad_s):g} deg/s"
    return out


@dataclass
class _Visit:
    """The times of one visit, added up as its searches are walked."""

    key: str
    point_id: str
    move_s: float | None
    searches: int = 0
    linear: float = 0.0
    linear_max: float = 0.0
    search: float = 0.0
    search_max: float = 0.0
    recorded: int = 0

    def row(self, settings: CycleSettings) -> CycleRow:
        return CycleRow(
            key=self.key,
            point_id=self.point_id,
            searches=self.searches,
            move_s=self.move_s,
            linear_s=self.linear,
            linear_max_s=self.linear_max,
            search_s=self.search,
            search_max_s=self.search_max,
            settle_s=self.searches * settings.settle_s,
            io_s=self.recorded * settings.io_s,
        )


def _travel(search: ProgramSearch) -> tuple[float, float]:
    """``(to the nominal face or edge, whole length)`` of a search, m."""
    c = search.command
    nominal = float((np.asarray(c.nominal_m) - np.asarray(c.start_m)) @ np.asarray(c.direction))
    return min(max(nominal, 0.0), float(c.length_m)), float(c.length_m)


def _path_time(
    q_prev: FloatArray | None,
    vias: Sequence[ArrayLike],
    q_to: FloatArray | None,
    limits: JointMotionLimits,
) -> float | None:
    """Time of the joint moves from ``q_prev`` through ``vias`` to ``q_to``; the leg from an
    unknown start is not counted (the program's first move), an unknown end makes it
    ``None``."""
    if q_to is None:
        return None
    stops = [np.asarray(v, dtype=np.float64) for v in vias] + [q_to]
    if q_prev is not None:
        stops.insert(0, q_prev)
    return float(sum(joint_move_time(a, b, limits) for a, b in itertools.pairwise(stops)))


def xoffset_starts_wobj(program: MeasuringProgram) -> tuple[tuple[str, FloatArray], ...]:
    """``((id, start), ...)`` of the x-offset run's searches in the order the program runs them
    (level by level, tooth by tooth), each start ``start_offset_m`` outside the side face in
    +x of the nominal frame, wobj, m; ``()`` without an x-offset run."""
    run = program.xoffset_run
    if run is None:
        return ()
    layout = procedure_kind(program.settings).adaptive_layout(list(program.points))
    if layout is None:
        return ()
    face_x = float(layout.face_coords_wobj[0])
    rows = xoffset_probe_points(run.grid, run.layers, run.teeth)
    return tuple(
        (p.id, np.array([face_x + run.start_offset_m, p.position_m[1], p.position_m[2]]))
        for row in rows
        for p in row
    )


def cycle_time(
    program: MeasuringProgram,
    q_safe: Mapping[str, ArrayLike | None],
    vias_q: Mapping[str, Sequence[ArrayLike]],
    speeds_m_s: Mapping[str, float],
    limits: JointMotionLimits,
    settings: CycleSettings,
    *,
    measured_starts_wobj: Mapping[str, ArrayLike] | None = None,
    xoffset_q: Sequence[ArrayLike | None] = (),
    linear_speed_m_s: float = LINEAR_SPEED_M_S,
) -> CycleTime:
    """The cycle time of ``program`` (module docstring).

    Args:
        program: the measuring program.
        q_safe: ``{point id: (n,)}`` joint values at each point's safe start, rad (the check's
            :attr:`planner.check.results.PointCheck.q_safe`; ``None``: no pose).
        vias_q: ``{point id: [(n,), ...]}`` the point's vias, in order, rad.
        speeds_m_s: ``{point id: search speed}``, m/s.
        limits: the joint limits.
        settings: the settle, I/O and acceleration figures.
        measured_starts_wobj: ``{point id: start}`` of the edge searches the program starts at
            a measured point (``edge_start_from_measured``), wobj, m.
        xoffset_q: joint values at each start of :func:`xoffset_starts_wobj`, in order, rad
            (``None``: no IK solution; that move is not timed).
        linear_speed_m_s: speed of the linear moves that are no search, m/s.

    Raises:
        InputError: a search speed is missing or not positive; joint values of the wrong size.
    """
    by_id = {rp.point.id: rp.point for rp in program.points}
    starts = measured_starts_wobj or {}
    eye = np.eye(4)
    visits: list[_Visit] = []
    q_prev: FloatArray | None = None

    def q_of(pid: str) -> FloatArray | None:
        q = q_safe.get(pid)
        return None if q is None else np.asarray(q, dtype=np.float64)

    for step in program.steps:
        if isinstance(step, MoveStep):
            q_to = q_of(step.point_id)
            move = _path_time(q_prev, vias_q.get(step.point_id, ()), q_to, limits)
            visits.append(_Visit(step.point_id, step.point_id, move))
            q_prev = q_to
            continue
        if not isinstance(step, SearchStep):
            continue
        visit = visits[-1]
        visit.key = step.key.removesuffix(FACE_APPROACH)
        point = by_id[step.point_id]
        speed = float(speeds_m_s.get(step.point_id, 0.0))
        if not (math.isfinite(speed) and speed > 0.0):
            raise InputError(f"point {step.point_id}: search speed must be > 0 m/s, got {speed}")
        measured = starts.get(step.point_id) if step.start == "measured point" else None
        legs = program_searches(point, eye, program.safety, measured)
        if step.key.endswith(FACE_APPROACH):  # the approach to the face; the edge search next
            nominal, full = _travel(legs[0])
            visit.search += nominal / speed
            visit.search_max += full / speed
        elif step.kind == "edge":
            if measured is not None:  # the straight move to the measured start
                visit.linear += legs[0].command.length_m / linear_speed_m_s
                visit.linear_max += legs[0].command.length_m / linear_speed_m_s
            nominal, full = _travel(legs[1])
            visit.search += nominal / speed
            visit.search_max += full / speed
            edge = legs[1].command
            safe = np.asarray(legs[2].command.nominal_m)
            end = np.asarray(edge.start_m) + edge.length_m * np.asarray(edge.direction)
            visit.linear += legs[2].command.length_m / linear_speed_m_s
            visit.linear_max += float(np.linalg.norm(safe - end)) / linear_speed_m_s
        else:  # an approach point: the search from the safe start, the retreat along it
            nominal, full = _travel(legs[0])
            visit.search += nominal / speed
            visit.search_max += full / speed
            visit.linear += nominal / linear_speed_m_s
            visit.linear_max += full / linear_speed_m_s
        visit.searches += 1
        visit.recorded += int(step.recorded)
    rows = [v.row(settings) for v in visits]
    rows += _xoffset_rows(
        program, q_prev, xoffset_q, speeds_m_s, limits, settings, linear_speed_m_s
    )
    notes = []
    if limits.defaulted:
        notes.append(
            f"the URDF gives no velocity limit for {', '.join(limits.defaulted)}: "
            f"{DEFAULT_JOINT_VELOCITY_RAD_S:g} rad/s assumed"
        )
    untimed = [r.key for r in rows if r.move_s is None]
    if untimed:
        notes.append(f"moves into {', '.join(untimed)} not timed: no pose (see the check)")
    return CycleTime(program.name, tuple(rows), settings, limits, linear_speed_m_s, tuple(notes))


def _xoffset_rows(
    program: MeasuringProgram,
    q_prev: FloatArray | None,
    xoffset_q: Sequence[ArrayLike | None],
    speeds_m_s: Mapping[str, float],
    limits: JointMotionLimits,
    settings: CycleSettings,
    linear_speed_m_s: float,
) -> list[CycleRow]:
    """The x-offset run as one row (``[]`` without one): per search a joint move from the
    previous start, the search at D's speed (``start_offset_m`` to the nominal face, plus
    ``overtravel_m`` at most), the retreat, a settle and an I/O time."""
    run = program.xoffset_run
    starts = xoffset_starts_wobj(program)
    if run is None or not starts:
        return []
    if len(xoffset_q) != len(starts):
        raise InputError(
            f"the x-offset run has {len(starts)} searches, got {len(xoffset_q)} joint values"
        )
    d_id = next(rp.point.id for rp in program.points if rp.role == "D")
    speed = float(speeds_m_s[d_id])
    move: float | None = 0.0
    for q in xoffset_q:
        q_to = None if q is None else np.asarray(q, dtype=np.float64)
        leg = _path_time(q_prev, (), q_to, limits)
        move = None if leg is None or move is None else move + leg
        q_prev = q_to
    n = len(starts)
    nominal, full = run.start_offset_m, run.start_offset_m + run.overtravel_m
    return [
        CycleRow(
            key="x-offset run",
            point_id="",
            searches=n,
            move_s=move,
            linear_s=n * nominal / linear_speed_m_s,
            linear_max_s=n * full / linear_speed_m_s,
            search_s=n * nominal / speed,
            search_max_s=n * full / speed,
            settle_s=n * settings.settle_s,
            io_s=n * settings.io_s,
        )
    ]
