"""The plan's validation settings: the physical models (from :mod:`calib.models`), the report,
trials and seed.

Defaults and their sources are in ``docs/simulation.md``.
"""

from __future__ import annotations

from calib.errors import PlanError
from calib.models import SensorSettings
from calib.models.misplacement import Misplacement
from calib.models.proximity import ProximitySensor
from calib.models.robot_error import RobotErrorModel
from calib.plan.report_spec import ReportSpec
from calib.structs import Strict


class ValidationSpec(Strict, frozen=True, kw_only=True):
    """Monte Carlo validation settings.

    Attributes:
        sensor: the sensor model, tagged by ``kind`` (``"proximity"``: the inductive sensor,
            ``"touch"``: the touch-trigger probe); a plan without ``kind`` is a proximity sensor.
        robot_error: the robot error model.
        misplacement: misplacement tolerance of the part.
        report: points of interest, regions and confidence levels of the report.
        trials: number of simulated calibrations.
        seed: seed of the ``numpy.random.Generator``.
    """

    sensor: SensorSettings = ProximitySensor()
    robot_error: RobotErrorModel = RobotErrorModel()
    misplacement: Misplacement = Misplacement()
    report: ReportSpec = ReportSpec()
    trials: int = 400
    seed: int = 20131023

    def __post_init__(self) -> None:
        if self.trials < 2:
            raise PlanError(f"trials: must be >= 2, got {self.trials}")
