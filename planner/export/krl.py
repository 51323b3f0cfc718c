"""KUKA KRL export: a ``.src``/``.dat`` pair that probes every point with an interrupt-driven
search and records the points.

Conventions: millimetres; A, B, C are the Z-Y'-X'' Tait-Bryan angles in degrees (the paper's
alpha, beta, gamma of eq. 7-9, :func:`calib.frames.tait_bryan_zyx_from_matrix`). The nominal
work object goes to ``BASE_DATA[10]`` (relative to ``$WORLD``, taken to be the robot base,
``$ROBROOT`` = 0), the sensor TCP to ``TOOL_DATA[10]`` and the tool load to ``LOAD_DATA[10]``;
the targets are ``E6POS`` in that base with the status ``S`` and turn ``T`` of the checked pose
(:func:`status_turn`: from the joint values of the IK solution at each target next to the
checked pose); without a check they have no S and T (the controller keeps the current status
and turn; check the first run in T1). Every search runs in the nominal base (not
adaptive; the frame comes from ``wobjcal calibrate``) and starts at ``x<ID>_safe``, outside
the nominal surface by the safe clearance of :mod:`planner.program.safety`; an edge point first
runs an approach search to ``x<ID>_face`` and then the edge search from the measured face point
along the plan's direction. A search moves ``LIN`` to the end point with
``INTERRUPT ... WHEN diSensor==TRUE`` (approach) or ``==FALSE`` (edge); the interrupt routine
brakes, stores ``$POS_INT`` and ``RESUME``-s. KRL's ``RESUME`` ends the routines below the one
that declared the interrupt and goes on in it after its call into the level below, so the
search routines (``SEARCH_RISE``, ``SEARCH_FALL``) declare the interrupt and run the ``LIN`` one
level below, in ``SEARCH_MOVE`` (which ends with ``WAIT SEC 0`` so that the advance run stays
there). Every name (variables, routines, the module's ``DEF``/``DEFDAT``) has at most
:data:`MAX_NAME` characters and is unique ignoring case, as KRL's are: long point ids and plan
names are cut, ids that differ only in case or are cut alike get ``_2``, ``_3`` ... (the
comments keep the plan's ids). ``xMeas[i]`` holds point i in the robot base
(``BASE_DATA[10]:xHit``, mm), ``nFail[i]`` is 0 (measured), 1 (no detection on the path) or 2
(the input was already at the searched level at the start).
"""

from __future__ import annotations

import numpy as np

from calib._version import __version__
from calib.frames import tait_bryan_zyx_from_matrix
from planner.export.job import ArmPose, ExportJob, TargetPair, safety_header
from planner.export.text import comment_text, fmt, identifier

BASE_NO = 10
TOOL_NO = 10
SENSOR_IN = 1
#: Longest name KRL accepts (variables, routines and the module: its ``DEF``, ``DEFDAT`` and
#: file name); KRL names are case-insensitive.
MAX_NAME = 24
#: The suffixes of a point's target names (``x<ID>_start`` ...; vias ``_v1``, ``_v2`` ...): none
#: is the tail of another, so points with different names get different target names.
TARGET_SUFFIXES = ("_start", "_end", "_safe", "_face")


def frame_text(T: np.ndarray) -> str:
    """``{X ..,Y ..,Z ..,A ..,B ..,C ..}`` of a transform (mm, degrees)."""
    p = T[:3, 3] * 1000.0
    abc = np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3]))
    vals = [*p, *abc]
    return "{" + ",".join(f"{k} {fmt(v, 6)}" for k, v in zip("XYZABC", vals, strict=True)) + "}"


def status_turn(arm: ArmPose) -> tuple[int, int]:
    """KUKA ``(S, T)`` of a robot configuration.

    Status: bit 0 the wrist root point behind axis 1 (overhead area), bit 1 the elbow up
    (A3 >= phi), bit 2 the wrist flipped (A5 <= 0 with A4 at its zero). Turn: bit ``i`` set when
    axis ``i + 1`` is negative, in the URDF's joint directions (ROS-Industrial KUKA URDFs use
    KUKA's).
    """
    s = (not arm.front) | (arm.elbow_up << 1) | (arm.wrist_flipped << 2)
    t = sum(1 << i for i, v in enumerate(arm.q_rad[:6]) if v < 0.0)
    return int(s), int(t)


def e6pos_text(T: np.ndarray, arm: ArmPose | None) -> str:
    """An ``E6POS`` literal: :func:`frame_text`, plus ``S`` and ``T`` when the pose is known."""
    text = frame_text(T)
    if arm is None:
        return text
    s, t = status_turn(arm)
    return f"{text[:-1]},S {s},T {t}}}"


def program_name(name: str) -> str:
    """The module's name for a job's ``name`` (its ``DEF`` and ``DEFDAT``, and the name of the
    ``.src``/``.dat`` files on the controller): ``name`` cut to :data:`MAX_NAME` characters."""
    return identifier(name, "W")[:MAX_NAME]


