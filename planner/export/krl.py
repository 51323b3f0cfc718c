"""KUKA KRL export: a ``.src``/``.dat`` pair that probes every point with an interrupt-driven
search and records the points; adaptive where the controller's measuring program is.

Conventions: millimetres; A, B, C are the Z-Y'-X'' Tait-Bryan angles in degrees (the paper's
alpha, beta, gamma of eq. 7-9, :func:`calib.frames.tait_bryan_zyx_from_matrix`). The nominal
work object goes to ``BASE_DATA[10]`` (relative to ``$WORLD``, taken to be the robot base,
``$ROBROOT`` = 0), the sensor TCP to ``TOOL_DATA[10]`` and the tool load to ``LOAD_DATA[10]``;
the targets are ``E6POS`` in that base with the status ``S`` and turn ``T`` of the checked pose
(:func:`status_turn`: from the joint values of the IK solution at each target next to the
checked pose); without a check they have no S and T (the controller keeps the current status
and turn; check the first run in T1). Every search starts at ``x<ID>_safe``, outside the
nominal surface by the safe clearance of :mod:`planner.program.safety`; an edge point first
runs an approach search to ``x<ID>_face`` and then the edge search from the measured face point
along the plan's direction (the searches: :mod:`planner.export.krl_probe`).

The program is the controller's measuring program (``job.program("krl")``):

- **nominal**: every search in the nominal base, once, in plan order, inline in the main
  program; the frame comes from ``wobjcal calibrate``;
- **adaptive**: the main program runs ``MEASURE_ADAPT``, which probes the points in the
  program's order (``x<ID>_probe(i)``) and updates ``BASE_DATA[10]`` and ``$BASE`` where the
  program's steps do: best fit and 3-2-1 by ``STEER`` (:mod:`planner.export.krl_steer`), A-H by
  its steps and the x-offset run (:mod:`planner.export.krl_adaptive`,
  :mod:`planner.export.krl_xoffset`), so each later search runs in the frame estimated so far.
  A point not measured stops it; ``nResult`` says how it ended (1: ``BASE_DATA[10]`` is the
  calibrated work object).

Every name (variables, routines, the module's ``DEF``/``DEFDAT``) has at most
:data:`MAX_NAME` characters and is unique ignoring case, as KRL's are: long point ids and plan
names are cut, ids that differ only in case or are cut alike get ``_2``, ``_3`` ... (the
comments keep the plan's ids). ``xMeas[i]`` holds point i in the robot base
(``BASE_DATA[10]:xHit``, mm; the adaptive A-H program's slots after the points hold the
retakes of C and D), ``nFail[i]`` is 0 (measured), 1 (no detection on the path), 2 (the input
was already at the searched level at the start) or, in an adaptive program, 3 (not run).
"""

from __future__ import annotations

import numpy as np

from calib._version import __version__
from calib.frames import tait_bryan_zyx_from_matrix
from planner.export.job import (
    ArmPose,
    ExportJob,
    TargetPair,
    check_header,
    cycle_header,
    digest_text,
    safety_header,
)
from planner.export.krl_adaptive import (
    ah_body,
    ah_data,
    ah_header,
    ah_routines,
    krl_job,
    measured_slots,
)
from planner.export.krl_probe import (
    failed_function,
    point_lines,
    probe_routine,
    search_routines,
)
from planner.export.krl_steer import steer_body, steer_data, steer_header, steer_routines
from planner.export.krl_text import (
    BASE_NO,
    MAX_NAME,
    SENSOR_IN,
    TOOL_NO,
    comment_lines,
    stop_lines,
)
from planner.export.krl_xoffset import has_xoffset, xoffset_data, xoffset_routines
from planner.export.paste import PasteLines
from planner.export.text import comment_text, fmt, identifier
from planner.program.model import MeasuringProgram

__all__ = [
    "BASE_NO",
    "MAX_NAME",
    "SENSOR_IN",
    "TARGET_SUFFIXES",
    "TOOL_NO",
    "e6pos_text",
    "export_krl",
    "frame_text",
    "paste_lines",
    "program_name",
    "status_turn",
]

#: The suffixes of a point's names (its targets ``x<ID>_start`` ...; vias ``_v1``, ``_v2`` ...;
#: in an adaptive program its routine ``x<ID>_probe`` and, for the A-H edge points, the search
#: direction ``_dir`` and face normal ``_nrm``): none is the tail of another, so points with
#: different names get different names.
TARGET_SUFFIXES = ("_start", "_end", "_safe", "_face", "_probe", "_dir", "_nrm")


def frame_text(T: np.ndarray) -> str:
    """``{X ..,Y ..,Z ..,A ..,B ..,C ..}`` of a transform (mm, degrees)."""
    p = T[:3, 3] * 1000.0
    abc = np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3]))
    vals = [*p, *abc]
    return "{" + ",".join(f"{k} {fmt(v, 6)}" for k, v in zip("XYZABC", vals, strict=True)) + "}"


