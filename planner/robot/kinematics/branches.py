"""Configuration branches of OPW arms and ABB ``confdata``.

Three binary flags tell the 8 inverse-kinematics branches of an OPW arm apart. They are computed
from the geometry (not from the solver's branch order), in the plane of the arm, i.e. in the OPW
frame turned by axis 1 (``x1`` points from axis 1 towards the shoulder offset ``a1``):

* ``shoulder_back``: the wrist centre lies behind axis 1 (``x1 < 0``);
* ``elbow_back``: the wrist centre lies behind the lower arm (the line from axis 2 to axis 3),
  i.e. on the ``-x1`` side of it when the lower arm is turned upright; for ABB arms with the
  wrist above the elbow this is the "elbow down" solution;
* ``wrist_negative``: robot axis 5 is negative (the flipped wrist).

ABB ``confdata`` ``[cf1, cf4, cf6, cfx]`` (RAPID, serial 6-axis robots) is then:

* ``cf1, cf4, cf6``: the quadrant of axes 1, 4, 6: ``floor(q / 90 deg)``, so 0 for [0, 90),
  1 for [90, 180), -1 for [-90, 0), -2 for [-180, -90), and beyond for axes with more range;
* ``cfx = 4 * shoulder_back + 2 * elbow_back + wrist_negative`` (0-7), ABB's table "wrist centre
  relative to axis 1: in front of / behind; relative to the lower arm: in front of / behind;
  axis 5: positive / negative".

Other vendors name the same three flags their own way, in their own joint directions (FANUC's
J5 turns the other way than ABB's axis 5). :func:`posture` gives them without any joint
convention: ``wrist_flipped`` is the sign of the OPW model's canonical ``theta5`` (axis 5 bent
the way ABB's positive axis 5 bends it, with axis 4 at its reference), and the exporters turn
the flags into FANUC ``CONFIG`` (``N``/``F``, ``U``/``D``, ``T``/``B``) and KUKA ``S``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_shape
from planner.builtins import robot_urdf
from planner.robot.kinematics.opw_robot import OPWRobot


@dataclass(frozen=True)
class BranchFlags:
    """The configuration of one 6-axis OPW solution (see the module docstring)."""

    shoulder_back: bool
    elbow_back: bool
    wrist_negative: bool

    @property
    def cfx(self) -> int:
        """ABB ``cfx`` 0-7: ``4 * shoulder_back + 2 * elbow_back + wrist_negative``."""
        return 4 * self.shoulder_back + 2 * self.elbow_back + int(self.wrist_negative)


def branch_codes(robot: OPWRobot, q: ArrayLike) -> NDArray[np.int_]:
    """``cfx``-style branch codes ``(...,)`` of robot joint values ``q (..., 6)``; -1 for NaN."""
    qa = np.asarray(q, dtype=float)
    p = robot.params
    th = p.to_theta(qa)
    t2, t3 = th[..., 1], th[..., 2]
    t23 = t2 + t3
    cx1 = p.a1 + p.c2 * np.sin(t2) + p.c3 * np.sin(t23) + p.a2 * np.cos(t23)
    across = np.sin(t3 + np.arctan2(p.a2, p.c3))  # sign of lower-arm x wrist-centre offset
    q5 = np.pi - (np.pi - qa[..., 4]) % (2 * np.pi)
    with np.errstate(invalid="ignore"):
        code = 4 * (cx1 < 0) + 2 * (across < 0) + (q5 < 0)
    return np.where(np.isnan(qa).any(axis=-1), -1, code).astype(int)


def classify(robot: OPWRobot, q: ArrayLike) -> BranchFlags:
    """The :class:`BranchFlags` of one configuration ``q (6,)``, rad."""
    code = int(branch_codes(robot, check_shape(q, (6,), "q")))
    return BranchFlags(bool(code & 4), bool(code & 2), bool(code & 1))


@dataclass(frozen=True)
class Posture:
    """The arm's configuration at one pose, free of any vendor's joint directions.

    Attributes:
        front: the wrist centre lies in front of axis 1 (on the side of the shoulder offset).
        elbow_up: the wrist centre lies in front of the lower arm (the elbow bent forward: the
            "elbow up" posture of an arm reaching forward).
        wrist_flipped: the canonical ``theta5`` of the OPW model is negative.
    """

    front: bool
    elbow_up: bool
    wrist_flipped: bool


def posture(robot: OPWRobot, q: ArrayLike) -> Posture:
    """The :class:`Posture` of robot joint values ``q (6,)``, rad."""
    qa = check_shape(q, (6,), "q")
    code = int(branch_codes(robot, qa))
    theta5 = float(robot.params.to_theta(qa)[4])
    theta5 = np.pi - (np.pi - theta5) % (2 * np.pi)  # wrapped to (-pi, pi]
    return Posture(front=not code & 4, elbow_up=not code & 2, wrist_flipped=theta5 < 0)


@lru_cache(maxsize=1)
def builtin_robot() -> OPWRobot:
    """The OPW model of the built-in IRB 4400-like arm (derived from its URDF, cached)."""
    from planner.robot.kinematics.chain import KinematicChain
    from planner.robot.kinematics.opw_from_urdf import opw_from_chain

    return opw_from_chain(KinematicChain.from_urdf(robot_urdf("builtin:irb4400")))


def quadrant(angle_rad: float) -> int:
    """ABB quadrant number ``floor(angle / 90 deg)`` of an axis angle."""
    return int(np.floor(angle_rad / (np.pi / 2)))


def abb_confdata(q: ArrayLike, robot: OPWRobot | None = None) -> tuple[int, int, int, int]:
    """ABB RAPID ``confdata`` ``(cf1, cf4, cf6, cfx)`` of joint values ``q (6,)`` in rad.

    Args:
        q: robot joint values (URDF convention; equal to ABB's for the built-in arm).
        robot: the OPW model; default the built-in IRB 4400-like arm.

    Raises:
        ShapeError, NonFiniteError: ``q`` is not 6 finite numbers.
    """
    qa = check_shape(q, (6,), "q")
    flags = classify(robot or builtin_robot(), qa)
    return quadrant(qa[0]), quadrant(qa[3]), quadrant(qa[5]), flags.cfx
