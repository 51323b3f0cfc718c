"""The KRL that searches and probes one point: the search routines, a point's probe lines, and
the ``x<ID>_probe`` routine of an adaptive program.

A search moves ``LIN`` to its end with ``INTERRUPT ... WHEN diSensor==TRUE`` (approach) or
``==FALSE`` (edge); the interrupt routine brakes, stores ``$POS_INT`` (in the current ``$BASE``)
in ``xHit`` and ``RESUME``-s. KRL's ``RESUME`` ends the routines below the one that declared
the interrupt and goes on in it after its call into the level below, so the search routines
(``SEARCH_RISE``, ``SEARCH_FALL``) declare the interrupt and run the ``LIN`` one level below, in
``SEARCH_MOVE`` (which ends with ``WAIT SEC 0`` so that the advance run stays there).

A point is probed from its safe start ``x<ID>_safe`` (:mod:`planner.program.safety`): an
approach point searches to ``x<ID>_end``; an edge point first approaches the face its edge
search runs along (to ``x<ID>_face``) and runs the edge search from the measured face point
along the plan's direction up to where the plan's search ends; or, in the adaptive A-H program
with ``edge_start_from_measured``, from a measured point (E for F, G for H) moved out along the
face normal. ``xMeas[i]`` gets the point in the robot base (``BASE_DATA[10]:xHit``, mm),
``nFail[i]`` 0 (measured), 1 (no detection on the path, or the measured face point lies past
the end of the edge search) or 2 (the input was already at the searched level at the start).
The nominal program writes these lines into its main program once per point; the adaptive one
wraps them in ``x<ID>_probe(nI)``, called from its measuring routine as its steps say, which
stops at the first point not measured (:func:`probe_call`).
"""

from __future__ import annotations

from planner.export.job import TargetPair
from planner.export.krl_text import BASE_NO, factor
from planner.export.text import comment_text, fmt

#: The interrupt priorities of the two search routines.
PRIORITIES = {"SEARCH_RISE": 20, "SEARCH_FALL": 21}


def search_routines() -> list[str]:
    """``SEARCH_RISE``/``SEARCH_FALL`` (declare the interrupt, search one level below),
    ``HIT_20``/``HIT_21`` (store ``$POS_INT``, ``RESUME``) and ``SEARCH_MOVE`` (the ``LIN``)."""
    lines: list[str] = []
    for routine, level in (("SEARCH_RISE", "TRUE"), ("SEARCH_FALL", "FALSE")):
        prio = PRIORITIES[routine]
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
    return [
        *lines,
        "DEF SEARCH_MOVE(xTo:IN)",
        "  DECL E6POS xTo",
        "  LIN xTo",
        "  WAIT SEC 0 ; stop the advance run here, so that RESUME ends this routine",
        "END",
        "",
    ]


def record_lines(i: str, pad: str) -> list[str]:
    """Store the point the last search found (``xHit``, in ``$BASE``) in the robot base."""
    return [
        f"{pad}IF bHit THEN",
        f"{pad}  xMeas[{i}]=BASE_DATA[{BASE_NO}]:xHit",
        f"{pad}  nFail[{i}]=0",
        f"{pad}ELSE",
        f"{pad}  nFail[{i}]=1",
        f"{pad}ENDIF",
    ]


def _edge_search(i: str, t: TargetPair, name: str, pad: str) -> list[str]:
    """From ``xStart`` (reached): the edge search along the plan's direction up to where the
    plan's search ends (``x<ID>_end`` projected on that line), if that lies ahead."""
    v = fmt(t.speed_m_s, 6)
    d = t.edge_direction_wobj
    dot = "+".join(f"({name}_end.{c}-xStart.{c})*{factor(d[k])}" for k, c in enumerate("XYZ"))
    return [
        f"{pad}fDot={dot}",
        f"{pad}IF fDot<=0 THEN",
        f"{pad}  nFail[{i}]=1 ; the start lies past the end of the edge search",
        f"{pad}ELSE",
        f"{pad}  xEnd={name}_end",
        *[f"{pad}  xEnd.{c}=xStart.{c}+fDot*{factor(d[k])}" for k, c in enumerate("XYZ")],
        f"{pad}  IF diSensor==FALSE THEN",
        f"{pad}    nFail[{i}]=2",
        f"{pad}  ELSE",
        f"{pad}    SEARCH_FALL(xEnd,{v})",
        *record_lines(i, pad + "    "),
        f"{pad}  ENDIF",
        f"{pad}ENDIF",
    ]


