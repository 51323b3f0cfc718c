"""The robot controller's base frame in a URDF: where its programs' coordinates are measured from.

A plan places the kinematic chain's base link (``cell.robot.base_link``, default the URDF's
root) in the world, and check, validate and suggest work in that link's frame. A controller
measures its Cartesian coordinates (work objects, ``robtarget``, ``p[...]`` poses, the points a
program records) from its own base frame, which need not be that link:

- ROS-Industrial descriptions name it: a link ``base`` hung from the base link by fixed joints
  ("base_link to UR 'Base' Coordinates transform"). On a Universal Robots arm it is turned by
  pi about z (``base_link`` is REP-103 aligned, X+ forward; the controller's X+ points
  backwards): a program written in ``base_link`` coordinates would send the robot to the mirror
  image of every point, about a metre away. On ABB and KUKA arms it is the identity; on
  FANUC arms it is raised to the J2 axis.
- A URDF without such a link: the base link is the controller's base.

Every face that writes or reads controller coordinates (the exported programs, the lines to
paste, the results a controller wrote) converts with :func:`controller_base` at that boundary;
the simulation stays in the base link's frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.robot.urdf_model import URDFModel

FloatArray = NDArray[np.float64]

#: The ROS-Industrial name of the controller's base frame.
CONTROLLER_BASE_LINK = "base"


@dataclass(frozen=True)
class ControllerBase:
    """The controller's base frame relative to the chain's base link.

    Attributes:
        link: the URDF link that is the controller's base (``None``: the chain's base link).
        base_link: the chain's base link.
        T_base_controller: ``(4, 4)`` the controller's base frame in the base link's frame, m.
    """

    link: str | None
    base_link: str
    T_base_controller: FloatArray

    @property
    def is_identity(self) -> bool:
        """The controller measures from the base link itself (to 1e-12)."""
        return bool(np.allclose(self.T_base_controller, np.eye(4), rtol=0.0, atol=1e-12))

    def describe(self) -> str:
        """One line for reports: which link, and how it sits on the base link (mm, deg)."""
        if self.link is None:
            return f"the controller's base frame is the chain's base link {self.base_link!r}"
        T = self.T_base_controller
        angle = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(T[:3, :3]) - 1.0) / 2.0))))
        shift = float(np.linalg.norm(T[:3, 3])) * 1e3
        return (
            f"programs use the controller's base frame, URDF link {self.link!r}: "
            f"turned {angle:.1f} deg and shifted {shift:.1f} mm from {self.base_link!r}"
        )


def controller_base(model: URDFModel, base_link: str | None = None) -> ControllerBase:
    """The controller's base frame of the robot ``model`` whose chain starts at ``base_link``.

    The link :data:`CONTROLLER_BASE_LINK` when it hangs from ``base_link`` by fixed joints
    only (the ROS-Industrial convention); otherwise the base link itself (identity).

    Args:
        model: the parsed URDF.
        base_link: the chain's base link (default the URDF's root).
    """
    start = model.root if base_link is None else model.link(base_link).name
    if start != CONTROLLER_BASE_LINK:
        poses = {start: np.eye(4)}
        frontier = [start]
        while frontier:
            parent = frontier.pop()
            for j in model.children(parent):
                if j.type != "fixed":
                    continue  # a link that moves with the arm is no base frame
                poses[j.child] = poses[parent] @ j.T_parent_joint
                if j.child == CONTROLLER_BASE_LINK:
                    return ControllerBase(CONTROLLER_BASE_LINK, start, poses[j.child])
                frontier.append(j.child)
    return ControllerBase(None, start, np.eye(4))
