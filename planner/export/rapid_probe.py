"""The RAPID routines that run one probe point: ``Probe_<name>(num i)`` and its handler.

An approach point: ``MoveJ`` to ``_safe`` (the safe start, :mod:`planner.program.safety`),
``SearchL \\SStop`` to ``_end``, store, retreat to ``_safe``. An edge point: ``MoveJ`` to
``_safe``, an approach ``SearchL`` to ``_face`` (the face the edge search runs along), then
``MoveL`` to the measured face point and ``SearchL \\SStop ... \\NegFlank`` along the plan's
direction up to where the plan's search ends; or, with ``edge_start_from_measured``, start at
a measured point passed in (``startBase``, base frame). ``measured{i}`` is in the base frame:
``pMeas`` is in ``wobjCal`` and converted with its ``uframe`` and ``oframe`` at once.
"""

from __future__ import annotations

from planner.export.job import TargetPair
from planner.export.text import fmt, literal_text

#: The wobjdata every search is commanded in.
WOBJ = "wobjCal"
BS = "\\"


def _store(i: str) -> list[str]:
    """Store the search point: ``pMeas`` is in ``WOBJ``; ``measured`` is in the base frame."""
    return [
        f"        measured{{{i}}}:=PoseVect({WOBJ}.uframe,PoseVect({WOBJ}.oframe,pMeas.trans));",
        f"        measuredOk{{{i}}}:=TRUE;",
        f'        measuredErr{{{i}}}:="";',
    ]


def _handler(t: TargetPair, safe: str, edge_stage: bool) -> list[str]:
    length = fmt(t.length_m * 1000.0, 1)
    if edge_stage:
        missed = (
            f'IF nStage=1 THEN measuredErr{{i}}:="face not found before the edge search"; '
            f'ELSE measuredErr{{i}}:="edge not found within {length} mm"; ENDIF'
        )
        level = (
            'IF nStage=1 THEN measuredErr{i}:="sensor already detecting at the start"; '
            'ELSE measuredErr{i}:="sensor not detecting at the start (not over the face)"; ENDIF'
        )
    else:
        missed = f'measuredErr{{i}}:="no detection within {length} mm";'
        level = 'measuredErr{i}:="sensor already detecting at the start";'
    wobj = f"tSensor{BS}WObj:={WOBJ}"
    return [
        "    ERROR",
        "        IF ERRNO=ERR_WHLSEARCH THEN",
        *_block(missed, 12),
        "        ELSEIF ERRNO=ERR_SIGSUPSEARCH THEN",
        *_block(level, 12),
        "        ELSE",
        "            RAISE;",
        "        ENDIF",
        "        measuredOk{i}:=FALSE;",
        f'        TPWrite "wobjcal: point {literal_text(t.point_id)} failed: "+measuredErr{{i}};',
        f"        MoveL {safe},vApproach,fine,{wobj};",
        "        IF bStopOnFail Stop;",
        "        RETURN;",
        "    ENDPROC",
        "",
    ]


def _block(text: str, indent: int) -> list[str]:
    """Lay out ``IF c THEN a; ELSE b; ENDIF`` (or one statement) one statement per line."""
    pad = " " * indent
    if not text.startswith("IF "):
        return [pad + text]
    head, rest = text.split(" THEN ", 1)
    then, rest = rest.split(" ELSE ", 1)
    other = rest.rsplit(" ENDIF", 1)[0]
    return [
        f"{pad}{head} THEN",
        f"{pad}    {then}",
        f"{pad}ELSE",
        f"{pad}    {other}",
        f"{pad}ENDIF",
    ]


