"""What every robot-program exporter needs, independent of the robot language.

An :class:`ExportJob` holds the nominal work object, the sensor tool and, per probe point, the
sensor-TCP pose at the start and at the end of its search, all in the wobj frame (metres), with
the IK branch's ABB configuration when known. The exporters (``rapid``, ``krl``, ``urscript``)
only format it. :func:`build_job` makes a job from a plan, the tool's TCP and (optionally) the
orientations and configurations chosen by ``wobjcal check``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import msgspec
import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import check_transform, invert_transform, make_transform
from calib.plan.file import Plan, plan_digest
from calib.probing import SearchCommand
from planner.export.text import module_name
from planner.program.build import (
    AdaptiveSpec,
    adaptive_spec,
    ah_base_problem,
    ah_base_sign,
    measuring_program,
    safety_spec,
)
from planner.program.controllers import CONTROLLERS
from planner.program.cycle_time import CycleTime
from planner.program.model import MeasuringProgram
from planner.program.safety import SafetySpec
from planner.program.searches import safe_and_face_wobj

FloatArray = NDArray[np.float64]
#: ABB ``confdata`` (cf1, cf4, cf6, cfx).
ConfData = tuple[int, int, int, int]


@dataclass(frozen=True)
class ArmPose:
    """The robot's joint values and configuration at one target (from the checked pose).

    Attributes:
        q_rad: ``(n,)`` joint values, rad, in the robot URDF's joint directions.
        front: the wrist centre lies in front of axis 1 (FANUC ``T``, KUKA status bit 0 = 0).
        elbow_up: the elbow bent forward (FANUC ``U``, KUKA status bit 1 = 1).
        wrist_flipped: axis 5 bent against ABB's positive direction (FANUC ``F``, KUKA status
            bit 2 = 1); see :func:`planner.robot.kinematics.branches.posture`.
    """

    q_rad: tuple[float, ...]
    front: bool
    elbow_up: bool
    wrist_flipped: bool


#: The targets of one search a writer may place, each with its :class:`ArmPose`.
TARGET_KINDS = ("start", "end", "safe", "face")


@dataclass(frozen=True)
class TargetPair:
    """The search of one probe point, as the robot program runs it.

    Attributes:
        point_id: the plan's point id, e.g. ``"A"``.
        role: the point's role in the procedure.
        kind: ``"approach"`` or ``"edge"``.
        T_wobj_start: ``(4, 4)`` sensor-TCP pose at the start of the search, wobj frame, m.
        T_wobj_end: ``(4, 4)`` sensor-TCP pose at the end of the search travel, wobj frame, m.
        speed_m_s: search speed, m/s.
        confdata: ABB configuration (cf1, cf4, cf6, cfx) of the IK branch, or ``None``.
        normal_wobj: ``(3,)`` outward normal of the face the sensor looks at, wobj frame.
        T_wobj_safe: ``(4, 4)`` where the program starts the (first) approach search, wobj
            frame, m: the plan's start moved out along the normal to the safe clearance
            (:class:`planner.program.safety.SafetySpec`); for an edge search, the edge start
            moved out along the normal (the approach to the face the edge search runs along).
        T_wobj_face: ``(4, 4)`` end of that approach search, wobj frame, m (for an approach
            point the plan's end, for an edge point past the face by the safe overtravel).
        arm: ``{kind: ArmPose}`` the robot's joint values and configuration at each target of
            :data:`TARGET_KINDS` (from IK next to the checked pose), or ``None`` without a
            check (or for robots that are not 6-axis OPW arms).
        vias_q_rad: the plan's via points of this point (``points[i].vias``), in order: joint
            values, rad, URDF joint order and directions. Every writer moves through them with
            joint moves, fine points, before the approach to the safe start.
    """

    point_id: str
    role: str
    kind: str
    T_wobj_start: FloatArray
    T_wobj_end: FloatArray
    speed_m_s: float
    confdata: ConfData | None = None
    normal_wobj: tuple[float, float, float] = (0.0, 0.0, 1.0)
    T_wobj_safe: FloatArray | None = None
    T_wobj_face: FloatArray | None = None
    arm: Mapping[str, ArmPose] | None = None
    vias_q_rad: tuple[tuple[float, ...], ...] = ()

    def vias_deg(self, language: str, n_axes: int = 6) -> list[tuple[float, ...]]:
        """The vias in degrees for a controller of ``n_axes`` axes (the URDF's joint order
        and directions: the exporters apply no joint offsets).

        Raises:
            InputError: a via does not have ``n_axes`` joint values (names the point and via).
        """
        out = []
        for k, q in enumerate(self.vias_q_rad, start=1):
            if len(q) != n_axes:
                raise InputError(
                    f"{language} export: point {self.point_id}, via {k}: {len(q)} joint values, "
                    f"the program writes {n_axes}-axis joint targets"
                )
            out.append(tuple(float(np.degrees(v)) for v in q))
        return out

    def target(self, kind: str) -> FloatArray:
        """``(4, 4)`` the target of ``kind`` (one of :data:`TARGET_KINDS`), wobj frame."""
        return {
            "start": self.T_wobj_start,
            "end": self.T_wobj_end,
            "safe": self.safe_start,
            "face": self.face_end,
        }[kind]

    def arm_pose(self, kind: str) -> ArmPose | None:
        """The :class:`ArmPose` at the target of ``kind``, or ``None`` when not known."""
        return None if self.arm is None else self.arm.get(kind)

    @property
    def safe_start(self) -> FloatArray:
        """``(4, 4)`` start of the (first) approach search, wobj frame (the plan's if unset)."""
        return self.T_wobj_start if self.T_wobj_safe is None else self.T_wobj_safe

    @property
    def face_end(self) -> FloatArray:
        """``(4, 4)`` end of the (first) approach search, wobj frame (the plan's if unset)."""
        return self.T_wobj_end if self.T_wobj_face is None else self.T_wobj_face

    @property
    def edge_direction_wobj(self) -> FloatArray:
        """``(3,)`` unit direction of the search, start to end, wobj frame."""
        d = self.T_wobj_end[:3, 3] - self.T_wobj_start[:3, 3]
        return d / np.linalg.norm(d)

    @property
    def length_m(self) -> float:
        """Search travel, metres."""
        return float(np.linalg.norm(self.T_wobj_end[:3, 3] - self.T_wobj_start[:3, 3]))


@dataclass(frozen=True)
class ToolData:
    """The robot-held sensor tool.

    Attributes:
        T_flange_tcp: ``(4, 4)`` pose of the sensor TCP in the flange frame, m.
        mass_kg: tool mass, kg.
        cog_m: ``(3,)`` centre of gravity in the flange frame, m.
    """

    T_flange_tcp: FloatArray
    mass_kg: float = 5.0
    cog_m: tuple[float, float, float] = (0.0, 0.0, 0.1)


@dataclass(frozen=True)
class CheckStatus:
    """What ``wobjcal check`` said about the program a job writes: every program's header says
    it (:func:`check_header`).

    Attributes:
        checked: the job was built from a check of the plan in its cell for this controller
            (``False``: built without one, e.g. ``wobjcal export --no-check`` or a job made in
            code).
        refused: ids of the points the check refuses, in plan order.
        problems: what refuses the plan besides its points, one line each: the check's error
            (``"error: ..."``) and the procedure's layout problem (``"layout: ..."``, known
            without a check too).
        reasons: why each refused point is refused, ``"P3: ..."``, in plan order (the headers
            of a program exported anyway say them).
    """

    checked: bool = False
    refused: tuple[str, ...] = ()
    problems: tuple[str, ...] = ()
    reasons: tuple[str, ...] = ()

    @property
    def passed(self) -> bool:
        """The check ran and refuses nothing."""
        return self.checked and not self.refused and not self.problems


@dataclass(frozen=True)
class ExportJob:
    """Everything an exporter writes.

    Attributes:
        name: identifier-safe program/module name, e.g. ``"WobjcalStatorSectionAh"``.
        plan_name: the plan's name (for comments).
        method: the plan's procedure.
        T_base_wobj: ``(4, 4)`` nominal work-object frame in the robot base frame (the
            chain's base link, as the cell has it), m.
        tool: the sensor tool.
        targets: one :class:`TargetPair` per point, in plan order.
        sensor_input: name of the sensor's digital input (RAPID signal, KRL/UR input number).
        safety: the misplacement tolerance the safe starts are computed for.
        adaptive: the A-H specifics the adaptive programs are written from (searches
            commanded in the frame estimated so far; ``beta1`` in the controller's base frame,
            :func:`planner.program.build.ah_base_sign`), or ``None`` when no controller runs the
            plan adaptively; a writer uses it only when its own program is adaptive.
        programs: the measuring program of every controller, by controller name: what each
            writer serialises (:meth:`program`).
        program_errors: why a controller has no program (its adaptive procedure refuses the
            layout), by controller name.
        plan_digest: :func:`calib.plan.file.plan_digest` of the plan (``""``: not known, a job
            made in code); every header carries it as ``plan digest <16 hex digits>``.
        check: what ``wobjcal check`` said about the program (:class:`CheckStatus`; the
            default: built without a check).
        cycle_times: the estimated cycle time of each controller's program, by controller
            name (:mod:`planner.check.cycle`; from the check's poses, so only with a check):
            every header says it (:func:`cycle_header`).
        T_base_controller: ``(4, 4)`` the controller's base frame in the robot base frame
            (:mod:`planner.robot.controller_base`; identity: the same frame). The writers
            declare the work object in the controller's frame, :attr:`T_controller_wobj`.
        controller_base: which frame that is, one sentence for the headers (``""``: the robot
            base frame itself, nothing to say).
        sensor_kind: the plan's sensor (``"proximity"``, ``"touch"``), as the headers name it
            (:attr:`sensor_words`).
    """

    name: str
    plan_name: str
    method: str
    T_base_wobj: FloatArray
    tool: ToolData
    targets: tuple[TargetPair, ...]
    sensor_input: str = "diSensor"
    safety: SafetySpec = field(default_factory=SafetySpec)
    adaptive: AdaptiveSpec | None = None
    programs: Mapping[str, MeasuringProgram] = field(default_factory=dict)
    program_errors: Mapping[str, str] = field(default_factory=dict)
    plan_digest: str = ""
    check: CheckStatus = field(default_factory=CheckStatus)
    cycle_times: Mapping[str, CycleTime] = field(default_factory=dict)
    T_base_controller: FloatArray = field(default_factory=lambda: np.eye(4))
    controller_base: str = ""
    sensor_kind: str = "proximity"

    @property
    def sensor_words(self) -> str:
        """The sensor in words for the program headers, e.g. ``"proximity sensor"``."""
        return "touch probe" if self.sensor_kind == "touch" else f"{self.sensor_kind} sensor"

    @property
    def T_controller_wobj(self) -> FloatArray:
        """``(4, 4)`` the nominal work object in the controller's base frame, m: what every
        program declares (``wobjdata``, ``BASE_DATA``, ``wobj``, ``PR[1]``)."""
        return invert_transform(self.T_base_controller) @ self.T_base_wobj

    def program(self, fmt: str) -> MeasuringProgram:
        """The measuring program the controller ``fmt`` runs for this job's plan.

        Raises:
            InputError: the controller has no program for the plan (the message says why).
        """
        if fmt in self.programs:
            return self.programs[fmt]
        why = self.program_errors.get(fmt, "the job was built without it")
        raise InputError(f"no {fmt} program for plan {self.plan_name!r}: {why}")


def default_sensor_rotation(
    normal: ArrayLike, edge_direction: ArrayLike | None = None
) -> FloatArray:
    """Sensor orientation in the wobj frame when no check chose one.

    The sensor +z looks into the surface (``-normal``); its +x is the edge direction for an edge
    search, else the wobj axis least aligned with the normal (z, then y) made perpendicular.
    """
    z = -np.asarray(normal, dtype=float)
    z /= np.linalg.norm(z)
    if edge_direction is not None:
        ref = np.asarray(edge_direction, dtype=float)
    else:
        ref = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = ref - (ref @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


def _ah_in_controller_base(
    spec: AdaptiveSpec,
    T_base_controller: FloatArray,
    programs: dict[str, MeasuringProgram],
    errors: dict[str, str],
) -> AdaptiveSpec | None:
    """The A-H specifics as a controller computes them in its own base frame: ``beta1`` with
    the sign :func:`planner.program.build.ah_base_sign` gives; a base turned otherwise refuses
    the adaptive A-H programs (moved from ``programs`` to ``errors``, which this changes)."""
    sign = ah_base_sign(T_base_controller)
    if sign is not None:
        beta1 = sign * spec.settings.beta1_rad
        return replace(spec, settings=msgspec.structs.replace(spec.settings, beta1_rad=beta1))
    for name, program in list(programs.items()):
        if why := ah_base_problem(program, T_base_controller):
            del programs[name]
            errors[name] = why
    return None


def build_job(
    plan: Plan,
    T_base_wobj: ArrayLike,
    tool: ToolData,
    rotations_wobj: Mapping[str, ArrayLike] | None = None,
    confdata: Mapping[str, ConfData] | None = None,
    sensor_input: str = "diSensor",
    check: CheckStatus | None = None,
    T_base_controller: ArrayLike | None = None,
    controller_base: str = "",
) -> ExportJob:
    """The export job of ``plan``.

    Args:
        plan: the plan.
        T_base_wobj: ``(4, 4)`` nominal work object in the robot base frame.
        tool: the sensor tool.
        rotations_wobj: ``{id: (3, 3)}`` sensor-TCP orientation in the wobj frame per point (from
            the check); missing points get :func:`default_sensor_rotation`.
        confdata: ``{id: (cf1, cf4, cf6, cfx)}`` per point (from the check), or ``None``.
        sensor_input: name of the sensor input.
        check: what ``wobjcal check`` said about the program (``None``: built without a
            check).
        T_base_controller: ``(4, 4)`` the controller's base frame in the robot base frame
            (``None``: the same frame).
        controller_base: which frame that is, for the headers (``""``: nothing to say).
    """
    T = check_transform(T_base_wobj, "T_base_wobj")
    T_bc = (
        np.eye(4)
        if T_base_controller is None
        else check_transform(T_base_controller, "T_base_controller")
    )
    rotations = rotations_wobj or {}
    confs = confdata or {}
    safety = safety_spec(plan)
    programs: dict[str, MeasuringProgram] = {}
    errors: dict[str, str] = {}
    for name in CONTROLLERS:
        try:
            programs[name] = measuring_program(plan, name)
        except InputError as exc:  # an adaptive procedure that refuses the layout
            errors[name] = str(exc)
    try:
        spec = adaptive_spec(plan) if any(p.adaptive for p in programs.values()) else None
    except InputError:
        spec = None
    if spec is not None:
        spec = _ah_in_controller_base(spec, T_bc, programs, errors)
    targets = []
    for p in plan.points:
        cmd = SearchCommand.from_point(p.to_probe_point(), np.eye(4))
        R = rotations.get(p.id)
        if R is None:
            R = default_sensor_rotation(p.normal, p.search.edge_direction)
        R = np.asarray(R, dtype=float)
        end = cmd.start_m + cmd.length_m * cmd.direction
        n = np.asarray(p.normal, dtype=float)
        safe, face_end = safe_and_face_wobj(p.to_probe_point(), safety)
        targets.append(
            TargetPair(
                point_id=p.id,
                role=p.role,
                kind=p.search.kind,
                T_wobj_start=make_transform(R, cmd.start_m),
                T_wobj_end=make_transform(R, end),
                speed_m_s=p.search.speed_m_s,
                confdata=confs.get(p.id),
                normal_wobj=(float(n[0]), float(n[1]), float(n[2])),
                T_wobj_safe=make_transform(R, safe),
                T_wobj_face=make_transform(R, face_end),
                vias_q_rad=tuple(tuple(float(v) for v in via.q_rad) for via in p.via_points),
            )
        )
    return ExportJob(
        name=module_name(plan.name or "plan"),
        plan_name=plan.name,
        method=plan.method,
        T_base_wobj=T,
        tool=tool,
        targets=tuple(targets),
        sensor_input=sensor_input,
        safety=safety,
        adaptive=spec,
        programs=programs,
        program_errors=errors,
        plan_digest=plan_digest(plan),
        check=check or CheckStatus(),
        T_base_controller=T_bc,
        controller_base=controller_base,
        sensor_kind=str(type(plan.validation.sensor).KIND),
    )


def digest_text(job: ExportJob) -> str:
    """``"plan digest <16 hex digits>"`` of the job's plan, as every program header writes it
    (results readers look for it; ``"plan digest unknown"`` for a job made in code)."""
    return f"plan digest {job.plan_digest or 'unknown'}"


def check_header(job: ExportJob, fmt: str) -> str:
    """What was checked, as the header of the controller ``fmt``'s program says it: ``CHECKED:
    ...`` when ``wobjcal check`` passed this program in the plan's cell, else ``NOT CHECKED:
    ...`` naming why (built without a check; or the points and problems check refuses)."""
    frame = f" Coordinates: {job.controller_base}." if job.controller_base else ""
    return _check_text(job, fmt) + frame


def _check_text(job: ExportJob, fmt: str) -> str:
    status = job.check
    c = CONTROLLERS[fmt]
    if status.passed:
        return (
            "CHECKED: wobjcal check passed for this program in the plan's cell "
            f"({len(job.targets)} points, controller {c.vendor} {c.label})."
        )
    refused = []
    if status.refused:
        ids = ", ".join(status.refused)
        refused.append(f"point{'s' if len(status.refused) > 1 else ''} {ids}")
    refused += status.problems
    if not status.checked:
        text = (
            "NOT CHECKED: built without a cell check (wobjcal export --no-check, or a job made "
            f"in code): run `wobjcal check --format {fmt}` on the plan before the first run."
        )
        return text + (f" Refused: {'; '.join(refused)}." if refused else "")
    why = "; ".join(_short(r) for r in status.reasons)
    return (
        'NOT CHECKED: exported with --force (or with "Export anyway" in the UI) although '
        f"wobjcal check refuses {'; '.join(refused)}"
        + (f" ({why})" if why else "")
        + ": fix the plan, or make sure by hand that those moves are safe, and run the program "
        "the first time at reduced speed."
    )


#: Longest reason of one point a program header repeats, characters.
REASON_CHARS = 160


def _short(reason: str) -> str:
    return reason if len(reason) <= REASON_CHARS else reason[: REASON_CHARS - 3] + "..."


def cycle_header(job: ExportJob, fmt: str) -> str:
    """The estimated cycle time of the controller ``fmt``'s program as its header says it
    (:meth:`planner.program.cycle_time.CycleTime.summary`), or why there is none (built
    without a cell check: no joint values to time the moves with)."""
    cycle = job.cycle_times.get(fmt)
    if cycle is None:
        return (
            "Cycle time not estimated: built without a cell check (no joint values to time the "
            f"moves with); `wobjcal check --format {fmt}` estimates it."
        )
    text = cycle.summary()
    return text[0].upper() + text[1:] + "."


def safety_header(job: ExportJob, fmt: str, prefix: str, width: int = 92) -> list[str]:
    """Header comment lines of the controller ``fmt``'s program when it runs every search in
    the nominal frame."""
    import textwrap

    name = job.program(fmt).name
    text = (
        f"PROGRAM: {name}. NOMINAL FRAME: every search is commanded in the nominal work object "
        "(not adaptive: this program runs no frame update); compute the frame afterwards with "
        "`wobjcal calibrate`. SAFE FOR: "
        + job.safety.describe()
        + ". Every search starts outside the nominal surface by at least the largest "
        "misplacement of its face plus the sensing distance (the plan's start or farther); "
        "edge searches first approach the face they run along and start "
        "from the measured face point. ASSUMES: the moves between the points are clear of "
        "the part and fixtures (checked by `wobjcal check`, not here). An edge search runs "
        "along the nominal direction: on a tilted part its track leaves the face by up to "
        "travel * sin(angle)."
    )
    return [prefix + line for line in textwrap.wrap(text, width - len(prefix))]
