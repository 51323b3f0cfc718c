"""Via points of a probe point: joint configurations the robot passes on its way to the point.

A probe point may carry an ordered list of vias (``points[i].vias``). The robot program moves
from the previous point (or from where the program starts, for the first point) through the
vias, in order, to the point's approach; each via is a joint move (RAPID ``MoveAbsJ``, KRL
``PTP`` to an ``AXIS``, URScript ``movej``, FANUC ``J`` to a joint position).

**The joint values are authoritative.** ``q_rad`` is the robot's joint configuration in the
URDF's joint order and directions, rad: a controller's joint target is unambiguous (one arm
configuration, no IK branch, no turn numbers), while a Cartesian via is not (the same TCP pose
has up to eight arm configurations and different turn conventions on every robot). ``tcp_wobj``
(the TCP pose at ``q_rad`` in the work-object frame) is only for humans reading the file: it is
written when the via is taught and never read back by ``check`` or the exporters.

The plan cannot know the robot's joint count or limits (``calib`` parses no URDF): this module
checks what it can (finite numbers, at most :data:`MAX_JOINTS`, the same count for every via of
the plan); ``wobjcal check`` checks the count against the robot, the joint limits and the
collisions of the moves (:mod:`planner.cell.moves.joint_moves`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Annotated, Final

import msgspec

from calib.errors import PlanError
from calib.plan.cell import Pose
from calib.structs import Strict

#: Most joint values a via may hold (6-axis arms plus external axes).
MAX_JOINTS: Final = 12


class ViaPoint(Strict, frozen=True, kw_only=True):
    """One via point: a joint configuration the robot passes (see the module docstring).

    Attributes:
        q_rad: joint values, rad, in the robot URDF's joint order and directions
            (authoritative).
        tcp_wobj: the probing TCP at ``q_rad`` in the work-object frame (``T_wobj_tcp``, m), for
            humans only; ``None`` when unknown.
    """

    q_rad: Annotated[list[float], msgspec.Meta(min_length=1, max_length=MAX_JOINTS)]
    tcp_wobj: Pose | None = None

    def __post_init__(self) -> None:
        if not 1 <= len(self.q_rad) <= MAX_JOINTS:
            raise PlanError(
                f"q_rad: must hold 1 to {MAX_JOINTS} joint values (rad), got {len(self.q_rad)}"
            )
        for k, v in enumerate(self.q_rad):
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
                raise PlanError(f"q_rad[{k}]: must be a finite number (rad), got {v!r}")


def check_via_counts(points: Sequence[tuple[str, Sequence[ViaPoint]]]) -> None:
    """Raise :class:`PlanError` unless every via of the plan has the same number of joints.

    Args:
        points: ``(point id, its vias)`` in plan order.
    """
    first: tuple[str, int, int] | None = None
    for i, (pid, vias) in enumerate(points):
        for k, via in enumerate(vias):
            n = len(via.q_rad)
            if first is None:
                first = (pid, k, n)
            elif n != first[2]:
                raise PlanError(
                    f"points[{i}].vias[{k}].q_rad: {n} joint values (point {pid!r}), but via "
                    f"{first[1]} of point {first[0]!r} has {first[2]}: one robot, one count"
                )