def probe_proc(t: TargetPair, name: str, from_measured: float | None) -> list[str]:
    """The ``PROC Probe_<name>(num i)`` that measures the point into ``measured{i}``.

    Args:
        t: the target.
        name: its RAPID name.
        from_measured: for an edge search that starts at an already measured point
            (``edge_start_from_measured``): the offset of the start along the face normal,
            m; the proc then takes ``pos startBase`` (base frame, mm) and skips the approach
            to the face. ``None``: approach the face first and start from the measured point.
    """
    wobj = f"tSensor{BS}WObj:={WOBJ}"
    safe = f"{name}_safe"
    vias = [
        f"        MoveAbsJ {name}_via{k},vApproach,fine,tSensor;"
        for k in range(1, len(t.vias_q_rad) + 1)
    ]
    if t.kind == "approach":
        return [
            f"    PROC Probe_{name}(num i)",
            *vias,
            f"        MoveJ {safe},vApproach,fine,{wobj};",
            f"        SearchL{BS}SStop,diSensor,pMeas,{name}_end,vSearch_{name},{wobj};",
            *_store("i"),
            f"        MoveL {safe},vApproach,fine,{wobj};",
            *_handler(t, safe, False),
        ]
    params = "num i" if from_measured is None else "num i,pos startBase"
    lines = [
        f"    PROC Probe_{name}({params})",
        "        VAR robtarget pStart;",
        "        VAR robtarget pEnd;",
        "        VAR num nStage:=1;",
        *vias,
        f"        pStart:={name}_start;",
    ]
    if from_measured is None:  # approach the face the edge search runs along, from outside
        lines += [
            f"        MoveJ {safe},vApproach,fine,{wobj};",
            f"        SearchL{BS}SStop,diSensor,pMeas,{name}_face,vSearch_{name},{wobj};",
            "        ! the edge search starts at the measured face point (TCP at the face)",
            "        pStart.trans:=pMeas.trans;",
        ]
    else:  # start at the measured point (base) plus the offset along the face normal
        lines += [
            f"        MoveJ {safe},vApproach,fine,{wobj};",
            f"        pStart.trans:=PoseVect(PoseInv({WOBJ}.uframe),startBase)"
            f"+{fmt(from_measured * 1000.0, 4)}*{name}_normal;",
        ]
    lines += [
        f"        MoveL pStart,vApproach,fine,{wobj};",
        "        ! run along the search direction up to where the plan's search ends",
        f"        pEnd:={name}_end;",
        f"        pEnd.trans:=pStart.trans+DotProd({name}_end.trans-pStart.trans,{name}_dir)"
        f"*{name}_dir;",
        "        ! a start past where the plan's search ends: searching on would run backwards",
        f"        IF DotProd({name}_end.trans-pStart.trans,{name}_dir)<=0 THEN",
        f'            measuredErr{{i}}:="edge not found within {fmt(t.length_m * 1000.0, 1)} mm";',
        "            measuredOk{i}:=FALSE;",
        f'            TPWrite "wobjcal: point {literal_text(t.point_id)} failed: "'
        "+measuredErr{i};",
        f"            MoveL {safe},vApproach,fine,{wobj};",
        "            IF bStopOnFail Stop;",
        "            RETURN;",
        "        ENDIF",
        "        nStage:=2;",
        f"        SearchL{BS}SStop,diSensor{BS}NegFlank,pMeas,pEnd,vSearch_{name},{wobj};",
        *_store("i"),
        f"        MoveL {safe},vApproach,fine,{wobj};",
        *_handler(t, safe, True),
    ]
    return lines


def stop_procs(label: str) -> list[str]:
    """``Fail`` (report, write what was measured, end the program) and ``Require`` (fail
    unless point ``i`` was measured): an adaptive program cannot go on without a point."""
    return [
        "",
        "    ! Stop the procedure: report, write what was measured, end the program",
        "    PROC Fail(string why)",
        f'        TPWrite "wobjcal: {label} stopped: "+why;',
        "        WriteMeasurements;",
        "        EXIT;",
        "    ENDPROC",
        "",
        "    PROC Require(num i)",
        '        IF NOT measuredOk{i} Fail "point "+measuredId{i}+": "+measuredErr{i};',
        "    ENDPROC",
        "",
    ]
