"""ABB RAPID export: one MODULE that probes every point with ``SearchL`` and records the points.

Layout of the module:

- ``PERS tooldata tSensor``: the sensor TCP on the flange (mm, quaternion ``[q1..q4]`` = w, x, y,
  z), with the tool's mass and centre of gravity;
- ``PERS wobjdata wobjNominal``: the nominal work object. ``uframe`` holds ``T_base_wobj`` (the
  controller's world frame is taken to be the robot base, ABB's default for one robot) and
  ``oframe`` is identity, so re-running with a calibrated ``uframe`` needs no other change;
- per point a start and an end ``robtarget`` in ``wobjNominal`` with the ``confdata``
  ``[cf1, cf4, cf6, cfx]`` of the IK branch ``wobjcal check`` chose (``[0, 0, 0, 0]`` and a
  comment when unknown) and a ``PROC`` that moves to the start, runs
  ``SearchL \\SStop, diSensor, ...`` (approach: rising flank) or
  ``SearchL \\SStop, diSensor \\NegFlank, ...`` (edge: the sensor stops detecting where the face
  ends), stores the search point in the base frame and retreats to the start;
- an ``ERROR`` handler per search: ``ERR_WHLSEARCH`` (no detection on the whole path) and
  ``ERR_SIGSUPSEARCH`` (the input already at the searched level at the start) record the failure,
  ``TPWrite`` it, retreat, and go on (or ``Stop`` when ``bStopOnFail`` is TRUE);
- ``PERS pos measured{N}`` with ``measuredId``/``measuredOk``/``measuredErr``, and
  ``WriteMeasurements`` writing ``HOME:/wobjcal_measured.json`` in the
  ``wobjcal.measurements/1`` format, ready for ``wobjcal calibrate``.
"""

from __future__ import annotations

import numpy as np

from calib._version import __version__
from calib.frames import quat_wxyz_from_matrix
from planner.export.common import ExportJob, TargetPair, fmt, identifier

EXTAX = "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]"
MEASURED_FILE = "wobjcal_measured.json"


def pose_text(T: np.ndarray) -> str:
    """``[[x,y,z],[q1,q2,q3,q4]]`` of a transform: mm and a (w, x, y, z) quaternion."""
    p = T[:3, 3] * 1000.0
    q = quat_wxyz_from_matrix(T[:3, :3])
    trans = ",".join(fmt(v, 4) for v in p)
    rot = ",".join(fmt(v, 9) for v in q)
    return f"[[{trans}],[{rot}]]"


def robtarget_text(T: np.ndarray, conf: tuple[int, int, int, int] | None) -> str:
    """A ``robtarget`` literal."""
    cf = ",".join(str(int(c)) for c in (conf or (0, 0, 0, 0)))
    return f"[{pose_text(T)[1:-1]},[{cf}],{EXTAX}]"


def _string(text: str) -> str:
    """A RAPID string literal (quotes and backslashes doubled, max 80 characters)."""
    return '"' + text.replace("\\", "\\\\").replace('"', '""')[:78] + '"'


def _declarations(job: ExportJob, names: list[str]) -> list[str]:
    tool = job.tool
    cog = ",".join(fmt(v * 1000.0, 3) for v in tool.cog_m)
    n = len(job.targets)
    ids = ",".join(_string(t.point_id) for t in job.targets)
    empty = ",".join(['""'] * n)
    lines = [
        f"    PERS tooldata tSensor:=[TRUE,{pose_text(tool.T_flange_tcp)},"
        f"[{fmt(tool.mass_kg, 3)},[{cog}],[1,0,0,0],0,0,0]];",
        f'    PERS wobjdata wobjNominal:=[FALSE,TRUE,"",{pose_text(job.T_base_wobj)},'
        "[[0,0,0],[1,0,0,0]]];",
        "    CONST speeddata vApproach:=[100,50,5000,1000];",
        f"    CONST num nPoints:={n};",
        f"    PERS string measuredId{{{n}}}:=[{ids}];",
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
            f"    ! {t.point_id} ({t.kind} search, role {t.role}, "
            f"{fmt(t.length_m * 1000.0, 1)} mm at {fmt(t.speed_m_s * 1000.0, 1)} mm/s)",
            f"    CONST robtarget {name}_start:={robtarget_text(t.T_wobj_start, t.confdata)};"
            + note,
            f"    CONST robtarget {name}_end:={robtarget_text(t.T_wobj_end, t.confdata)};",
            f"    CONST speeddata vSearch_{name}:=[{fmt(t.speed_m_s * 1000.0, 3)},30,5000,1000];",
        ]
    return lines


