"""A small interpreter for the FANUC TP subset that ``planner.export.fanuc`` writes, and the
parser of the ASCII ``.ls`` it runs.

:func:`parse_ls` reads a program back (sections, numbered ``/MN`` lines, ``/POS`` positions in
Cartesian and joint representation) and asserts its layout on the way. :class:`TPMachine` runs
its ``/MN`` instructions, each exactly as the exporter writes it (anything else fails):
comments, ``LBL[i]``, ``PR[i]=LPOS``, ``PR[i]=P[n]``, ``PR[i,j]=a`` and ``R[i]=a`` with at
most one ``+``/``-``/``*``, ``UFRAME[i]=PR[j]``/``UTOOL[i]=PR[j]``, ``UFRAME_NUM``/``UTOOL_NUM``,
``IF DI[1]=ON|OFF,JMP LBL[i]``, ``SKIP CONDITION DI[1]=ON|OFF``, ``J P[n]|PR[n] k% FINE`` and
``L P[n]|PR[n] v mm/sec FINE`` with or without ``Skip,LBL[i],PR[k]=LPOS``.

Frames (mm and degrees; WORLD = the robot base): a Cartesian ``P[]`` or ``PR[]`` target puts the
TCP at ``UFRAME[UFRAME_NUM] @ target``; a ``P[]`` whose ``UF``/``UT`` are not the active numbers
is an error, as on the controller. ``LPOS`` is the TCP in the active user frame. A ``J`` to a
joint-represented ``P[]`` (a via) is recorded and leaves the TCP unknown (no kinematics here):
anything that needs it before the next Cartesian target fails. Registers hold doubles (a real
controller's are single precision: these tests hold the text's written decimals, not the
controller's arithmetic). Reading a register never written, or selecting a frame number never
set, fails (a controller would use whatever it holds).

Sensor (the input ``DI[1]``): its level is off at the start. After a motion that moves the TCP
(more than 1e-9 m) and is no search, it is ``rest_level(T_base_tcp)`` when that callback is
given, else off (the program's moves end at safe starts, clear of the part); a motion that does
not move it leaves it as it was; after a joint move to joint values it is unknown, and reading
it fails. A skip motion (``L ... Skip,LBL[i],PR[k]=LPOS``; a ``SKIP CONDITION`` must be set):

- the input already at the condition's level: the skip fires at once, the robot does not move
  (``PR[k]`` = the TCP there), the next line runs;
- else ``search(start_m, end_m, sensor_axis, neg_flank)`` is asked once (robot base, metres,
  the target's z axis, ``neg_flank`` when the input is on and the condition waits for it to go
  off: the contract of :mod:`tests.rapid_interp`). A ``(3,)`` point (on the commanded line, to
  1e-9 m) is where the input switches: the robot stops there (an ideal stop: the position the
  high-speed skip records), the input is at the condition's level, ``PR[k]`` = that TCP and the
  next line runs. ``"ERR_SIGSUPSEARCH"``: the input was already at the condition's level as the
  motion began, so the skip fires at once as above. Any other string: no change on the way, the
  robot reaches the target and the program jumps to ``LBL[i]``.
"""

from __future__ import annotations

import itertools
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Self

import numpy as np
from scipy.spatial.transform import Rotation

from calib.frames import (
    invert_transform,
    make_transform,
    matrix_from_rotvec,
    rotvec_from_matrix,
    transform_points,
)
from planner.export import fanuc as F

#: ``search(start_m, end_m, sensor_axis, neg_flank) -> (3,) point (base, m) or a string``.
SearchFn = Callable[[np.ndarray, np.ndarray, np.ndarray, bool], Any]
#: The sensor input's level with the TCP at rest at ``T_base_tcp`` (``(4, 4)``, m).
RestLevelFn = Callable[[np.ndarray], bool]
#: The callback's answer meaning "already at the searched level as the motion began".
AT_START = "ERR_SIGSUPSEARCH"
#: A motion shorter than this (m) leaves the sensor input as it was.
MOVE_TOL_M = 1e-9
#: A search answer farther than this from the commanded line (m) is refused.
LINE_TOL_M = 1e-9
#: Instructions one run may execute (an endless loop fails instead of hanging the test).
MAX_STEPS = 100_000

