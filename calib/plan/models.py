"""The error models of a plan, used by ``wobjcal validate`` (Monte Carlo).

The fields mirror ``planner.sim.proximity.ProximitySensor`` and ``planner.sim.error_models`` so
that the plan file holds exactly what the simulation uses; defaults are justified in
``docs/simulation.md``.
"""

from __future__ import annotations

import math

from calib.plan.base import PlanError, Strict, check_positive


class SensorModel(Strict, frozen=True, kw_only=True):
    """The proximity sensor, for validation (``planner.sim.proximity.ProximitySensor``).

    Attributes:
        face_diameter_m: diameter of the active face, m.
        sensing_distance_m: nominal sensing distance on a flat steel target, m.
        decay_length_m: length over which the damping signal falls by ``e``, m.
        hysteresis_fraction: switch-off distance exceeds switch-on by this part of the distance.
        repeatability_sigma_m: 1-sigma jitter of the switching distance, m.
        n_rays: rays over the face for switching decisions.
        n_scan_rays: rays for the coarse scan of an edge search.
    """

    face_diameter_m: float = 0.018
    sensing_distance_m: float = 0.008
    decay_length_m: float = 0.0016
    hysteresis_fraction: float = 0.10
    repeatability_sigma_m: float = 0.00004
    n_rays: int = 256
    n_scan_rays: int = 19

    def __post_init__(self) -> None:
        check_positive(self.face_diameter_m, "face_diameter_m", allow_zero=True)
        check_positive(self.sensing_distance_m, "sensing_distance_m")
        check_positive(self.decay_length_m, "decay_length_m")
        check_positive(self.hysteresis_fraction, "hysteresis_fraction", allow_zero=True)
        check_positive(self.repeatability_sigma_m, "repeatability_sigma_m", allow_zero=True)
        check_positive(self.n_rays, "n_rays")
        check_positive(self.n_scan_rays, "n_scan_rays")


class RobotErrorModel(Strict, frozen=True, kw_only=True):
    """Robot positioning errors, for validation (``planner.sim.error_models.RobotErrorModel``).

    Attributes:
        repeatability_sigma_m: 1-sigma per-axis TCP scatter of each search, m.
        accuracy_amplitude_m: RMS per axis of the smooth absolute-accuracy field, m (0: off).
        accuracy_wavelength_m: typical wavelength of the accuracy field, m.
        accuracy_terms: number of sine terms of the field.
    """

    repeatability_sigma_m: float = 0.00002
    accuracy_amplitude_m: float = 0.0
    accuracy_wavelength_m: float = 1.0
    accuracy_terms: int = 6

    def __post_init__(self) -> None:
        check_positive(self.repeatability_sigma_m, "repeatability_sigma_m", allow_zero=True)
        check_positive(self.accuracy_amplitude_m, "accuracy_amplitude_m", allow_zero=True)
        check_positive(self.accuracy_wavelength_m, "accuracy_wavelength_m")
        check_positive(self.accuracy_terms, "accuracy_terms")


class Misplacement(Strict, frozen=True, kw_only=True):
    """How far the real part may lie from its nominal pose (uniform, for validation).

    Attributes:
        max_translation_m: largest translation, m (paper: 20 mm).
        max_angle_rad: largest rotation, rad (paper: 3 deg).
    """

    max_translation_m: float = 0.020
    max_angle_rad: float = math.radians(3.0)

    def __post_init__(self) -> None:
        check_positive(self.max_translation_m, "max_translation_m", allow_zero=True)
        check_positive(self.max_angle_rad, "max_angle_rad", allow_zero=True)


class ValidationSpec(Strict, frozen=True, kw_only=True):
    """Monte Carlo validation settings.

    Attributes:
        sensor: the sensor model.
        robot_error: the robot error model.
        misplacement: misplacement tolerance of the part.
        trials: number of simulated calibrations.
        seed: seed of the ``numpy.random.Generator``.
    """

    sensor: SensorModel = SensorModel()
    robot_error: RobotErrorModel = RobotErrorModel()
    misplacement: Misplacement = Misplacement()
    trials: int = 400
    seed: int = 20131023

    def __post_init__(self) -> None:
        if self.trials < 2:
            raise PlanError(f"trials: must be >= 2, got {self.trials}")