def paste_lines(T_base_wobj: np.ndarray) -> PasteLines:
    """The calibrated work object as KRL's base the programs use (the export registry's paste
    lines): ``BASE_DATA[BASE_NO]={X ..,Y ..,Z ..,A ..,B ..,C ..}``, mm and degrees, relative to
    ``$WORLD`` taken to be ``$ROBROOT``."""
    return PasteLines("$WORLD = $ROBROOT", (f"BASE_DATA[{BASE_NO}]={frame_text(T_base_wobj)}",))


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


def _dat(job: ExportJob, names: list[str], program: MeasuringProgram) -> str:
    n = len(job.targets)
    n_slots = len(measured_slots(job))
    tool = job.tool
    cog = tool.cog_m
    lines = [
        "&ACCESS RVP",
        "&REL 1",
        f"DEFDAT {program_name(job.name)}",
        f"; Generated by wobjcal {__version__} from plan {comment_text(repr(job.plan_name))} "
        f"({digest_text(job)}). Units mm, degrees.",
        *comment_lines(comment_text(check_header(job, "krl")), "; "),
        *comment_lines(comment_text(cycle_header(job, "krl")), "; "),
        f"SIGNAL diSensor $IN[{SENSOR_IN}]",
        f"DECL FRAME xBaseNominal={frame_text(job.T_controller_wobj)}",
        f"DECL FRAME xToolSensor={frame_text(tool.T_flange_tcp)}",
        f"DECL LOAD ldSensor={{M {fmt(tool.mass_kg, 3)},CM {{X {fmt(cog[0] * 1e3, 3)},"
        f"Y {fmt(cog[1] * 1e3, 3)},Z {fmt(cog[2] * 1e3, 3)},A 0,B 0,C 0}},J {{X 0,Y 0,Z 0}}}}",
        "DECL E6POS xHit",
        "DECL E6POS xStart",
        "DECL E6POS xEnd",
        "DECL REAL fDot",
        "DECL BOOL bHit=FALSE",
        f"DECL INT nPoints={n}",
        f"DECL FRAME xMeas[{n_slots}]",
        f"DECL INT nFail[{n_slots}]",
    ]
    if program.adaptive:
        lines += [
            "; how the program ended: 0 running (or stopped by the operator), 1 calibrated",
            "; (BASE_DATA[10]), 2 slot nStopAt not measured (nFail says why), 3 the points define",
            "; no frame, 4 x-offset search nStopAt found nothing (BASE_DATA[10] calibrated)",
            "DECL INT nResult=0",
            "DECL INT nStopAt=0",
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
    if program.steers_itself:
        lines += steer_data(job, program)
    elif program.adaptive:
        lines += [*ah_data(job, names), *xoffset_data(job)]
    lines.append("ENDDAT")
    return "\n".join(lines) + "\n"


def _setup_lines() -> list[str]:
    """Set the work object, the tool and its load."""
    return [
        "  BAS(#INITMOV,0)",
        f"  BASE_DATA[{BASE_NO}]=xBaseNominal",
        f"  TOOL_DATA[{TOOL_NO}]=xToolSensor",
        f"  LOAD_DATA[{TOOL_NO}]=ldSensor",
        f"  $BASE=BASE_DATA[{BASE_NO}]",
        f"  $TOOL=TOOL_DATA[{TOOL_NO}]",
        f"  $LOAD=LOAD_DATA[{TOOL_NO}]",
    ]


def _src(job: ExportJob, names: list[str], program: MeasuringProgram) -> str:
    head = [
        "&ACCESS RVP",
        "&REL 1",
        f"DEF {program_name(job.name)}()",
    ]
    about = [
        f"  ; Generated by wobjcal {__version__} from plan {comment_text(repr(job.plan_name))} "
        f"({digest_text(job)}, procedure {comment_text(job.method)}).",
        *comment_lines(comment_text(check_header(job, "krl"))),
        *comment_lines(comment_text(cycle_header(job, "krl"))),
        f"  ; Probes each point with the {job.sensor_words} on diSensor; see the .dat file.",
        _status_note(job),
    ]
    if program.adaptive:
        return "\n".join(_adaptive_src(job, names, program, head, about))
    n = len(job.targets)
    lines = [
        *head,
        "  DECL INT nI",
        *about,
        *safety_header(job, "krl", "  ; "),
        "  ; Results: xMeas[i] = point i in the robot base (mm), nFail[i] = 0 ok, 1 no detection,",
        "  ; 2 input already at the searched level at the start, 3 not run. Order of points:",
        "  ; "
        + ", ".join(f"{i}={comment_text(t.point_id)}" for i, t in enumerate(job.targets, start=1)),
        *_setup_lines(),
        "  ; the data list keeps a previous run's values: every point not run until it is",
        f"  FOR nI=1 TO {n}",
        "    nFail[nI]=3",
        "  ENDFOR",
    ]
    for i, (t, name) in enumerate(zip(job.targets, names, strict=True), start=1):
        lines += [
            f"  ; --- point {comment_text(t.point_id)} ({comment_text(t.kind)} search)",
            *point_lines(str(i), t, name),
        ]
    lines += ["END", "", *search_routines()]
    return "\n".join(lines)


def _adaptive_header(job: ExportJob, program: MeasuringProgram) -> list[str]:
    """The header of an adaptive program: its name, what it computes, what it is safe for."""
    a = job.adaptive
    from_measured = a is not None and a.settings.edge_start_from_measured
    edges = (
        "edge searches first approach the face they run along and start from the measured "
        "face point"
        + (" (F and H: from the measured E and G, as the procedure does)" if from_measured else "")
    )
    what = steer_header(program) if program.steers_itself else ah_header()
    return comment_lines(
        f"PROGRAM: {program.name}. {what} SAFE FOR: {job.safety.describe()}. Every search starts "
        "outside the nominal surface by at least the largest misplacement of its face plus the "
        f"sensing distance (the plan's start or farther); {edges}. ASSUMES: the moves between "
        "the points are clear of the part and fixtures (checked by `wobjcal check`, not here), "
        "and every motion ends at its target (no approximation: $BASE changes between them)."
    )


def _adaptive_src(
    job: ExportJob,
    names: list[str],
    program: MeasuringProgram,
    head: list[str],
    about: list[str],
) -> list[str]:
    slots = measured_slots(job)
    order = ", ".join(
        f"{i}={comment_text(pid)}{' (retake)' if retake else ''}"
        for i, (pid, retake) in enumerate(slots, start=1)
    )
    if program.steers_itself:
        body = steer_body(job, program, names)
        routines = steer_routines()
    else:
        body = ah_body(job, program, names)
        if has_xoffset(job):
            body += [
                "  ; 10: the x-offset run over the teeth at two slot-hole levels, in the",
                "  ;     calibrated frame, and the x-offset matrix (eq. 13-14)",
                "  XOFFSET_RUN()",
                *stop_lines("  "),
            ]
        routines = ah_routines() + xoffset_routines(job, names)
    # A-H with edge_start_from_measured: F and H start at the measured E and G (offset, mm)
    a = job.adaptive  # None for best fit and 3-2-1 (export_krl)
    from_measured: dict[int, float] = {}
    if a is not None and a.settings.edge_start_from_measured:
        offset_mm = a.settings.edge_start_offset_m * 1000.0
        from_measured = {a.index["F"]: offset_mm, a.index["H"]: offset_mm}
    probes: list[str] = []
    for i, (t, name) in enumerate(zip(job.targets, names, strict=True)):
        probes += probe_routine(t, name, from_measured.get(i))
    return [
        *head,
        "  DECL INT nI",
        *about,
        *_adaptive_header(job, program),
        *comment_lines(
            "Results: xMeas[i] = point i in the robot base (mm), nFail[i] = 0 ok, 1 no "
            "detection, 2 input already at the searched level at the start, 3 not run; "
            "nResult: how the program ended (see the .dat). Order of points: " + order
        ),
        *_setup_lines(),
        "  ; the data list keeps a previous run's values: start from nothing measured",
        "  nResult=0",
        "  nStopAt=0",
        f"  FOR nI=1 TO {len(slots)}",
        "    nFail[nI]=3",
        "  ENDFOR",
        "  MEASURE_ADAPT()",
        "END",
        "",
        f"; {comment_text(program.name)}: the searches in the program's order, each in",
        f"; BASE_DATA[{BASE_NO}] (the frame estimated so far), and the frame updates between them",
        "DEF MEASURE_ADAPT()",
        *body,
        "  nResult=1",
        "END",
        "",
        *probes,
        *routines,
        *failed_function(),
        *search_routines(),
    ]


def _status_note(job: ExportJob) -> str:
    missing = [comment_text(t.point_id) for t in job.targets if t.arm is None]
    if not missing:
        return "  ; S and T of every target: the configuration of the pose wobjcal check chose."
    return (
        "  ; No S and T for points " + ", ".join(missing) + " (no checked pose): the controller "
        "keeps the current status and turn; run the first time in T1."
    )


def export_krl(job: ExportJob) -> dict[str, str]:
    """The KRL program of ``job``: ``{".src": text, ".dat": text}`` (the program of
    ``job.program("krl")``: adaptive or nominal)."""
    job, program = krl_job(job)  # the A-H specifics: for A-H programs only
    names = _names(job.targets)
    return {".src": _src(job, names, program), ".dat": _dat(job, names, program)}
