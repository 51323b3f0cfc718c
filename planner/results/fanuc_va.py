"""The FANUC results: the register backups ``POSREG.VA`` and ``NUMREG.VA``.

The TP program keeps point ``i`` (1-based, plan order) in ``PR[PR_MEAS_BASE + i]`` (the
sensor TCP where the skip fired, in the user frame ``UFRAME[UFRAME_NO]`` = ``PR[PR_UFRAME]``,
the nominal work object; mm) and its result in ``R[R_CODE_BASE + i]`` (0 measured, 1 no
detection on the path, 2 the input already at the searched level at the start, 3 not run: the
program sets every code to 3 first). Both register files are text the controller writes when
its variables are backed up (``MD:POSREG.VA``, ``MD:NUMREG.VA``, e.g. from a USB backup or the
controller's web page):

.. code-block:: text

    [*POSREG*]$POSREG  Storage: CMOS  Access: RW  : ARRAY[1,100] OF Position Reg
        [1,11] =   ''
      Group: 1   Config: N U T, 0, 0, 0
      X:  1510.236   Y:  -402.712   Z:   731.912
      W:  -180.000   P:      .000   R:   -90.000
        [1,12] =   '' Uninitialized

    [*NUMREG*]$NUMREG  Storage: CMOS  Access: RW  : ARRAY[200] OF Numeric Reg
      [11] = 0  ''

Positions print with 3 decimals (a micrometre), a leading zero dropped (``.000``); an axis the
controller cannot print is ``********``. Only group 1 is read. ``PR[PR_UFRAME]`` must hold the
plan's nominal work object (to the file's 3 decimals): otherwise the registers are another
program's or the frame was changed, and nothing is read.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from calib.frames import (
    matrix_from_tait_bryan_zyx,
    rotvec_from_matrix,
    tait_bryan_zyx_from_matrix,
)
from planner.export.fanuc import PR_MEAS_BASE, PR_UFRAME, R_CODE_BASE
from planner.results.errors import ResultsError
from planner.results.krl_dat import SlotReadings

#: Reasons, by the code in ``R[R_CODE_BASE + i]``.
CODES = {
    1: "no detection on the search path",
    2: "the input was already at the searched level at the start",
    3: "not run (the program stopped before it)",
}
#: How far ``PR[PR_UFRAME]`` may lie from the plan's nominal frame: the file's rounding.
FRAME_TOL_MM = 0.002
FRAME_TOL_DEG = 0.002

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|\*+"
_PR_HEAD = re.compile(r"^\s*\[\s*(\d+)\s*,\s*(\d+)\s*\]\s*=\s*'([^']*)'\s*(.*?)\s*$")
_R_HEAD = re.compile(r"^\s*\[\s*(\d+)\s*\]\s*=\s*(\S+)(?:\s+'[^']*')?\s*$")
_AXES = re.compile(rf"([XYZWPR])\s*:\s*({_NUM})")


@dataclass
class PositionRegister:
    """One position register of ``POSREG.VA``.

    Attributes:
        values: ``{axis: value}`` of X, Y, Z (mm), W, P, R (deg); ``None`` for ``********``.
        joint: it is in joint representation.
        initialized: it holds a position.
        line: its line in the file.
    """

    values: dict[str, float | None] = field(default_factory=dict)
    joint: bool = False
    initialized: bool = True
    line: int = 0


def _number(text: str) -> float | None:
    return None if text.startswith("*") else float(text)


def parse_posreg(text: str, source: str) -> dict[int, PositionRegister]:
    """``{index: register}`` of group 1 in the ``POSREG.VA`` text.

    Raises:
        ResultsError: not a ``POSREG.VA`` (no ``[*POSREG*]$POSREG`` header).
    """
    if "[*POSREG*]$POSREG" not in text:
        raise ResultsError(f"{source}: not a FANUC POSREG.VA (no [*POSREG*]$POSREG header)")
    out: dict[int, PositionRegister] = {}
    current: PositionRegister | None = None
    for no, line in enumerate(text.splitlines(), start=1):
        if (h := _PR_HEAD.match(line)) is not None:
            group, index, rest = int(h.group(1)), int(h.group(2)), h.group(4)
            current = PositionRegister(line=no) if group == 1 else None
            if current is not None:
                current.initialized = "uninitialized" not in rest.lower()
                out[index] = current
            continue
        if current is None:
            continue
        if re.search(r"\bJ\d\s*=", line):
            current.joint = True
        for axis, value in _AXES.findall(line):
            current.values[axis] = _number(value)
    return out


def parse_numreg(text: str, source: str) -> dict[int, float | None]:
    """``{index: value}`` of the ``NUMREG.VA`` text (``None``: uninitialized).

    Raises:
        ResultsError: not a ``NUMREG.VA``, or a value that cannot be read (named by line).
    """
    if "[*NUMREG*]$NUMREG" not in text:
        raise ResultsError(f"{source}: not a FANUC NUMREG.VA (no [*NUMREG*]$NUMREG header)")
    out: dict[int, float | None] = {}
    body = text.split("[*NUMREG*]$NUMREG", 1)[1]
    offset = text[: len(text) - len(body)].count("\n")
    for no, line in enumerate(body.splitlines(), start=offset + 1):
        if line.lstrip().startswith("[*"):
            break  # the next variable ($MAXREGNUM ...)
        if (h := _R_HEAD.match(line)) is None:
            continue
        value = h.group(2)
        if value.lower().startswith("uninit"):
            out[int(h.group(1))] = None
            continue
        try:
            out[int(h.group(1))] = float(value)
        except ValueError:
            raise ResultsError(
                f"{source}:{no}: R[{h.group(1)}] = {value!r} is not a number"
            ) from None
    return out


def _xyz(pr: PositionRegister, index: int, what: str, source: str) -> np.ndarray:
    if not pr.initialized:
        raise ResultsError(f"{source}:{pr.line}: PR[{index}] ({what}) is uninitialized")
    if pr.joint:
        raise ResultsError(
            f"{source}:{pr.line}: PR[{index}] ({what}) is in joint representation; the "
            "program writes it as LPOS (Cartesian)"
        )
    vals = [pr.values.get(a) for a in "XYZ"]
    if any(v is None for v in vals):
        raise ResultsError(f"{source}:{pr.line}: PR[{index}] ({what}) has no X, Y and Z values")
    return np.array(vals, dtype=float)


def check_user_frame(
    regs: dict[int, PositionRegister], T_base_wobj: np.ndarray, source: str
) -> None:
    """Refuse unless ``PR[PR_UFRAME]`` holds ``T_base_wobj`` (mm, W, P, R) to the file's
    rounding.

    Raises:
        ResultsError: missing, or another frame (named with both values).
    """
    pr = regs.get(PR_UFRAME)
    what = "the user frame the program set"
    if pr is None:
        raise ResultsError(f"{source}: no PR[{PR_UFRAME}] ({what})")
    got = _xyz(pr, PR_UFRAME, what, source)
    angles = [pr.values.get(a) for a in "WPR"]
    if any(a is None for a in angles):
        raise ResultsError(f"{source}:{pr.line}: PR[{PR_UFRAME}] ({what}) has no W, P, R")
    want = T_base_wobj[:3, 3] * 1e3
    r, p, w = np.degrees(tait_bryan_zyx_from_matrix(T_base_wobj[:3, :3]))
    a = np.radians(np.array(angles, dtype=float))
    R_got = matrix_from_tait_bryan_zyx(a[2], a[1], a[0])  # W, P, R = gamma, beta, alpha
    d_deg = np.degrees(np.linalg.norm(rotvec_from_matrix(R_got.T @ T_base_wobj[:3, :3])))
    if np.abs(got - want).max() > FRAME_TOL_MM or d_deg > FRAME_TOL_DEG:
        raise ResultsError(
            f"{source}:{pr.line}: PR[{PR_UFRAME}] ({what}) is X {got[0]:.3f} Y {got[1]:.3f} "
            f"Z {got[2]:.3f} W {angles[0]:.3f} P {angles[1]:.3f} R {angles[2]:.3f}, the plan's "
            f"nominal work object X {want[0]:.3f} Y {want[1]:.3f} Z {want[2]:.3f} "
            f"W {w:.3f} P {p:.3f} R {r:.3f}: registers of another plan's program, or the "
            "frame was changed"
        )


def fanuc_readings(
    regs: dict[int, PositionRegister],
    codes: dict[int, float | None],
    ids: list[str],
    T_base_wobj: np.ndarray,
    sources: tuple[str, str],
) -> SlotReadings:
    """The points (robot base, mm) of the program's registers, by the plan's ``ids`` (plan
    order, point ``i`` in ``PR[PR_MEAS_BASE + i]`` and ``R[R_CODE_BASE + i]``).

    Raises:
        ResultsError: a code register missing, uninitialized or not a code; a measured
            point's position register missing or not Cartesian (each named).
    """
    pos_src, num_src = sources
    check_user_frame(regs, T_base_wobj, pos_src)
    out = SlotReadings()
    for i, pid in enumerate(ids, start=1):
        k, j = R_CODE_BASE + i, PR_MEAS_BASE + i
        if k not in codes:
            raise ResultsError(f"{num_src}: no R[{k}] (the result of point {pid})")
        code = codes[k]
        if code is None:
            raise ResultsError(f"{num_src}: R[{k}] (the result of point {pid}) is uninitialized")
        if code == 0:
            if j not in regs:
                raise ResultsError(f"{pos_src}: no PR[{j}] (point {pid}, measured: R[{k}] = 0)")
            p = _xyz(regs[j], j, f"point {pid}", pos_src)
            base = T_base_wobj[:3, :3] @ (p * 1e-3) + T_base_wobj[:3, 3]
            out.points[pid] = (float(base[0] * 1e3), float(base[1] * 1e3), float(base[2] * 1e3))
        elif code in CODES:
            out.failed[pid] = f"R[{k}] = {code:g}: {CODES[int(code)]}"
        else:
            raise ResultsError(
                f"{num_src}: R[{k}] = {code:g} (point {pid}) is no code the program writes"
            )
    return out
