"""FANUC TP text: program names, comments, W-P-R angles, numbers and the ``CONFIG`` string.

The pieces :mod:`planner.export.fanuc` writes a ``.ls`` program from; conventions (mm,
degrees, ``R = Rz(R) @ Ry(P) @ Rx(W)``) as in that module's docstring.
"""

from __future__ import annotations

import re
import textwrap

import numpy as np

from calib.frames import tait_bryan_zyx_from_matrix
from planner.export.job import ArmPose
from planner.export.text import fmt, identifier
from planner.program.controllers import FANUC_JOINT_MOVE

#: Program name, comment and position-comment lengths relied on.
NAME_MAX = 36
COMMENT_MAX = 32
POS_COMMENT_MAX = 16
#: Joint speed to the safe starts (%), linear speed of the moves that are no search (mm/sec).
JOINT_PCT = round(100 * FANUC_JOINT_MOVE.velocity_fraction)
LINEAR_MM_S = 100
#: The axes (1-based) whose turn numbers ``CONFIG`` lists, in order: the usual
#: ``$SCR_GRP[1].$TURN_AXIS`` of 6-axis FANUC arms (check it on the controller).
TURN_AXES = (4, 6, 1)

_NOT_IN_COMMENT = re.compile(r"[^A-Za-z0-9 _+*/=.,:()<>\[\]#%&?@-]")


def program_name(name: str) -> str:
    """A TP program name made of ``name``: upper case, ``[A-Z][A-Z0-9_]*``, at most 36 chars."""
    ident = re.sub(r"[^A-Z0-9_]", "_", name.upper())
    if not ident[:1].isalpha():
        ident = "W" + ident
    return ident[:NAME_MAX]


def comment_lines(text: str) -> list[str]:
    """``text`` as TP comment texts: printable ASCII without ``;``, quotes or ``!``, wrapped to
    :data:`COMMENT_MAX` characters (the ``!`` and `` ;`` around them not counted)."""
    text = re.sub(r"\s+", " ", text.replace(";", ",").replace("'s ", " "))
    clean = _NOT_IN_COMMENT.sub("", text)
    return textwrap.wrap(clean, COMMENT_MAX, break_on_hyphens=False)


def wpr_deg(R: np.ndarray) -> tuple[float, float, float]:
    """FANUC ``(W, P, R)`` in degrees of a rotation matrix: ``R = Rz(R) @ Ry(P) @ Rx(W)``."""
    alpha, beta, gamma = np.degrees(tait_bryan_zyx_from_matrix(R))
    return float(gamma), float(beta), float(alpha)


def xyzwpr(T: np.ndarray) -> list[float]:
    """``[X, Y, Z, W, P, R]`` of a transform in metres: mm and degrees."""
    return [*(float(v) * 1000.0 for v in T[:3, 3]), *wpr_deg(T[:3, :3])]


def turn_number(angle_rad: float) -> int:
    """FANUC turn number of a joint angle: ``k`` with ``angle - 360 k`` in ``[-180, 180)`` deg."""
    return int(np.floor((float(angle_rad) + np.pi) / (2 * np.pi)))


def config_text(arm: ArmPose) -> str:
    """FANUC ``CONFIG`` of a robot configuration, e.g. ``"N U T, 0, 0, 0"``.

    ``N``/``F``: axis 5 bent like FANUC's negative J5 (the tool-down home J5 = -90 deg) or
    flipped; ``U``/``D``: elbow up or down; ``T``/``B``: the wrist centre in front of axis 1 or
    behind it; then the turn numbers of :data:`TURN_AXES` (joint values in the URDF's
    directions, which ROS-Industrial FANUC URDFs give in FANUC's).
    """
    turns = ", ".join(str(turn_number(arm.q_rad[a - 1])) for a in TURN_AXES)
    flags = (
        f"{'F' if arm.wrist_flipped else 'N'} {'U' if arm.elbow_up else 'D'} "
        f"{'T' if arm.front else 'B'}"
    )
    return f"{flags}, {turns}"


def _const(x: float) -> str:
    """A TP numeric constant (6 decimals; a negative one in parentheses, ``(-1.5)``)."""
    s = fmt(x, 6)
    return f"({s})" if s.startswith("-") else s


def _pos_num(x: float) -> str:
    return f"{0.0 if abs(x) < 5e-7 else x:.6f}"


def _ascii_ident(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]", "_", identifier(text))