NUM = r"-?\d+\.\d+"
CONST = r"\d+(?:\.\d+)?|\(-\d+(?:\.\d+)?\)"
OPERAND = rf"PR\[\d+,[1-6]\]|R\[\d+\]|{CONST}"
COMMENT = r"![A-Za-z0-9 _+*/=.,:()<>\[\]#%&?@-]{1,32}"
POS = re.compile(
    r'P\[(\d+):"([A-Za-z0-9_ ]{0,16})"\]\{\n   GP1:\n'
    r"\tUF : (\d+), UT : (\d+),\t\tCONFIG : '([^'\n]*)',\n"
    rf"\tX = ({NUM})  mm,\tY = ({NUM})  mm,\tZ = ({NUM})  mm,\n"
    rf"\tW = ({NUM}) deg,\tP = ({NUM}) deg,\tR = ({NUM}) deg\n}};"
)
#: A via: joint representation (``J1= ... deg``), no configuration.
JPOS = re.compile(
    r'P\[(\d+):"([A-Za-z0-9_ ]{0,16})"\]\{\n   GP1:\n'
    r"\tUF : (\d+), UT : (\d+),\n"
    rf"\tJ1= ({NUM}) deg,\tJ2= ({NUM}) deg,\tJ3= ({NUM}) deg,\n"
    rf"\tJ4= ({NUM}) deg,\tJ5= ({NUM}) deg,\tJ6= ({NUM}) deg\n}};"
)
_SKIP_MOVE = re.compile(r"L (P|PR)\[(\d+)\] \d+mm/sec FINE(?: Skip,LBL\[(\d+)\],PR\[(\d+)\]=LPOS)?")


class TPError(AssertionError):
    """The program did something the controller would refuse, or the interpreter cannot model."""


# ------------------------------------------------------------------ poses


