"""The results files a controller leaves after a run of a wobjcal program, written from the end
state of this project's interpreters, as each controller writes them: what
:mod:`planner.results` reads back.

- KUKA: the ``.dat`` with the data list's runtime values saved into it (array elements as lines
  after their ``DECL``, scalars as their ``DECL``'s value), numbers at full precision (the
  interpreter is float64; a controller writes its 32-bit REAL).
- UR: the controller's log, each ``textmsg`` a line after PolyScope's time stamp and source,
  between other programs' lines.
- FANUC: ``POSREG.VA`` (3 decimals, leading zero dropped) and ``NUMREG.VA``.
"""

from __future__ import annotations

import re

import numpy as np

from calib.frames import tait_bryan_zyx_from_matrix
from tests.fanuc_interp import TPMachine
from tests.krl_interp import KrlMachine


def _frame_value(T_m: np.ndarray) -> str:
    a, b, c = np.degrees(tait_bryan_zyx_from_matrix(T_m[:3, :3]))
    x, y, z = T_m[:3, 3] * 1e3
    return "{" + ",".join(f"{k} {float(v)!r}" for k, v in zip("XYZABC", (x, y, z, a, b, c))) + "}"


def krl_saved_dat(dat: str, m: KrlMachine) -> str:
    """``dat`` (the exported ``.dat``) as the controller saves it after the run ``m``."""
    frames = m.frames_m("xMeas")
    codes = m.ints("nFail")
    out: list[str] = []
    for line in dat.splitlines():
        if (s := re.fullmatch(r"DECL INT (nResult|nStopAt)=\d+", line)) is not None:
            out.append(f"DECL INT {s.group(1)}={m.value(s.group(1))}")
            continue
        out.append(line)
        if re.fullmatch(r"DECL FRAME xMeas\[\d+\]", line):
            out += [f"xMeas[{i}]={_frame_value(T)}" for i, T in sorted(frames.items())]
        elif re.fullmatch(r"DECL INT nFail\[\d+\]", line):
            out += [f"nFail[{i}]={v}" for i, v in sorted(codes.items()) if v is not None]
    return "\n".join(out) + "\n"


def ur_log(messages: list[str]) -> str:
    """The controller's log of a run whose ``textmsg`` lines are ``messages``, after another
    program's lines (PolyScope's layout: time stamp, source, text)."""
    rows = [
        "2026-11-27 09:12:01.101  PolyScope  Program pick_place started",
        "2026-11-27 09:12:09.552  Controller  Program pick_place stopped",
    ]
    rows += [
        f"2026-11-27 10:00:{k // 100:02d}.{k % 100:03d}  Controller  {msg}"
        for k, msg in enumerate(messages)
    ]
    return "\n".join(rows) + "\n"


def _va_num(v: float) -> str:
    text = f"{v:9.3f}"
    return text.replace("0.", ".", 1) if abs(v) < 1 and "0." in text else text


def fanuc_va(tp: TPMachine, n_regs: int = 100, n_r: int = 200) -> tuple[str, str]:
    """``(POSREG.VA, NUMREG.VA)`` of the registers after the run ``tp``."""
    pos = [f"[*POSREG*]$POSREG  Storage: CMOS  Access: RW  : ARRAY[1,{n_regs}] OF Position Reg"]
    for i in range(1, n_regs + 1):
        if i not in tp.PR:
            pos.append(f"    [1,{i}] =   '' Uninitialized")
            continue
        x, y, z, w, p, r = (float(v) for v in tp.PR[i])
        pos += [
            f"    [1,{i}] =   ''",
            "  Group: 1   Config: N U T, 0, 0, 0",
            f"  X: {_va_num(x)}   Y: {_va_num(y)}   Z: {_va_num(z)}",
            f"  W: {_va_num(w)}   P: {_va_num(p)}   R: {_va_num(r)}",
        ]
    num = [f"[*NUMREG*]$NUMREG  Storage: CMOS  Access: RW  : ARRAY[{n_r}] OF Numeric Reg"]
    for i in range(1, n_r + 1):
        if i in tp.R:
            v = tp.R[i]
            text = str(int(v)) if float(v).is_integer() else f"{v:.6f}"
            num.append(f"  [{i}] = {text}  ''")
        else:
            num.append(f"  [{i}] = 0  ''")
    num.append("[*NUMREG*]$MAXREGNUM  Storage: CMOS  Access: RW  : INTEGER = 200")
    return "\n".join(pos) + "\n", "\n".join(num) + "\n"
