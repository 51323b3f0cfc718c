"""The plan's validation settings: the physical models (from :mod:`calib.models`), the report,
trials and seed.

Defaults and their sources are in ``docs/simulation.md``.
"""

from __future__ import annotations

import msgspec

from calib.models import SensorSettings
from calib.models.cycle import CycleSettings
from calib.models.misplacement import Misplacement
from calib.models.proximity import ProximitySensor
from calib.models.robot_error import RobotErrorModel
from calib.plan.report_spec import ReportSpec
from calib.structs import Strict, check_count

#: Most trials a validation runs (about a minute per 10,000 on two cores; the results are
#: kept in memory for the confidence intervals).
MAX_TRIALS = 100_000
#: Seeds are integers 0 .. 2**63 - 1.
MAX_SEED = 2**63 - 1


class ValidationSpec(Strict, frozen=True, kw_only=True):
    """Monte Carlo validation settings.

    Attributes:
        sensor: the sensor model, tagged by ``kind`` (``"proximity"``: the inductive sensor,
            ``"touch"``: the touch-trigger probe); a plan without ``kind`` is a proximity sensor.
        robot_error: the robot error model.
        misplacement: misplacement tolerance of the part.
        report: points of interest, regions and confidence levels of the report.
        trials: number of simulated calibrations, 2 .. :data:`MAX_TRIALS`.
        seed: seed of the ``numpy.random.Generator``, 0 .. :data:`MAX_SEED`.
        cycle: the timing figures of the measuring program's cycle-time model
            (:class:`calib.models.cycle.CycleSettings`); left out of the file when not set, so
            plans written before it keep their digest (:attr:`cycle_settings` reads both).
    """

    sensor: SensorSettings = ProximitySensor()
    robot_error: RobotErrorModel = RobotErrorModel()
    misplacement: Misplacement = Misplacement()
    report: ReportSpec = ReportSpec()
    trials: int = 400
    seed: int = 20131023
    cycle: CycleSettings | msgspec.UnsetType = msgspec.UNSET

    @property
    def cycle_settings(self) -> CycleSettings:
        """The cycle-time figures (the defaults when the file sets none)."""
        return CycleSettings() if isinstance(self.cycle, msgspec.UnsetType) else self.cycle

    def __post_init__(self) -> None:
        check_count(self.trials, "trials", minimum=2, maximum=MAX_TRIALS)
        check_count(self.seed, "seed", minimum=0, maximum=MAX_SEED)