def _names(targets: tuple[TargetPair, ...]) -> list[str]:
    """``x<ID>`` per target, cut so that ``x<ID>_start`` (and every other target name of the
    point) has at most :data:`MAX_NAME` characters, and made unique ignoring case with
    ``_2``, ``_3`` ... (KRL names are case-insensitive)."""
    longest = max((len(f"_v{len(t.vias_q_rad)}") for t in targets), default=0)
    width = MAX_NAME - max(longest, *(len(x) for x in TARGET_SUFFIXES))
    names: list[str] = []
    taken: set[str] = set()
    for t in targets:
        base = identifier("x" + t.point_id)[:width].rstrip("_")
        name, k = base, 2
        while name.upper() in taken:
            tail = f"_{k}"
            name, k = base[: width - len(tail)].rstrip("_") + tail, k + 1
        taken.add(name.upper())
        names.append(name)
    return names


def _dat(job: ExportJob, names: list[str]) -> str:
    n = len(job.targets)
    tool = job.tool
    cog = tool.cog_m
    lines = [
        "&ACCESS RVP",
        "&REL 1",
        f"DEFDAT {program_name(job.name)}",
        f"; Generated by wobjcal {__version__} from plan {comment_text(repr(job.plan_name))}. "
        "Units mm, degrees.",
        f"SIGNAL diSensor $IN[{SENSOR_IN}]",
        f"DECL FRAME xBaseNominal={frame_text(job.T_base_wobj)}",
        f"DECL FRAME xToolSensor={frame_text(tool.T_flange_tcp)}",
        f"DECL LOAD ldSensor={{M {fmt(tool.mass_kg, 3)},CM {{X {fmt(cog[0] * 1e3, 3)},"
        f"Y {fmt(cog[1] * 1e3, 3)},Z {fmt(cog[2] * 1e3, 3)},A 0,B 0,C 0}},J {{X 0,Y 0,Z 0}}}}",
        "DECL E6POS xHit",
        "DECL E6POS xStart",
        "DECL E6POS xEnd",
        "DECL REAL fDot",
        "DECL BOOL bHit=FALSE",
        f"DECL INT nPoints={n}",
        f"DECL FRAME xMeas[{n}]",
        f"DECL INT nFail[{n}]",
    ]
    for t, name in zip(job.targets, names, strict=True):
        lines += [
            f"; {comment_text(t.point_id)}: {comment_text(t.kind)} search, role "
            f"{comment_text(t.role)}, "
            f"{fmt(t.length_m * 1000.0, 1)} mm at {fmt(t.speed_m_s * 1000.0, 1)} mm/s",
            f"DECL E6POS {name}_start={e6pos_text(t.T_wobj_start, t.arm_pose('start'))}",
            f"DECL E6POS {name}_end={e6pos_text(t.T_wobj_end, t.arm_pose('end'))}",
            f"DECL E6POS {name}_safe={e6pos_text(t.safe_start, t.arm_pose('safe'))}",
        ]
        if t.kind == "edge":
            lines.append(f"DECL E6POS {name}_face={e6pos_text(t.face_end, t.arm_pose('face'))}")
        for k, deg in enumerate(t.vias_deg("KRL"), start=1):
            axes = ",".join(f"A{j} {fmt(v, 4)}" for j, v in enumerate(deg, start=1))
            lines.append(f"DECL AXIS {name}_v{k}={{{axes}}}")
    lines.append("ENDDAT")
    return "\n".join(lines) + "\n"


