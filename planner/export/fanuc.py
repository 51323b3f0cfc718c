"""FANUC TP export: one ASCII ``.ls`` program that probes every point with skip searches and
keeps the measured points in position registers.

Conventions: millimetres and degrees; a pose is ``X, Y, Z, W, P, R`` with W, P, R the fixed-axis
rotations about x, y, z of the user frame, ``R = Rz(R) @ Ry(P) @ Rx(W)``: the paper's Tait-Bryan
z-y'-x'' angles with (alpha, beta, gamma) = (R, P, W)
(:func:`calib.frames.tait_bryan_zyx_from_matrix`). The program writes the nominal work object
into ``PR[PR_UFRAME]`` and sets ``UFRAME[UFRAME_NO]`` from it (relative to WORLD, taken to be the
robot base of the plan, as KRL takes ``$WORLD``), and the sensor TCP into ``PR[PR_UTOOL]`` ->
``UTOOL[UTOOL_NO]``; every ``P[]`` is a sensor-TCP pose in that user frame with that tool, with
the ``CONFIG`` of the robot's configuration there (:func:`config_text`: flip, up, top and the
turn numbers of :data:`TURN_AXES`, from the IK solution at that target next to the pose
``wobjcal check`` chose). A target without a checked pose (``--no-check``, a point check
refuses, exported with ``--force``; a robot that is not a 6-axis OPW arm) has no ``CONFIG`` to
derive, and none is guessed: it is written as a position register built from ``LPOS`` (``PR[k]=
LPOS``, then its six components), so the robot keeps the configuration and turn numbers it has
when it gets there, as a KRL target without ``S`` and ``T`` does; the header names those points
and says to run the program the first time in T1 (:data:`PR_SAFE`, :data:`PR_TARGET`).

Every search runs in the nominal user frame (not adaptive; the frame comes from ``wobjcal
calibrate``) and starts at the safe start of :mod:`planner.program.safety`. A search is
``SKIP CONDITION DI[SENSOR_DI]=ON`` (approach) or ``=OFF`` (edge) and a linear move to the end
point ``... FINE Skip,LBL[i],PR[k]=LPOS``: when the input switches, the robot stops, ``PR[k]``
holds the TCP where the skip fired (user frame) and the next line runs; when it never switches,
the robot reaches the end point and the program jumps to ``LBL[i]``. An edge point first runs an
approach search to its face (``face_end``), then the edge search from the measured face point
(orientation of the plan's edge start) along the plan's direction up to the plan's end, as the
KRL export does. Results, point ``i`` (1-based, plan order): ``PR[PR_MEAS_BASE + i]`` the measured
TCP (user frame, mm) and ``R[R_CODE_BASE + i]`` 0 measured, 1 no detection on the path, 2 the
input already at the searched level at the start, 3 not run (program stopped before).

Limits relied on (conservative; larger on recent controllers): program names of at most 36
characters (letters, digits, ``_``, starting with a letter), ``!`` comments of at most 32
characters, position comments of at most 16, ``PR[1..100]``, ``R[1..200]`` (the default register
counts), user frames 1-9 and tool frames 1-10.

Via points (``points[i].vias``) are ``P[]`` in joint representation (``J1= ... deg``), reached
with ``J P[n] ... FINE`` before the point's safe start. The joint values are the URDF's: on a
controller whose J3 is measured against the horizontal (the FANUC J2/J3 interaction that the
ROS-Industrial driver converts) J3 must be corrected before running; the program says so.
"""

from __future__ import annotations

import numpy as np

from calib._version import __version__
from calib.errors import InputError
from planner.export.fanuc_text import (
    COMMENT_MAX,
    JOINT_PCT,
    LINEAR_MM_S,
    NAME_MAX,
    POS_COMMENT_MAX,
    TURN_AXES,
    _ascii_ident,
    _const,
    _pos_num,
    comment_lines,
    config_text,
    program_name,
    turn_number,
    wpr_deg,
    xyzwpr,
)
from planner.export.job import (
    ExportJob,
    TargetPair,
    check_header,
    cycle_header,
    digest_text,
    safety_header,
)
from planner.export.paste import PasteLines
from planner.export.text import fmt

__all__ = [
    "COMMENT_MAX",
    "NAME_MAX",
    "POS_COMMENT_MAX",
    "TURN_AXES",
    "comment_lines",
    "config_text",
    "export_fanuc",
    "paste_lines",
    "program_name",
    "turn_number",
    "wpr_deg",
    "xyzwpr",
]

