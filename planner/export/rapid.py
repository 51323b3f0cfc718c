"""ABB RAPID export: one MODULE that probes every point with ``SearchL`` and records the points.

Layout of the module:

- a header comment: adaptive or nominal frame, the misplacement tolerance the search starts
  are safe for (:mod:`planner.program.safety`) and what the program assumes;
- ``PERS tooldata tSensor``: the sensor TCP on the flange (mm, quaternion ``[q1..q4]`` = w, x, y,
  z), with the tool's mass and centre of gravity;
- ``PERS wobjdata wobjNominal``: the nominal work object. ``uframe`` holds ``T_base_wobj`` (the
  controller's world frame is taken to be the robot base, ABB's default for one robot) and
  ``oframe`` is identity; ``PERS wobjdata wobjCal``: the frame every search is commanded in,
  set to ``wobjNominal`` at the start. The program updates ``wobjCal.uframe`` where its measuring
  program does: after every step of the A-H procedure (:mod:`planner.export.rapid_adaptive`), or
  between the searches of a best fit or a 3-2-1 (:mod:`planner.export.rapid_steer`), and ends
  with the calibrated work object in it; a nominal program leaves it nominal;
- per point ``_start``/``_end`` (the plan's search), ``_safe`` (the safe start) and for edge
  points ``_face``, ``_dir``, ``_normal``, all in ``wobjCal`` with the ``confdata``
  ``[cf1, cf4, cf6, cfx]`` of the IK branch ``wobjcal check`` chose (``[0, 0, 0, 0]`` and a
  comment when unknown), and a ``PROC Probe_<name>(num i)`` (:mod:`planner.export.rapid_probe`)
  with an ``ERROR`` handler for ``ERR_WHLSEARCH`` and ``ERR_SIGSUPSEARCH`` that records the
  failure, ``TPWrite``-s it, retreats and goes on (``Stop`` when ``bStopOnFail``; the adaptive
  program stops at the first failure);
- ``PERS pos measured{N}`` (base frame, mm; the adaptive program adds the retakes of C and D)
  with ``measuredId``/``measuredRetake``/``measuredOk``/``measuredErr``, and
  ``WriteMeasurements`` (:mod:`planner.export.rapid_write`) writing
  ``HOME:/wobjcal_measured.json`` in the ``wobjcal.measurements/1`` format.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from calib._version import __version__
from calib.frames import quat_wxyz_from_matrix
from planner.export.job import ExportJob, check_header, cycle_header, digest_text
from planner.export.paste import PasteLines
from planner.export.rapid_probe import WOBJ, probe_proc
from planner.export.rapid_steer import steer_main, steer_procs
from planner.export.rapid_write import MEASURED_FILE, write_proc
from planner.export.text import comment_text, fmt, identifier
from planner.program.controllers import RAPID_JOINT_MOVE

#: ``vApproach``'s TCP and tool speeds, mm/s and deg/s (the controller's joint moves,
#: :data:`planner.program.controllers.RAPID_JOINT_MOVE`, which the cycle time times).
_V_TCP_MM_S = 1000.0 * (RAPID_JOINT_MOVE.tcp_speed_m_s or 0.0)
_V_ORI_DEG_S = math.degrees(RAPID_JOINT_MOVE.tool_speed_rad_s or 0.0)

EXTAX = "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]"


def pose_text(T: np.ndarray) -> str:
    """``[[x,y,z],[q1,q2,q3,q4]]`` of a transform: mm and a (w, x, y, z) quaternion."""
    p = T[:3, 3] * 1000.0
    q = quat_wxyz_from_matrix(T[:3, :3])
    trans = ",".join(fmt(v, 4) for v in p)
    rot = ",".join(fmt(v, 9) for v in q)
    return f"[[{trans}],[{rot}]]"


def wobjdata_text(T_base_wobj: np.ndarray) -> str:
    """A ``wobjdata`` literal whose user frame is ``T_base_wobj`` (in the world frame, taken to
    be the robot base), not held by the robot, object frame identity."""
    return f'[FALSE,TRUE,"",{pose_text(T_base_wobj)},[[0,0,0],[1,0,0,0]]]'


def paste_lines(T_base_wobj: np.ndarray) -> PasteLines:
    """The calibrated work object as a RAPID ``wobjdata`` declaration (the export registry's
    paste lines): ``PERS wobjdata wobjCalibrated``, mm and a (w, x, y, z) quaternion."""
    return PasteLines(
        "world frame = robot base",
        (f"PERS wobjdata wobjCalibrated:={wobjdata_text(T_base_wobj)};",),
    )


def robtarget_text(T: np.ndarray, conf: tuple[int, int, int, int] | None) -> str:
    """A ``robtarget`` literal."""
    cf = ",".join(str(int(c)) for c in (conf or (0, 0, 0, 0)))
    return f"[{pose_text(T)[1:-1]},[{cf}],{EXTAX}]"


def _string(text: str) -> str:
    """A RAPID string literal (quotes and backslashes doubled, control characters dropped,
    max 80 characters)."""
    body = comment_text(text).replace("\\", "\\\\").replace('"', '""')
    return '"' + body[:78] + '"'


def _declarations(job: ExportJob, names: list[str]) -> list[str]:
    tool = job.tool
    cog = ",".join(fmt(v * 1000.0, 3) for v in tool.cog_m)
    slots = measured_slots(job)
    n = len(slots)
    ids = ",".join(_string(pid) for pid, _ in slots)
    retake = ",".join("TRUE" if r else "FALSE" for _, r in slots)
    empty = ",".join(['""'] * n)
    nominal = wobjdata_text(job.T_controller_wobj)
    lines = [
        f"    PERS tooldata tSensor:=[TRUE,{pose_text(tool.T_flange_tcp)},"
        f"[{fmt(tool.mass_kg, 3)},[{cog}],[1,0,0,0],0,0,0]];",
        f"    PERS wobjdata wobjNominal:={nominal};",
        "    ! the frame the searches are commanded in (updated step by step when adaptive)",
        f"    PERS wobjdata {WOBJ}:={nominal};",
        f"    CONST speeddata vApproach:=[{fmt(_V_TCP_MM_S, 3)},{fmt(_V_ORI_DEG_S, 3)},5000,1000];",
        f"    CONST num nPoints:={n};",
        f"    PERS string measuredId{{{n}}}:=[{ids}];",
        f"    PERS bool measuredRetake{{{n}}}:=[{retake}];",
        f"    PERS pos measured{{{n}}}:=[{','.join(['[0,0,0]'] * n)}];",
        f"    PERS bool measuredOk{{{n}}}:=[{','.join(['FALSE'] * n)}];",
        f"    PERS string measuredErr{{{n}}}:=[{empty}];",
        "    ! TRUE: stop the program at the first failed search",
        "    PERS bool bStopOnFail:=FALSE;",
        "    VAR robtarget pMeas;",
    ]
    for t, name in zip(job.targets, names, strict=True):
        note = "" if t.confdata else "  ! confdata unknown: run wobjcal check"
        lines += [
            f"    ! {comment_text(t.point_id)} ({comment_text(t.kind)} search, role "
            f"{comment_text(t.role)}, "
            f"{fmt(t.length_m * 1000.0, 1)} mm at {fmt(t.speed_m_s * 1000.0, 1)} mm/s)",
            f"    CONST robtarget {name}_start:={robtarget_text(t.T_wobj_start, t.confdata)};"
            + note,
            f"    CONST robtarget {name}_end:={robtarget_text(t.T_wobj_end, t.confdata)};",
            f"    CONST robtarget {name}_safe:={robtarget_text(t.safe_start, t.confdata)};",
        ]
        if t.kind == "edge":
            d = t.edge_direction_wobj
            n_w = t.normal_wobj
            lines += [
                f"    CONST robtarget {name}_face:={robtarget_text(t.face_end, t.confdata)};",
                f"    CONST pos {name}_dir:=[{','.join(fmt(v, 9) for v in d)}];",
                f"    CONST pos {name}_normal:=[{','.join(fmt(v, 9) for v in n_w)}];",
            ]
        lines.append(
            f"    CONST speeddata vSearch_{name}:=[{fmt(t.speed_m_s * 1000.0, 3)},30,5000,1000];"
        )
        for k, deg in enumerate(t.vias_deg("RAPID"), start=1):
            lines.append(
                f"    CONST jointtarget {name}_via{k}:=[[{','.join(fmt(v, 4) for v in deg)}],"
                "[9E9,9E9,9E9,9E9,9E9,9E9]];"
            )
    return lines


def measured_slots(job: ExportJob) -> list[tuple[str, bool]]:
    """``(point id, is a retake)`` of each entry of the RAPID ``measured`` array, in order."""
    slots = [(t.point_id, False) for t in job.targets]
    a = job.adaptive
    if a is not None and a.settings.retake_c_d:
        slots += [(job.targets[a.index[r]].point_id, True) for r in ("C", "D")]
    return slots


def export_rapid(job: ExportJob) -> str:
    """The RAPID module text of ``job``."""
    from planner.export.rapid_adaptive import (
        adaptive_header,
        adaptive_main,
        adaptive_procs,
        xoffset_procs,
    )

    program = job.program("rapid")
    if not program.adaptive:  # the A-H specifics are for the controllers that run them
        job = replace(job, adaptive=None)
    names = _unique_names([t.point_id for t in job.targets])
    a = job.adaptive
    lines = [
        f"MODULE {job.name}",
        f"    ! Generated by wobjcal {__version__} from plan {comment_text(repr(job.plan_name))} "
        f"({digest_text(job)}, procedure {comment_text(job.method)}).",
        *_comment(comment_text(check_header(job, "rapid"))),
        *_comment(comment_text(cycle_header(job, "rapid"))),
        f"    ! PROGRAM: {comment_text(program.name)}.",
        f"    ! Probes each point with the {job.sensor_words} on digital input diSensor.",
        *(
            adaptive_header()
            if a is not None
            else _steered_header()
            if program.steers_itself
            else _nominal_header()
        ),
        *_comment(
            "SAFE FOR: "
            + job.safety.describe()
            + ". Every search starts outside the nominal surface by at least the largest "
            "misplacement of its face plus the sensing distance (the plan's start or farther); "
            "edge searches first approach the face they run along "
            "and start from the measured face point. ASSUMES: the moves between the points "
            "are clear of the part and fixtures (checked by `wobjcal check`, not here), and "
            "all moves end in fine points (wobjCal changes between them)."
        ),
        f"    ! Units mm; quaternions [q1,q2,q3,q4] = w, x, y, z; robtargets in {WOBJ}.",
        "    ! wobjNominal.uframe = nominal work object in the world frame (= robot base).",
        "    ! confdata [cf1,cf4,cf6,cfx] from the IK branch chosen by `wobjcal check`.",
        "    ! Results: measured{i} (base frame, mm; SearchL gives pMeas in the wobj, converted",
        f"    ! with {WOBJ}.uframe and .oframe) of point measuredId{{i}}, and",
        f"    ! HOME:/{MEASURED_FILE} for `wobjcal calibrate PLAN RESULTS`.",
        *_declarations(job, names),
        *(adaptive_procs(job) if a is not None else []),
        *(steer_procs(job, program) if program.steers_itself else []),
        *xoffset_procs(job, names),
        "",
        "    PROC main()",
        *_conf_lines(job),
        f"        {WOBJ}:=wobjNominal;",
        "        ! PERS values survive a previous run: start from nothing measured",
        "        FOR i FROM 1 TO nPoints DO",
        "            measuredOk{i}:=FALSE;",
        '            measuredErr{i}:="";',
        "        ENDFOR",
        *(
            adaptive_main(job, names)
            if a is not None
            else steer_main(job, program, names)
            if program.steers_itself
            else [f"        Probe_{name} {i};" for i, name in enumerate(names, start=1)]
        ),
        "        WriteMeasurements;",
        "    ENDPROC",
        "",
    ]
    for t, name in zip(job.targets, names, strict=True):
        start_at = None
        if a is not None and a.settings.edge_start_from_measured and t.role in ("F", "H"):
            start_at = a.settings.edge_start_offset_m
        lines += probe_proc(t, name, start_at)
    lines += write_proc(job.plan_digest)
    return "\n".join(_data_first(lines)) + "\nENDMODULE\n"


_ROUTINE_START = ("    PROC ", "    FUNC ", "    TRAP ", "    LOCAL PROC ", "    LOCAL FUNC ")
_ROUTINE_END = ("    ENDPROC", "    ENDFUNC", "    ENDTRAP")


def _data_first(lines: list[str]) -> list[str]:
    """The module's lines (``MODULE`` line first, no ``ENDMODULE``) with every module-level
    data declaration before the first routine, as RAPID's module syntax requires (``MODULE
    name <data declarations> <routine declarations> ENDMODULE``); the writers' sections put
    their constants beside their routines. Comment lines go with the item after them; the
    order within data and within routines is kept."""
    head: list[str] = [lines[0]]
    data: list[str] = []
    routines: list[str] = []
    pending: list[str] = []
    in_routine = False
    for line in lines[1:]:
        if in_routine:
            routines.append(line)
            if line.startswith(_ROUTINE_END):
                in_routine = False
            continue
        if not line.strip() or line.startswith("    !"):
            pending.append(line)
        elif line.startswith(_ROUTINE_START):
            routines += [*pending, line]
            pending, in_routine = [], True
        else:  # a data declaration
            (data if data or routines else head).extend([*pending, line])
            pending = []
    return [*head, *data, *routines, *pending]


def _comment(text: str, width: int = 92) -> list[str]:
    """``text`` as RAPID comment lines of at most ``width`` characters."""
    import textwrap

    return ["    ! " + line for line in textwrap.wrap(text, width - 6)]


def _steered_header() -> list[str]:
    return [
        f"    ! ADAPTIVE: {WOBJ}.uframe is updated after the points its steps name (the smallest",
        "    ! motion that puts them on their faces), so each search runs in the work-object",
        f"    ! frame estimated so far. At the end {WOBJ} holds the measured frame, NOT YET",
        "    ! SCREENED for gross errors: use it once `wobjcal calibrate` trusts it.",
    ]


def _nominal_header() -> list[str]:
    return [
        f"    ! NOMINAL FRAME: every search is commanded in {WOBJ} = wobjNominal (not adaptive).",
    ]


def _conf_lines(job: ExportJob) -> list[str]:
    if all(t.confdata is not None for t in job.targets):
        return ["        ConfJ\\On;", "        ConfL\\On;"]
    return [
        "        ! confdata unknown for some points: let the controller choose",
        "        ConfJ\\Off;",
        "        ConfL\\Off;",
    ]


def _unique_names(ids: list[str]) -> list[str]:
    """RAPID identifiers ``p<ID>`` for point ids, unique."""
    names: list[str] = []
    for pid in ids:
        base = identifier("p" + pid)
        name, k = base, 2
        while name in names:
            name, k = f"{base}_{k}", k + 1
        names.append(name)
    return names


def rapid_files(job: ExportJob) -> dict[str, str]:
    """The RAPID module of ``job`` as ``{".mod": text}`` (the export registry's writer)."""
    return {".mod": export_rapid(job)}
