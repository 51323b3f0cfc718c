"""The plan's validation settings: the physical models (from :mod:`calib.models`), trials, seed.

Defaults and their sources are in ``docs/simulation.md``.
"""

from __future__ import annotations

from calib.errors import PlanError
from calib.models.misplacement import Misplacement
from calib.models.proximity import ProximitySensor
from calib.models.robot_error import RobotErrorModel
from calib.structs import Strict


class ValidationSpec(Strict, frozen=True, kw_only=True):
    """Monte Carlo validation settings.

    Attributes:
        sensor: the sensor model.
        robot_error: the robot error model.
        misplacement: misplacement tolerance of the part.
        trials: number of simulated calibrations.
        seed: seed of the ``numpy.random.Generator``.
    """

    sensor: ProximitySensor = ProximitySensor()
    robot_error: RobotErrorModel = RobotErrorModel()
    misplacement: Misplacement = Misplacement()
    trials: int = 400
    seed: int = 20131023

    def __post_init__(self) -> None:
        if self.trials < 2:
            raise PlanError(f"trials: must be >= 2, got {self.trials}")
