"""How long the robot takes besides moving: the timing figures of the cycle-time model.

:class:`CycleSettings` is the one definition of the figures a plan gives the cycle-time model of
its measuring program (:mod:`planner.program.cycle_time`, ``docs/cycle_time.md``): the plan file
holds it as ``validation.cycle`` (left out of the file when not set: the defaults below apply).
The joint velocities come from the robot's URDF and the speed of the linear moves that are no
search from what every exported program commands; only what neither says is here.
"""

from __future__ import annotations

import math

from calib.errors import PlanError
from calib.limits import MAX_IO_S, MAX_JOINT_ACCELERATION_RAD_S2, MAX_SETTLE_S
from calib.structs import Strict


def _check_range(value: float, field: str, maximum: float, unit: str, *, allow_zero: bool) -> None:
    """Raise :class:`PlanError` unless ``value`` is a finite number in ``[0, maximum]``
    (``(0, maximum]`` without ``allow_zero``), naming the field and the unit."""
    low = "0 <=" if allow_zero else "0 <"
    ok = math.isfinite(value) and (value >= 0.0 if allow_zero else value > 0.0)
    if not ok or value > maximum:
        raise PlanError(f"{field}: must be {low} {field} <= {maximum:g} ({unit}), got {value!r}")


class CycleSettings(Strict, frozen=True, kw_only=True):
    """Timing figures of the measuring program that neither the URDF nor the program gives.

    Attributes:
        settle_s: time the robot stands still at each search stop (the ``\\SStop`` stop, the
            fine point and the sensor's switching latched) before it moves on, s; 0 to
            :data:`calib.limits.MAX_SETTLE_S`. Default 0.2 s: an industrial arm's fine point
            settles in 0.1-0.3 s.
        io_s: time per recorded measurement for the program's bookkeeping (storing the point,
            the estimate update of an adaptive program, a log line), s; 0 to
            :data:`calib.limits.MAX_IO_S`. Default 0.1 s.
        joint_acceleration_rad_s2: largest acceleration (and deceleration) of every joint in
            the joint moves, rad/s^2 (m/s^2 for a sliding joint); above 0, at most
            :data:`calib.limits.MAX_JOINT_ACCELERATION_RAD_S2`. URDFs give no acceleration.
            Default 5 rad/s^2: an IRB 4400 class arm's main axes reach full speed (150 deg/s)
            in about half a second.
    """

    settle_s: float = 0.2
    io_s: float = 0.1
    joint_acceleration_rad_s2: float = 5.0

    def __post_init__(self) -> None:
        _check_range(self.settle_s, "settle_s", MAX_SETTLE_S, "s", allow_zero=True)
        _check_range(self.io_s, "io_s", MAX_IO_S, "s", allow_zero=True)
        _check_range(
            self.joint_acceleration_rad_s2,
            "joint_acceleration_rad_s2",
            MAX_JOINT_ACCELERATION_RAD_S2,
            "rad/s^2",
            allow_zero=False,
        )
