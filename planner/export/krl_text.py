"""KUKA KRL text shared by the KRL writers: the controller's data numbers, numbers as operands,
vectors as FRAMEs, arrays of a data list and wrapped comments.

KRL has no array literals: an array of a data list (``.dat``) is declared on one line and its
elements are given one per line (``fBasis[1,2,3]=0.5``), so no line grows with the plan. A
vector is a ``FRAME`` whose ``A``, ``B``, ``C`` are 0 (KRL has no vector type); ``X``, ``Y``,
``Z`` in millimetres for points, unit-less for directions.
"""

from __future__ import annotations

import textwrap

import numpy as np
from numpy.typing import ArrayLike

from planner.export.text import fmt

#: ``BASE_DATA[BASE_NO]`` holds the work object every search is commanded in.
BASE_NO = 10
#: ``TOOL_DATA[TOOL_NO]`` and ``LOAD_DATA[TOOL_NO]`` hold the sensor tool.
TOOL_NO = 10
#: The sensor's digital input, ``$IN[SENSOR_IN]`` (signal ``diSensor``).
SENSOR_IN = 1
#: Longest name KRL accepts (variables, routines and the module: its ``DEF``, ``DEFDAT`` and
#: file name); KRL names are case-insensitive.
MAX_NAME = 24
#: The work-object variable of the programs.
WOBJ = f"BASE_DATA[{BASE_NO}]"


def factor(x: float, decimals: int = 9) -> str:
    """``x`` as the right operand of ``*`` or ``+``: a negative number in parentheses
    (``*(-0.5)``, never ``*-0.5``)."""
    text = fmt(x, decimals)
    return f"({text})" if text.startswith("-") else text


def vector_text(v: ArrayLike, decimals: int = 9) -> str:
    """A vector as a ``FRAME`` aggregate ``{X ..,Y ..,Z ..,A 0,B 0,C 0}`` (``v`` in the units
    the program uses: mm for points)."""
    x, y, z = (float(c) for c in np.asarray(v, dtype=float))
    return f"{{X {fmt(x, decimals)},Y {fmt(y, decimals)},Z {fmt(z, decimals)},A 0,B 0,C 0}}"


def array_lines(typ: str, name: str, values: ArrayLike, decimals: int = 12) -> list[str]:
    """The data-list lines of an array: its ``DECL`` and one line per element.

    Args:
        typ: ``"REAL"`` or ``"INT"``.
        name: the array's name.
        values: its values, 1 to 3 dimensions (KRL indices from 1); ``NaN`` elements are left
            unset (never read by the program).
        decimals: decimals of a REAL element.
    """
    arr = np.asarray(values, dtype=float)
    if not 1 <= arr.ndim <= 3:
        raise ValueError(f"KRL arrays have 1 to 3 dimensions, {name} has {arr.ndim}")
    lines = [f"DECL {typ} {name}[{','.join(str(n) for n in arr.shape)}]"]
    for idx in np.ndindex(*arr.shape):
        v = float(arr[idx])
        if np.isnan(v):
            continue
        text = str(round(v)) if typ == "INT" else fmt(v, decimals)
        lines.append(f"{name}[{','.join(str(i + 1) for i in idx)}]={text}")
    return lines


def comment_lines(text: str, prefix: str = "  ; ", width: int = 92) -> list[str]:
    """``text`` as KRL comment lines of at most ``width`` characters."""
    return [prefix + line for line in textwrap.wrap(text, width - len(prefix))]


def stop_lines(pad: str) -> list[str]:
    """Leave the measuring routine when the program has stopped (``nResult`` set)."""
    return [f"{pad}IF nResult<>0 THEN", f"{pad}  RETURN", f"{pad}ENDIF"]