def _probe_proc(i: int, t: TargetPair, name: str) -> list[str]:
    flank = " \\NegFlank" if t.kind == "edge" else ""
    level = (
        "not detecting at the start (not over the face)"
        if t.kind == "edge"
        else ("already detecting at the start")
    )
    length = fmt(t.length_m * 1000.0, 1)
    missed = (
        f"edge not found within {length} mm (sensor kept detecting)"
        if t.kind == "edge"
        else f"no detection within {length} mm"
    )
    wobj = "tSensor\\WObj:=wobjNominal"
    return [
        f"    PROC Probe_{name}()",
        f"        MoveJ {name}_start,vApproach,fine,{wobj};",
        f"        SearchL\\SStop,diSensor{flank},pMeas,{name}_end,vSearch_{name},{wobj};",
        f"        measured{{{i}}}:=PoseVect(wobjNominal.uframe,"
        "PoseVect(wobjNominal.oframe,pMeas.trans));",
        f"        measuredOk{{{i}}}:=TRUE;",
        f'        measuredErr{{{i}}}:="";',
        f"        MoveL {name}_start,vApproach,fine,{wobj};",
        "    ERROR",
        "        IF ERRNO=ERR_WHLSEARCH THEN",
        f'            measuredErr{{{i}}}:="{missed}";',
        "        ELSEIF ERRNO=ERR_SIGSUPSEARCH THEN",
        f'            measuredErr{{{i}}}:="sensor {level}";',
        "        ELSE",
        "            RAISE;",
        "        ENDIF",
        f"        measuredOk{{{i}}}:=FALSE;",
        f'        TPWrite "wobjcal: point {t.point_id} failed: "+measuredErr{{{i}}};',
        f"        MoveL {name}_start,vApproach,fine,{wobj};",
        "        IF bStopOnFail Stop;",
        "        RETURN;",
        "    ENDPROC",
        "",
    ]


def _write_proc() -> list[str]:
    q = '""'
    return [
        "    ! Write the measurements as wobjcal.measurements/1 for `wobjcal calibrate`",
        "    PROC WriteMeasurements()",
        "        VAR iodev file;",
        '        VAR string sep:="";',
        f'        Open "HOME:"\\File:="{MEASURED_FILE}",file\\Write;',
        f'        Write file,"{{{q}schema{q}: {q}wobjcal.measurements/1{q}, '
        f'{q}frame{q}: {q}base{q}, {q}units{q}: {q}mm{q},";',
        f'        Write file," {q}points{q}: {{"\\NoNewLine;',
        "        FOR i FROM 1 TO nPoints DO",
        "            IF measuredOk{i} THEN",
        f'                Write file,sep+"{q}"+measuredId{{i}}+"{q}: ["\\NoNewLine;',
        '                Write file,NumToStr(measured{i}.x,4)+", "\\NoNewLine;',
        '                Write file,NumToStr(measured{i}.y,4)+", "\\NoNewLine;',
        '                Write file,NumToStr(measured{i}.z,4)+"]"\\NoNewLine;',
        '                sep:=", ";',
        "            ENDIF",
        "        ENDFOR",
        f'        Write file,"}}, {q}failed{q}: {{"\\NoNewLine;',
        '        sep:="";',
        "        FOR i FROM 1 TO nPoints DO",
        "            IF NOT measuredOk{i} THEN",
        f'                Write file,sep+"{q}"+measuredId{{i}}+"{q}: {q}"\\NoNewLine;',
        f'                Write file,measuredErr{{i}}+"{q}"\\NoNewLine;',
        '                sep:=", ";',
        "            ENDIF",
        "        ENDFOR",
        '        Write file,"}}";',
        "        Close file;",
        f'        TPWrite "wobjcal: measurements written to HOME:/{MEASURED_FILE}";',
        "    ENDPROC",
    ]


def export_rapid(job: ExportJob) -> str:
    """The RAPID module text of ``job``."""
    names = _unique_names([t.point_id for t in job.targets])
    lines = [
        f"MODULE {job.name}",
        f"    ! Generated by wobjcal {__version__} from plan {job.plan_name!r} "
        f"(procedure {job.method}).",
        "    ! Probes each point with the proximity sensor on digital input diSensor.",
        "    ! Units mm; quaternions [q1,q2,q3,q4] = w, x, y, z; robtargets in wobjNominal.",
        "    ! wobjNominal.uframe = nominal work object in the world frame (= robot base).",
        "    ! confdata [cf1,cf4,cf6,cfx] from the IK branch chosen by `wobjcal check`.",
        "    ! Results: measured{i} (base frame, mm) of point measuredId{i}, and",
        f"    ! HOME:/{MEASURED_FILE} for `wobjcal calibrate PLAN MEASURED`.",
        *_declarations(job, names),
        "",
        "    PROC main()",
        *_conf_lines(job),
        *[f"        Probe_{name};" for name in names],
        "        WriteMeasurements;",
        "    ENDPROC",
        "",
    ]
    for i, (t, name) in enumerate(zip(job.targets, names, strict=True), start=1):
        lines += _probe_proc(i, t, name)
    lines += _write_proc()
    lines.append("ENDMODULE")
    return "\n".join(lines) + "\n"


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