#: User frame of the nominal work object (``UFRAME[9]``).
UFRAME_NO = 9
#: Tool frame of the sensor TCP (``UTOOL[9]``).
UTOOL_NO = 9
#: Digital input of the proximity sensor (``DI[1]``).
SENSOR_DI = 1
#: Position register the nominal work object is written to before ``UFRAME[UFRAME_NO]=PR[1]``.
PR_UFRAME = 1
#: Position register the sensor TCP is written to before ``UTOOL[UTOOL_NO]=PR[2]``.
PR_UTOOL = 2
#: Scratch: start of an edge search (the measured face point).
PR_EDGE_START = 3
#: Scratch: end of an edge search.
PR_EDGE_END = 4
#: Scratch: the face point measured by the approach search of an edge point.
PR_FACE = 5
#: Scratch: the safe start of a point without a checked pose there (``LPOS`` + components).
PR_SAFE = 6
#: Scratch: the end of the first search of a point without a checked pose there.
PR_TARGET = 7
#: Point ``i`` (1-based) is measured into ``PR[PR_MEAS_BASE + i]``: PR[11], PR[12], ...
PR_MEAS_BASE = 10
#: Point ``i`` (1-based) reports its result code in ``R[R_CODE_BASE + i]``: R[11], R[12], ...
R_CODE_BASE = 10
#: Scratch numeric registers (the edge search's projection).
R_TMP = (1, 2)
#: Position and numeric registers the program may use (the controllers' default counts).
PR_COUNT = 100
R_COUNT = 200
#: Most points one program can probe (PR[11..100]).
MAX_POINTS = min(PR_COUNT - PR_MEAS_BASE, R_COUNT - R_CODE_BASE)