def rot_wpr(w: float, p: float, r: float) -> np.ndarray:
    """FANUC W, P, R (deg) to a matrix, built here by hand: ``Rz(r) @ Ry(p) @ Rx(w)``."""
    w, p, r = np.radians([w, p, r])
    Rx = np.array([[1, 0, 0], [0, np.cos(w), -np.sin(w)], [0, np.sin(w), np.cos(w)]])
    Ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    Rz = np.array([[np.cos(r), -np.sin(r), 0], [np.sin(r), np.cos(r), 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def pose_matrix(v: np.ndarray) -> np.ndarray:
    """``[X, Y, Z, W, P, R]`` (mm, deg) to a transform in metres."""
    return make_transform(rot_wpr(*v[3:]), np.asarray(v[:3]) / 1000.0)


def pose_values(T: np.ndarray) -> np.ndarray:
    """A transform (m) to ``[X, Y, Z, W, P, R]`` (mm, deg) with scipy (extrinsic xyz)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # gimbal lock at P = +-90: any split of W, R is fine
        wpr = Rotation.from_matrix(T[:3, :3]).as_euler("xyz", degrees=True)
    return np.array([*(T[:3, 3] * 1000.0), *wpr])


# ------------------------------------------------------------------ parsing the .ls back


@dataclass
class Position:
    comment: str
    uf: int
    ut: int
    config: str
    values: np.ndarray  # X, Y, Z, W, P, R (mm, deg); a via: J1..J6 (deg)


@dataclass
class Program:
    name: str
    attr: str
    lines: list[str]  # /MN instructions without line number and " ;"
    positions: dict[int, Position]
    joints: dict[int, Position] = field(default_factory=dict)  # vias: J1..J6, deg


def parse_ls(text: str) -> Program:
    """The sections of a TP ASCII program; asserts its layout on the way."""
    rows = text.split("\n")
    assert text.endswith("/END\n")
    heads = [i for i, row in enumerate(rows) if row.startswith("/")]
    assert [rows[i].split()[0] for i in heads] == ["/PROG", "/ATTR", "/MN", "/POS", "/END"]
    m = re.fullmatch(r"/PROG  (\w+)", rows[0])
    assert m, rows[0]
    _, attr, mn, pos = ("\n".join(rows[a + 1 : b]) for a, b in itertools.pairwise(heads))
    lines = []
    for k, row in enumerate(mn.split("\n"), start=1):
        lm = re.fullmatch(r" *(\d+):(.*) ;", row)
        assert lm and int(lm.group(1)) == k, (k, row)  # numbered 1, 2, 3, ... without gaps
        lines.append(lm.group(2).strip())
    positions = {}
    for pm in POS.finditer(pos):
        n = int(pm.group(1))
        assert n not in positions
        vals = np.array([float(pm.group(k)) for k in range(6, 12)])
        positions[n] = Position(pm.group(2), int(pm.group(3)), int(pm.group(4)), pm.group(5), vals)
    joints = {}
    for jm in JPOS.finditer(pos):
        n = int(jm.group(1))
        assert n not in positions and n not in joints
        vals = np.array([float(jm.group(k)) for k in range(5, 11)])
        joints[n] = Position(jm.group(2), int(jm.group(3)), int(jm.group(4)), "", vals)
    assert not JPOS.sub("", POS.sub("", pos)).strip(), "text in /POS that is no position"
    lc = re.search(r"^LINE_COUNT\t= (\d+);$", attr, re.M)
    assert lc and int(lc.group(1)) == len(lines)
    return Program(m.group(1), attr, lines, positions, joints)


def frame_constants(lines: list[str], pr: int) -> np.ndarray:
    """The six constants the program writes into ``PR[pr]``: X, Y, Z, W, P, R."""
    vals = {}
    for line in lines:
        m = re.fullmatch(rf"PR\[{pr},([1-6])\]=({CONST})", line)
        if m:
            vals[int(m.group(1))] = float(m.group(2).strip("()"))
    assert sorted(vals) == [1, 2, 3, 4, 5, 6]
    return np.array([vals[k] for k in range(1, 7)])


# ------------------------------------------------------------------ the interpreter


class TPMachine:
    """Runs the ``/MN`` of a TP program (module docstring) with the sensor TCP moving in the
    robot base and ``DI[1]`` answered by ``search`` (and ``rest_level``).

    Args:
        text: the ``.ls`` program.
        search: answers each skip motion (module docstring).
        rest_level: the input's level with the TCP at rest after a motion that is no search
            (``None``: off).
        T_base_tcp_start: ``(4, 4)`` the TCP before the program runs, base frame, m.

    After :meth:`run`: ``PR``, ``R`` (registers), ``uframe``/``utool`` (``{n: (4, 4)}``, m),
    ``searches`` (one dict per skip motion: ``on`` the condition's level, ``start``/``end``
    the TCP and ``axis`` the target's z, base, m, ``answer`` the callback's or ``None`` when
    it fired at once, ``found`` the skip fired), ``joint_targets`` (the TCP of each ``J`` to
    a Cartesian ``P[]``) and ``joint_moves_deg`` (each ``J`` to a via's joint values).
    """

    def __init__(
        self,
        text: str,
        search: SearchFn,
        rest_level: RestLevelFn | None = None,
        T_base_tcp_start: np.ndarray | None = None,
    ) -> None:
        self.prog = parse_ls(text)
        self.labels: dict[int, int] = {}
        for i, line in enumerate(self.prog.lines):
            if m := re.fullmatch(r"LBL\[(\d+)\]", line):
                assert int(m.group(1)) not in self.labels, line
                self.labels[int(m.group(1))] = i
        self.search = search
        self.rest_level = rest_level
        self.PR: dict[int, np.ndarray] = {}
        self.R: dict[int, float] = {}
        self.uframe: dict[int, np.ndarray] = {0: np.eye(4)}
        self.utool: dict[int, np.ndarray] = {0: np.eye(4)}
        self.uf = self.ut = 0
        start = make_transform(np.eye(3), [0.9, 0.1, 1.3])
        self.tcp: np.ndarray | None = start if T_base_tcp_start is None else T_base_tcp_start
        self.level: bool | None = False
        self.skip_on: bool | None = None
        self.searches: list[dict[str, Any]] = []
        self.joint_targets: list[np.ndarray] = []
        self.joint_moves_deg: list[np.ndarray] = []

    # -------------------------------------------------------------- state
    def di(self) -> bool:
        """``DI[1]`` now."""
        if self.level is None:
            raise TPError("DI[1] read while the TCP is unknown (after a joint move to a via)")
        return self.level

    def here(self) -> np.ndarray:
        """``(4, 4)`` the TCP, base frame, m."""
        if self.tcp is None:
            raise TPError("the TCP is unknown (a joint move to a via, no Cartesian move since)")
        return self.tcp

    def value(self, tok: str) -> float:
        if m := re.fullmatch(r"PR\[(\d+),([1-6])\]", tok):
            return float(self.pr(int(m.group(1)))[int(m.group(2)) - 1])
        if m := re.fullmatch(r"R\[(\d+)\]", tok):
            if int(m.group(1)) not in self.R:
                raise TPError(f"{tok} read before it was written")
            return self.R[int(m.group(1))]
        return float(tok.strip("()"))

    def pr(self, n: int) -> np.ndarray:
        if n not in self.PR:
            raise TPError(f"PR[{n}] read before it was written")
        return self.PR[n]

    def target(self, kind: str, n: int) -> np.ndarray:
        """``(4, 4)`` the TCP at a Cartesian ``P[n]``/``PR[n]``, base frame, m."""
        if kind == "P":
            if n not in self.prog.positions:
                raise TPError(f"P[{n}] is no Cartesian position")
            pos = self.prog.positions[n]
            if (pos.uf, pos.ut) != (self.uf, self.ut):
                raise TPError(f"P[{n}]: UF {pos.uf}, UT {pos.ut} not the active frame numbers")
            return self.uframe[self.uf] @ pose_matrix(pos.values)
        return self.uframe[self.uf] @ pose_matrix(self.pr(n))

    def lpos(self) -> np.ndarray:
        return pose_values(invert_transform(self.uframe[self.uf]) @ self.here())

    # -------------------------------------------------------------- motion
    def _move(self, goal: np.ndarray) -> None:
        """A motion that is no search: the TCP at ``goal``, the input at rest there."""
        moved = self.tcp is None or np.linalg.norm(goal[:3, 3] - self.tcp[:3, 3]) > MOVE_TOL_M
        self.tcp = goal
        if moved:
            self.level = bool(self.rest_level(goal.copy())) if self.rest_level else False

    def skip_move(self, goal: np.ndarray) -> bool:
        """One skip motion from the TCP to ``goal``: True when the skip fired."""
        if self.skip_on is None:
            raise TPError("a Skip motion without a SKIP CONDITION")
        T0 = self.here()
        want = self.skip_on
        start, end, axis = T0[:3, 3].copy(), goal[:3, 3].copy(), goal[:3, 2].copy()
        record: dict[str, Any] = dict(on=want, start=start, end=end, axis=axis, answer=None)
        self.searches.append(record)
        level = self.di()
        if level == want:  # the condition is already true: the skip fires, no motion
            record["found"] = True
            return True
        answer = self.search(start.copy(), end.copy(), axis.copy(), level)
        answer = answer if isinstance(answer, str) else np.array(answer, dtype=float)
        record["answer"] = answer
        if isinstance(answer, str) and answer == AT_START:  # on the searched level at once
            self.level = want
            record["found"] = True
            return True
        if isinstance(answer, str):  # no change on the way: the robot reaches the target
            self.tcp = goal
            record["found"] = False
            return False
        self.tcp = self._pose_on_line(T0, goal, answer)
        self.level = want
        record["found"] = True
        return True

    def _pose_on_line(self, T0: np.ndarray, goal: np.ndarray, p: np.ndarray) -> np.ndarray:
        """The commanded pose where the TCP passes ``p`` (m) on the line ``T0 -> goal``.

        Raises:
            TPError: ``p`` is not on the segment (a callback answering another search).
        """
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise TPError(f"search callback returned {p!r}, not a (3,) point")
        d = goal[:3, 3] - T0[:3, 3]
        L = float(np.linalg.norm(d))
        t = float((p - T0[:3, 3]) @ d / L) if L > 0 else 0.0
        off = float(np.linalg.norm(p - T0[:3, 3] - t * d / max(L, 1e-300)))
        if off > LINE_TOL_M or t < -LINE_TOL_M or t > L + LINE_TOL_M:
            raise TPError(
                f"search callback returned a point {off:.3g} m off the commanded line, "
                f"{t:.6f} m along it (length {L:.6f} m)"
            )
        s = min(max(t / L, 0.0), 1.0) if L > 0 else 1.0
        R0 = T0[:3, :3]
        R = R0 @ matrix_from_rotvec(s * rotvec_from_matrix(R0.T @ goal[:3, :3]))
        return make_transform(R, p)

    # -------------------------------------------------------------- the program
    def run(self) -> Self:
        lines, pc = self.prog.lines, 0
        for _ in range(MAX_STEPS):
            if pc >= len(lines):
                return self
            line = lines[pc]
            pc += 1
            jump = self.step(line)
            if jump is not None:
                if jump not in self.labels:
                    raise TPError(f"JMP to LBL[{jump}], which the program does not define")
                pc = self.labels[jump]
        raise TPError(f"more than {MAX_STEPS} instructions: an endless loop")

    def step(self, line: str) -> int | None:
        """Execute one instruction; the label to jump to, or ``None``."""
        if line.startswith("!"):
            assert re.fullmatch(COMMENT, line), line
        elif re.fullmatch(r"LBL\[\d+\]", line):
            pass
        elif m := re.fullmatch(r"PR\[(\d+)\]=LPOS", line):
            self.PR[int(m.group(1))] = self.lpos()
        elif m := re.fullmatch(r"PR\[(\d+)\]=P\[(\d+)\]", line):
            n = int(m.group(2))
            if n not in self.prog.positions:
                raise TPError(f"PR[]=P[{n}]: no Cartesian P[{n}]")
            self.PR[int(m.group(1))] = self.prog.positions[n].values.copy()
        elif m := re.fullmatch(rf"PR\[(\d+),([1-6])\]=({OPERAND})(?:([+-])({OPERAND}))?", line):
            v = self.value(m.group(3))
            if m.group(4):
                v += self.value(m.group(5)) * (1 if m.group(4) == "+" else -1)
            self.pr(int(m.group(1)))[int(m.group(2)) - 1] = v
        elif m := re.fullmatch(rf"R\[(\d+)\]=({OPERAND})(?:([-+*])({OPERAND}))?", line):
            v = self.value(m.group(2))
            if m.group(3):
                w = self.value(m.group(4))
                v = {"+": v + w, "-": v - w, "*": v * w}[m.group(3)]
            self.R[int(m.group(1))] = v
        elif m := re.fullmatch(r"(UFRAME|UTOOL)\[(\d+)\]=PR\[(\d+)\]", line):
            frames = self.uframe if m.group(1) == "UFRAME" else self.utool
            frames[int(m.group(2))] = pose_matrix(self.pr(int(m.group(3))))
        elif m := re.fullmatch(r"(UFRAME|UTOOL)_NUM=(\d+)", line):
            n = int(m.group(2))
            if n not in (self.uframe if m.group(1) == "UFRAME" else self.utool):
                raise TPError(f"{line}: frame {n} was never set")
            if m.group(1) == "UFRAME":
                self.uf = n
            else:
                self.ut = n
        elif m := re.fullmatch(r"IF DI\[1\]=(ON|OFF),JMP LBL\[(\d+)\]", line):
            if self.di() == (m.group(1) == "ON"):
                return int(m.group(2))
        elif m := re.fullmatch(r"SKIP CONDITION DI\[1\]=(ON|OFF)", line):
            self.skip_on = m.group(1) == "ON"
        elif m := re.fullmatch(r"J P\[(\d+)\] \d+% FINE", line):
            n = int(m.group(1))
            if n in self.prog.joints:  # a via: joint values, no kinematics here
                self.joint_moves_deg.append(self.prog.joints[n].values.copy())
                self.tcp, self.level = None, None
            else:
                self._move(self.target("P", n))
                self.joint_targets.append(self.here())
        elif m := re.fullmatch(r"J PR\[(\d+)\] \d+% FINE", line):  # a target without CONFIG
            self._move(self.target("PR", int(m.group(1))))
            self.joint_targets.append(self.here())
        elif m := _SKIP_MOVE.fullmatch(line):
            goal = self.target(m.group(1), int(m.group(2)))
            if m.group(3) is None:
                self._move(goal)
            elif self.skip_move(goal):
                self.PR[int(m.group(4))] = self.lpos()
            else:
                return int(m.group(3))
        else:
            raise TPError(f"instruction the exporter should not write: {line!r}")
        return None

    # -------------------------------------------------------------- results
    def codes(self, n: int) -> list[int]:
        """``R[R_CODE_BASE + i]`` of points ``i = 1..n`` (0 measured)."""
        return [int(self.value(f"R[{F.R_CODE_BASE + i}]")) for i in range(1, n + 1)]

    def recorded_base_m(self, n: int) -> np.ndarray:
        """``(n, 3)`` ``PR[PR_MEAS_BASE + i]`` of points ``i = 1..n`` converted to the robot
        base as the program's header says: ``p_base = Rot(W,P,R) p + (X,Y,Z)`` with the
        ``PR[PR_UFRAME]`` constants it writes, m (NaN where a point has none)."""
        T_base_uf = pose_matrix(frame_constants(self.prog.lines, F.PR_UFRAME))
        out = np.full((n, 3), np.nan)
        for i in range(1, n + 1):
            if F.PR_MEAS_BASE + i in self.PR:
                out[i - 1] = transform_points(T_base_uf, self.PR[F.PR_MEAS_BASE + i][:3] / 1e3)
        return out