def _src(job: ExportJob, names: list[str]) -> str:
    lines = [
        "&ACCESS RVP",
        "&REL 1",
        f"DEF {program_name(job.name)}()",
        f"  ; Generated by wobjcal {__version__} from plan {comment_text(repr(job.plan_name))} "
        f"(procedure {comment_text(job.method)}).",
        "  ; Probes each point with the proximity sensor on diSensor; see the .dat file.",
        _status_note(job),
        *safety_header(job, "krl", "  ; "),
        "  ; Results: xMeas[i] = point i in the robot base (mm), nFail[i] = 0 ok, 1 no detection,",
        "  ; 2 input already at the searched level at the start. Order of points:",
        "  ; "
        + ", ".join(f"{i}={comment_text(t.point_id)}" for i, t in enumerate(job.targets, start=1)),
        "  BAS(#INITMOV,0)",
        f"  BASE_DATA[{BASE_NO}]=xBaseNominal",
        f"  TOOL_DATA[{TOOL_NO}]=xToolSensor",
        f"  LOAD_DATA[{TOOL_NO}]=ldSensor",
        f"  $BASE=BASE_DATA[{BASE_NO}]",
        f"  $TOOL=TOOL_DATA[{TOOL_NO}]",
        f"  $LOAD=LOAD_DATA[{TOOL_NO}]",
    ]
    for i, (t, name) in enumerate(zip(job.targets, names, strict=True), start=1):
        lines += _point_lines(i, t, name)
    lines += ["END", ""]
    for routine, level, prio in (("SEARCH_RISE", "TRUE", 20), ("SEARCH_FALL", "FALSE", 21)):
        lines += [
            f"DEF {routine}(xGoal:IN,fVel:IN)",
            "  DECL E6POS xGoal",
            "  DECL REAL fVel",
            f"  INTERRUPT DECL {prio} WHEN diSensor=={level} DO HIT_{prio}()",
            "  bHit=FALSE",
            "  $VEL.CP=fVel",
            f"  INTERRUPT ON {prio}",
            "  SEARCH_MOVE(xGoal) ; the motion one level below the declaration, for RESUME",
            f"  INTERRUPT OFF {prio}",
            "END",
            "",
            f"DEF HIT_{prio}()",
            f"  INTERRUPT OFF {prio}",
            "  BRAKE F",
            "  xHit=$POS_INT",
            "  bHit=TRUE",
            f"  RESUME ; ends SEARCH_MOVE, goes on in {routine} after its call",
            "END",
            "",
        ]
    lines += [
        "DEF SEARCH_MOVE(xTo:IN)",
        "  DECL E6POS xTo",
        "  LIN xTo",
        "  WAIT SEC 0 ; stop the advance run here, so that RESUME ends this routine",
        "END",
        "",
    ]
    return "\n".join(lines)


def _status_note(job: ExportJob) -> str:
    missing = [comment_text(t.point_id) for t in job.targets if t.arm is None]
    if not missing:
        return "  ; S and T of every target: the configuration of the pose wobjcal check chose."
    return (
        "  ; No S and T for points " + ", ".join(missing) + " (no checked pose): the controller "
        "keeps the current status and turn; run the first time in T1."
    )


def _point_lines(i: int, t: TargetPair, name: str) -> list[str]:
    """Probe one point: an approach search from ``_safe``; for an edge point, then the edge
    search from the measured face point along the plan's direction, up to the plan's end."""
    v = fmt(t.speed_m_s, 6)
    vias = [
        f"  PTP {name}_v{k} ; via {k} (axis angles, deg)" for k in range(1, len(t.vias_q_rad) + 1)
    ]
    head = [
        f"  ; --- point {comment_text(t.point_id)} ({comment_text(t.kind)} search)",
        *vias,
        "  $VEL.CP=0.1",
        f"  PTP {name}_safe",
        "  IF diSensor==TRUE THEN",
        f"    nFail[{i}]=2",
        "  ELSE",
    ]
    tail = ["  ENDIF", "  $VEL.CP=0.1", f"  LIN {name}_safe"]
    if t.kind == "approach":
        return [*head, f"    SEARCH_RISE({name}_end,{v})", *_record(i, "    "), *tail]
    d = t.edge_direction_wobj
    dot = "+".join(f"({name}_end.{c}-xStart.{c})*{_factor(d[k])}" for k, c in enumerate("XYZ"))
    return [
        *head,
        "    ; approach the face the edge search runs along",
        f"    SEARCH_RISE({name}_face,{v})",
        "    IF bHit THEN",
        "      ; start the edge search at the measured face point (in the same base)",
        f"      xStart={name}_start",
        "      xStart.X=xHit.X",
        "      xStart.Y=xHit.Y",
        "      xStart.Z=xHit.Z",
        "      $VEL.CP=0.1",
        "      LIN xStart",
        f"      fDot={dot}",
        f"      xEnd={name}_end",
        *[f"      xEnd.{c}=xStart.{c}+fDot*{_factor(d[k])}" for k, c in enumerate("XYZ")],
        "      IF diSensor==FALSE THEN",
        f"        nFail[{i}]=2",
        "      ELSE",
        f"        SEARCH_FALL(xEnd,{v})",
        *_record(i, "        "),
        "      ENDIF",
        "    ELSE",
        f"      nFail[{i}]=1",
        "    ENDIF",
        *tail,
    ]


def _factor(x: float) -> str:
    """``x`` as the right operand of ``*``: a negative number in parentheses (``*(-0.5)``,
    never ``*-0.5``)."""
    text = fmt(x, 9)
    return f"({text})" if text.startswith("-") else text


def _record(i: int, pad: str) -> list[str]:
    return [
        f"{pad}IF bHit THEN",
        f"{pad}  xMeas[{i}]=BASE_DATA[{BASE_NO}]:xHit",
        f"{pad}  nFail[{i}]=0",
        f"{pad}ELSE",
        f"{pad}  nFail[{i}]=1",
        f"{pad}ENDIF",
    ]


def export_krl(job: ExportJob) -> dict[str, str]:
    """The KRL program of ``job``: ``{".src": text, ".dat": text}``."""
    names = _names(job.targets)
    return {".src": _src(job, names), ".dat": _dat(job, names)}