class _Program:
    """The ``/MN`` instructions and the ``/POS`` positions of the program being written."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.positions: list[str] = []

    def add(self, instruction: str) -> None:
        self.lines.append(instruction)

    def comment(self, text: str) -> None:
        self.lines += ["!" + c for c in comment_lines(text)]

    def target(self, t: TargetPair, kind: str, label: str, pr: int) -> str:
        """The target ``kind`` of ``t`` as a motion's destination: ``P[n]`` (:meth:`position`)
        when the robot's configuration there is known, else ``PR[pr]`` written here from
        ``LPOS`` and the target's six components (:meth:`set_register`), so the robot keeps its
        current configuration and turn numbers (written where the motion starts)."""
        if t.arm_pose(kind) is None:
            self.set_register(pr, t.target(kind))
            return f"PR[{pr}]"
        return f"P[{self.position(t, kind, label)}]"

    def copy_target(self, pr: int, t: TargetPair, kind: str, label: str) -> None:
        """``PR[pr]`` = the target ``kind`` of ``t``: ``PR[pr]=P[n]`` when its configuration is
        known, else from ``LPOS`` and its six components (the robot's configuration)."""
        if t.arm_pose(kind) is None:
            self.set_register(pr, t.target(kind))
        else:
            self.add(f"PR[{pr}]=P[{self.position(t, kind, label)}]")

    def position(self, t: TargetPair, kind: str, label: str) -> int:
        """Add the sensor-TCP pose of target ``kind`` of ``t`` (user frame) as the next
        ``P[n]`` with its configuration; return ``n``.

        Raises:
            ValueError: the robot's configuration there is not known (use :meth:`target`).
        """
        arm = t.arm_pose(kind)
        if arm is None:
            raise ValueError(f"point {t.point_id}: no configuration at its {kind} target")
        n = len(self.positions) + 1
        x, y, z, w, p, r = (_pos_num(v) for v in xyzwpr(t.target(kind)))
        self.positions.append(
            f'P[{n}:"{label[:POS_COMMENT_MAX]}"]{{\n'
            "   GP1:\n"
            f"\tUF : {UFRAME_NO}, UT : {UTOOL_NO},\t\tCONFIG : '{config_text(arm)}',\n"
            f"\tX = {x}  mm,\tY = {y}  mm,\tZ = {z}  mm,\n"
            f"\tW = {w} deg,\tP = {p} deg,\tR = {r} deg\n"
            "};"
        )
        return n

    def joint_position(self, deg: tuple[float, ...], label: str) -> int:
        """Add the joint values ``deg`` (J1..J6, degrees) as the next ``P[n]`` in joint
        representation (no frame, no configuration: a joint target is unambiguous); return
        ``n``."""
        n = len(self.positions) + 1
        j = [f"J{k}= {_pos_num(v)} deg" for k, v in enumerate(deg, start=1)]
        first, second = ",\t".join(j[:3]), ",\t".join(j[3:])
        self.positions.append(
            f'P[{n}:"{label[:POS_COMMENT_MAX]}"]{{\n'
            "   GP1:\n"
            f"\tUF : {UFRAME_NO}, UT : {UTOOL_NO},\n"
            f"\t{first},\n"
            f"\t{second}\n"
            "};"
        )
        return n

    def set_register(self, pr: int, T: np.ndarray) -> None:
        """``PR[pr]`` = the pose ``T`` (m), component by component (mm, degrees)."""
        self.add(f"PR[{pr}]=LPOS")  # a Cartesian position register, then its six components
        for k, v in enumerate(xyzwpr(T), start=1):
            self.add(f"PR[{pr},{k}]={_const(v)}")

    def mn(self) -> str:
        out = []
        for i, line in enumerate(self.lines, start=1):
            pad = "" if line[:2] in ("J ", "L ") else "  "
            out.append(f"{i:4d}:{pad}{line} ;")
        return "\n".join(out)


def paste_lines(T_base_wobj: np.ndarray) -> PasteLines:
    """The calibrated work object as the TP instructions the programs set their user frame
    with (the export registry's paste lines): ``PR[PR_UFRAME]`` component by component (X, Y,
    Z mm; W, P, R deg), then ``UFRAME[UFRAME_NO]=PR[PR_UFRAME]``, relative to WORLD taken to be
    the robot base."""
    prog = _Program()
    prog.set_register(PR_UFRAME, T_base_wobj)
    prog.add(f"UFRAME[{UFRAME_NO}]=PR[{PR_UFRAME}]")
    return PasteLines(
        f"TP instructions, WORLD = robot base; user frame {UFRAME_NO}",
        tuple(f"{line} ;" for line in prog.lines),
    )


def export_fanuc(job: ExportJob) -> dict[str, str]:
    """The FANUC TP program of ``job``: ``{".ls": text}``.

    Raises:
        InputError: more points than :data:`MAX_POINTS` (the register block holds).
    """
    n = len(job.targets)
    if n > MAX_POINTS:
        raise InputError(
            f"a FANUC program holds at most {MAX_POINTS} points (PR[{PR_MEAS_BASE + 1}.."
            f"{PR_COUNT}]), the plan has {n}; split the plan"
        )
    name = program_name(job.name)
    prog = _Program()
    _header(prog, job, name)
    prog.set_register(PR_UFRAME, job.T_controller_wobj)
    prog.set_register(PR_UTOOL, job.tool.T_flange_tcp)
    prog.add(f"UFRAME[{UFRAME_NO}]=PR[{PR_UFRAME}]")
    prog.add(f"UTOOL[{UTOOL_NO}]=PR[{PR_UTOOL}]")
    prog.add(f"UFRAME_NUM={UFRAME_NO}")
    prog.add(f"UTOOL_NUM={UTOOL_NO}")
    for i in range(1, n + 1):
        prog.add(f"R[{R_CODE_BASE + i}]=3")
    for i, t in enumerate(job.targets, start=1):
        _point(prog, i, t)
    text = "\n".join(
        [
            f"/PROG  {name}",
            "/ATTR",
            "OWNER\t\t= MNEDITOR;",
            'COMMENT\t\t= "wobjcal probe";',
            "PROG_SIZE\t= 0;",
            "FILE_NAME\t= ;",
            "VERSION\t\t= 0;",
            f"LINE_COUNT\t= {len(prog.lines)};",
            "MEMORY_SIZE\t= 0;",
            "PROTECT\t\t= READ_WRITE;",
            "TCD:  STACK_SIZE\t= 0,",
            "      TASK_PRIORITY\t= 50,",
            "      TIME_SLICE\t= 0,",
            "      BUSY_LAMP_OFF\t= 0,",
            "      ABORT_REQUEST\t= 0,",
            "      PAUSE_REQUEST\t= 0;",
            "DEFAULT_GROUP\t= 1,*,*,*,*;",
            "CONTROL_CODE\t= 00000000 00000000;",
            "/MN",
            prog.mn(),
            "/POS",
            *prog.positions,
            "/END",
            "",
        ]
    )
    return {".ls": text}


def _header(prog: _Program, job: ExportJob, name: str) -> None:
    """The comment lines at the top of ``/MN``: provenance (version, plan, digest), what was
    checked, units, frames, safety, results, and the points written without ``CONFIG``."""
    n = len(job.targets)
    tool = job.tool
    cog = ", ".join(fmt(c * 1000.0, 1) for c in tool.cog_m)
    first, last = PR_MEAS_BASE + 1, PR_MEAS_BASE + n
    no_config = [
        _ascii_ident(t.point_id)
        for t in job.targets
        if any(t.arm_pose(k) is None for k in _KINDS.get(t.kind, ("safe", "end")))
    ]
    scratch = PR_TARGET if no_config else PR_FACE
    for text in (
        f"Generated by wobjcal {__version__} from plan {job.plan_name} (procedure {job.method}). "
        f"Save as {name}.ls (file name = program name).",
        digest_text(job),  # one comment line: what a results reader looks for
        check_header(job, "fanuc"),
        cycle_header(job, "fanuc"),
        "Units mm, deg. W,P,R: fixed angles about x,y,z of the user frame, R = Rz(R) Ry(P) "
        "Rx(W) (the paper's Tait-Bryan z-y-x angles alpha,beta,gamma = R,P,W).",
        f"UFRAME[{UFRAME_NO}] = PR[{PR_UFRAME}] = nominal work object in WORLD, taken to be the "
        f"plan's robot base: check WORLD before the run. UTOOL[{UTOOL_NO}] = PR[{PR_UTOOL}] = "
        f"sensor TCP in the flange. Sensor on DI[{SENSOR_DI}]. Tool {fmt(tool.mass_kg, 3)} kg, "
        f"COG [{cog}] mm: set the payload schedule on the controller.",
        " ".join(safety_header(job, "fanuc", "", 10_000)),
        f"Results: PR[{first}]..PR[{last}] = point 1..{n}: TCP where the skip fired (LPOS), "
        f"UFRAME[{UFRAME_NO}], mm. R[{R_CODE_BASE + 1}]..R[{R_CODE_BASE + n}] = 0 measured, "
        "1 no detection, 2 input already at the searched level at the start, 3 not run. A PR "
        "is valid only when its R is 0.",
        "Points: "
        + ", ".join(f"{i}={_ascii_ident(t.point_id)}" for i, t in enumerate(job.targets, start=1)),
        "Read back: PR[] on the TP (DATA) or in MD:POSREG.VA, R[] in MD:NUMREG.VA. Convert each "
        f"point to the base, p_base = Rot(W,P,R) p + (X,Y,Z) with the PR[{PR_UFRAME}] values set "
        "below, and write a wobjcal.measurements/1 file (frame base, units mm) for wobjcal "
        "calibrate.",
        f"Overwrites PR[{PR_UFRAME}]..PR[{scratch}], PR[{first}]..PR[{last}], "
        f"R[{R_TMP[0]}]..R[{R_TMP[1]}], R[{R_CODE_BASE + 1}]..R[{R_CODE_BASE + n}]. CONFIG of "
        "every P[] from the pose wobjcal check chose (turn numbers of "
        + ", ".join(f"J{a}" for a in TURN_AXES)
        + ": check $SCR_GRP[1].$TURN_AXIS); run the first time in T1. Limits "
        f"assumed: name {NAME_MAX}, comment {COMMENT_MAX} chars, PR[1..{PR_COUNT}], "
        f"R[1..{R_COUNT}].",
    ):
        prog.comment(text)
    if no_config:
        prog.comment(
            f"NO CONFIG for points {', '.join(no_config)} (no checked robot pose): their targets "
            f"are PR[{PR_SAFE}], PR[{PR_TARGET}], PR[{PR_EDGE_START}], PR[{PR_EDGE_END}] made "
            "from LPOS, so the robot keeps its current configuration and turn numbers there. "
            "Run the first time in T1 at low override."
        )
    if any(t.vias_q_rad for t in job.targets):
        prog.comment(
            "Via points: P[] in joint representation, the URDF's joint values (no offsets). "
            "Where the controller measures J3 against the horizontal (J2/J3 interaction), "
            "correct J3 first. Joint positions have no CONFIG."
        )


#: The targets a point's program moves to, by search kind.
_KINDS = {"approach": ("safe", "end"), "edge": ("safe", "face", "start", "end")}


def _point(prog: _Program, i: int, t: TargetPair) -> None:
    """Probe point ``i``: approach search from the safe start; for an edge point, then the
    edge search from the measured face point along the plan's direction to the plan's end."""
    ident = _ascii_ident(t.point_id)
    code, meas, label = R_CODE_BASE + i, PR_MEAS_BASE + i, i
    speed = max(1, round(t.speed_m_s * 1000.0))
    keep = POS_COMMENT_MAX - 6
    vias = [
        prog.joint_position(deg, f"{ident[:keep]} v{k}")
        for k, deg in enumerate(t.vias_deg("FANUC"), start=1)
    ]
    prog.comment(f"--- point {i} {ident}: {t.kind} search")
    for n in vias:
        prog.add(f"J P[{n}] {JOINT_PCT}% FINE")
    safe = prog.target(t, "safe", f"{ident[:keep]} safe", PR_SAFE)
    prog.add(f"J {safe} {JOINT_PCT}% FINE")
    first = "end" if t.kind == "approach" else "face"
    goal = prog.target(t, first, f"{ident[:keep]} {first}", PR_TARGET)
    prog.add(f"R[{code}]=2")
    prog.add(f"IF DI[{SENSOR_DI}]=ON,JMP LBL[{label}]")
    prog.add(f"R[{code}]=1")
    prog.add(f"SKIP CONDITION DI[{SENSOR_DI}]=ON")
    if t.kind == "approach":
        prog.add(f"L {goal} {speed}mm/sec FINE Skip,LBL[{label}],PR[{meas}]=LPOS")
    else:
        prog.add(f"L {goal} {speed}mm/sec FINE Skip,LBL[{label}],PR[{PR_FACE}]=LPOS")
        prog.comment("edge start: the measured face point, plan orientation")
        s, e = PR_EDGE_START, PR_EDGE_END
        prog.copy_target(s, t, "start", f"{ident[:keep]} start")
        for k in (1, 2, 3):
            prog.add(f"PR[{s},{k}]=PR[{PR_FACE},{k}]")
        prog.add(f"L PR[{s}] {LINEAR_MM_S}mm/sec FINE")
        prog.copy_target(e, t, "end", f"{ident[:keep]} end")
        _project_end(prog, t.edge_direction_wobj)
        prog.add(f"R[{code}]=2")
        prog.add(f"IF DI[{SENSOR_DI}]=OFF,JMP LBL[{label}]")
        prog.add(f"R[{code}]=1")
        prog.add(f"SKIP CONDITION DI[{SENSOR_DI}]=OFF")
        prog.add(f"L PR[{e}] {speed}mm/sec FINE Skip,LBL[{label}],PR[{meas}]=LPOS")
    prog.add(f"R[{code}]=0")
    prog.add(f"LBL[{label}]")
    prog.add(f"L {safe} {LINEAR_MM_S}mm/sec FINE")


def _project_end(prog: _Program, d: np.ndarray) -> None:
    """``PR[end] = PR[start] + ((PR[end] - PR[start]) . d) d`` in x, y, z (``d`` a unit vector,
    user frame): the plan's end projected on the line along ``d`` through the measured start.
    One operation per line, no negative constant (a negative ``d`` swaps the operands)."""
    s, e = PR_EDGE_START, PR_EDGE_END
    acc, tmp = R_TMP
    terms = [k for k in range(3) if abs(d[k]) > 1e-12]
    prog.comment(f"end: along the plan's edge direction, R[{acc}] = travel mm")
    for j, k in enumerate(terms):
        a, b = (e, s) if d[k] > 0 else (s, e)
        reg = acc if j == 0 else tmp
        prog.add(f"R[{reg}]=PR[{a},{k + 1}]-PR[{b},{k + 1}]")
        if abs(abs(d[k]) - 1.0) > 1e-12:
            prog.add(f"R[{reg}]=R[{reg}]*{_const(abs(d[k]))}")
        if j > 0:
            prog.add(f"R[{acc}]=R[{acc}]+R[{tmp}]")
    for k in range(3):
        if k not in terms:
            prog.add(f"PR[{e},{k + 1}]=PR[{s},{k + 1}]")
            continue
        step = acc
        if abs(abs(d[k]) - 1.0) > 1e-12:
            step = tmp
            prog.add(f"R[{tmp}]=R[{acc}]*{_const(abs(d[k]))}")
        prog.add(f"PR[{e},{k + 1}]=PR[{s},{k + 1}]{'+' if d[k] > 0 else '-'}R[{step}]")