def point_lines(i: str, t: TargetPair, name: str) -> list[str]:
    """Probe one point into slot ``i`` (an INT literal or variable): an approach search from
    ``_safe``; for an edge point, then the edge search from the measured face point along the
    plan's direction, up to the plan's end."""
    v = fmt(t.speed_m_s, 6)
    vias = [
        f"  PTP {name}_v{k} ; via {k} (axis angles, deg)" for k in range(1, len(t.vias_q_rad) + 1)
    ]
    head = [
        *vias,
        "  $VEL.CP=0.1",
        f"  PTP {name}_safe",
        "  IF diSensor==TRUE THEN",
        f"    nFail[{i}]=2",
        "  ELSE",
    ]
    tail = ["  ENDIF", "  $VEL.CP=0.1", f"  LIN {name}_safe"]
    if t.kind == "approach":
        return [*head, f"    SEARCH_RISE({name}_end,{v})", *record_lines(i, "    "), *tail]
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
        *_edge_search(i, t, name, "      "),
        "    ELSE",
        f"      nFail[{i}]=1",
        "    ENDIF",
        *tail,
    ]


def probe_routine(t: TargetPair, name: str, from_measured_mm: float | None) -> list[str]:
    """``DEF x<ID>_probe(nI:IN)``: probe the point into slot ``nI``.

    Args:
        t: the target.
        name: its KRL name ``x<ID>``.
        from_measured_mm: for an edge search that starts at a measured point
            (``edge_start_from_measured``): the offset of the start along the face normal, mm;
            the routine then takes ``xFrom`` (the point, robot base, mm) and moves from the
            safe start straight to it, with no approach to the face. ``None``: approach the
            face first and start from the measured face point.
    """
    head = [
        f"; {comment_text(t.point_id)}: {comment_text(t.kind)} search, role {comment_text(t.role)}"
    ]
    if from_measured_mm is None:
        return [
            *head,
            f"DEF {name}_probe(nI:IN)",
            "  DECL INT nI",
            *point_lines("nI", t, name),
            "END",
            "",
        ]
    n = t.normal_wobj
    vias = [
        f"  PTP {name}_v{k} ; via {k} (axis angles, deg)" for k in range(1, len(t.vias_q_rad) + 1)
    ]
    start = [
        f"  xStart.{c}=xFromW.{c}+{factor(from_measured_mm * n[k])}" for k, c in enumerate("XYZ")
    ]
    return [
        *head,
        f"DEF {name}_probe(nI:IN,xFrom:IN)",
        "  DECL INT nI",
        "  DECL FRAME xFrom",
        "  DECL FRAME xFromW",
        *vias,
        "  $VEL.CP=0.1",
        f"  PTP {name}_safe",
        f"  ; start at the measured point moved {fmt(from_measured_mm, 4)} mm out along the face",
        "  ; normal (the point in the base, the start in the estimate BASE_DATA[10])",
        f"  xFromW=INV_POS(BASE_DATA[{BASE_NO}]):xFrom",
        f"  xStart={name}_start",
        *start,
        "  $VEL.CP=0.1",
        "  LIN xStart",
        *_edge_search("nI", t, name, "  "),
        "  $VEL.CP=0.1",
        f"  LIN {name}_safe",
        "END",
        "",
    ]


def failed_function() -> list[str]:
    """``FAILED(nSlot)``: whether slot ``nSlot`` was not measured; then the program stops
    (``nResult`` 2, ``nStopAt`` the slot): an adaptive program cannot go on without it."""
    return [
        "; Stop the adaptive program when point nSlot was not measured (nFail says why)",
        "DEFFCT BOOL FAILED(nSlot:IN)",
        "  DECL INT nSlot",
        "  IF nFail[nSlot]==0 THEN",
        "    RETURN FALSE",
        "  ENDIF",
        "  nResult=2",
        "  nStopAt=nSlot",
        "  RETURN TRUE",
        "ENDFCT",
        "",
    ]


def probe_call(name: str, slot: int, pad: str, start_from: str | None = None) -> list[str]:
    """Probe a point into ``slot`` and leave the measuring routine when it was not measured."""
    arg = f",{start_from}" if start_from else ""
    return [
        f"{pad}{name}_probe({slot}{arg})",
        f"{pad}IF FAILED({slot}) THEN",
        f"{pad}  RETURN",
        f"{pad}ENDIF",
    ]
