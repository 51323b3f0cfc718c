"""How far the robot's TCP is from where the controller believes it is.

:class:`RobotErrorModel` is the one definition of the robot's error: the plan file holds it
(``validation.robot_error``) and the simulation draws from it. Defaults and their sources are
in ``docs/simulation.md``. Every sampler takes an explicit ``rng: numpy.random.Generator``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.structs import Strict, check_count, check_positive

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class AccuracyField:
    """A smooth absolute-positioning error field of one robot, base frame.

    ``e(p) = sum_k a_k sin(w_k . p + phi_k)``: where the TCP really is minus where the controller
    believes it is, at commanded position ``p``.

    Attributes:
        amplitudes_m: ``(K, 3)`` error amplitude of each term, m.
        wavevectors: ``(K, 3)`` spatial angular frequencies, rad/m.
        phases: ``(K,)`` phases, rad.
    """

    amplitudes_m: FloatArray
    wavevectors: FloatArray
    phases: FloatArray

    def __call__(self, p_m: ArrayLike) -> FloatArray:
        """Error ``(..., 3)`` (m) at commanded TCP position(s) ``(..., 3)`` (base, m)."""
        p = np.asarray(p_m, dtype=np.float64)
        arg = p @ self.wavevectors.T + self.phases  # (..., K)
        return np.sin(arg) @ self.amplitudes_m


class RobotErrorModel(Strict, frozen=True, kw_only=True):
    """Robot positioning errors added to every commanded search.

    Attributes:
        repeatability_sigma_m: 1-sigma per-axis TCP offset, drawn anew for each search (the
            robot returns to a commanded pose with this scatter), m.
        accuracy_amplitude_m: RMS size per axis of the smooth absolute-accuracy field, m; 0
            turns the field off. One field is drawn per validation run (it belongs to the robot,
            not to the trial).
        accuracy_wavelength_m: typical wavelength of the accuracy field, m.
        accuracy_terms: number of sine terms in the field.
        tcp_sigma_m: 1-sigma per axis of the sensor TCP's calibration error, in the sensor's
            tool frame (:func:`calib.models.sensor.tool_rotation`), m; drawn once per simulated
            calibration (each calibration stands for a cell with its own TCP calibration); 0
            turns it off.
    """

    repeatability_sigma_m: float = 0.00002
    accuracy_amplitude_m: float = 0.0
    accuracy_wavelength_m: float = 1.0
    accuracy_terms: int = 6
    tcp_sigma_m: float = 0.0

    def __post_init__(self) -> None:
        check_positive(self.repeatability_sigma_m, "repeatability_sigma_m", allow_zero=True)
        check_positive(self.accuracy_amplitude_m, "accuracy_amplitude_m", allow_zero=True)
        check_positive(self.accuracy_wavelength_m, "accuracy_wavelength_m")
        check_count(self.accuracy_terms, "accuracy_terms", maximum=1000)
        check_positive(self.tcp_sigma_m, "tcp_sigma_m", allow_zero=True)

    @classmethod
    def none(cls) -> RobotErrorModel:
        """A perfect robot."""
        return cls(repeatability_sigma_m=0.0, accuracy_amplitude_m=0.0, tcp_sigma_m=0.0)

    def sample_repeatability_m(self, rng: np.random.Generator) -> FloatArray:
        """``(3,)`` TCP offset of one search, base frame, m."""
        if self.repeatability_sigma_m == 0.0:
            return np.zeros(3)
        return rng.normal(0.0, self.repeatability_sigma_m, size=3)

    def sample_tcp_error_m(self, rng: np.random.Generator) -> FloatArray:
        """``(3,)`` one TCP calibration error, sensor tool frame, m (no draw when it is off)."""
        if self.tcp_sigma_m == 0.0:
            return np.zeros(3)
        return rng.normal(0.0, self.tcp_sigma_m, size=3)

    def sample_field(self, rng: np.random.Generator) -> AccuracyField | None:
        """One robot's absolute-accuracy field, or ``None`` when the amplitude is 0."""
        if self.accuracy_amplitude_m == 0.0:
            return None
        k = int(self.accuracy_terms)
        directions = rng.normal(size=(k, 3))
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        wavelengths = self.accuracy_wavelength_m * rng.uniform(0.5, 1.5, size=k)
        # each sine term has RMS a / sqrt(2); scale so the sum has the requested RMS per axis
        amps = rng.normal(size=(k, 3)) * self.accuracy_amplitude_m * math.sqrt(2.0 / k)
        return AccuracyField(
            amplitudes_m=amps,
            wavevectors=directions * (2 * math.pi / wavelengths)[:, None],
            phases=rng.uniform(0, 2 * math.pi, size=k),
        )
