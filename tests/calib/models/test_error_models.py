"""Robot repeatability, the absolute-accuracy field and the misplacement tolerance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from calib.errors import PlanError
from calib.frames import rotvec_from_matrix
from calib.models import Misplacement, RobotErrorModel


def test_misplacement_stays_within_tolerance_and_turns_about_the_pivot(rng) -> None:
    m = Misplacement(max_translation_m=0.020, max_angle_rad=math.radians(3.0))
    pivot = np.array([0.0, -0.3, -0.1])
    shifts, angles = [], []
    for _ in range(2000):
        T = m.sample(rng, pivot)
        R = T[:3, :3]
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-12)
        shifts.append(np.linalg.norm(T[:3, :3] @ pivot + T[:3, 3] - pivot))
        angles.append(np.linalg.norm(rotvec_from_matrix(R)))
    assert max(shifts) <= 0.020 + 1e-12 and max(shifts) > 0.019
    assert max(angles) <= math.radians(3.0) + 1e-12 and max(angles) > math.radians(2.9)
    # uniform in the ball: the median radius is 0.5^(1/3) of the maximum
    assert np.median(shifts) == pytest.approx(0.020 * 0.5 ** (1 / 3), rel=0.05)


def test_zero_misplacement_is_identity(rng) -> None:
    assert np.allclose(
        Misplacement(max_translation_m=0.0, max_angle_rad=0.0).sample(rng, [1.0, 2.0, 3.0]),
        np.eye(4),
    )


def test_repeatability_has_the_given_sigma(rng) -> None:
    model = RobotErrorModel(repeatability_sigma_m=3e-5)
    e = np.array([model.sample_repeatability_m(rng) for _ in range(4000)])
    assert np.std(e, axis=0) == pytest.approx([3e-5] * 3, rel=0.06)
    assert np.allclose(RobotErrorModel.none().sample_repeatability_m(rng), 0.0)
    assert RobotErrorModel.none().sample_field(rng) is None


def test_accuracy_field_is_smooth_with_the_given_rms(rng) -> None:
    model = RobotErrorModel(accuracy_amplitude_m=5e-4, accuracy_wavelength_m=1.0)
    rms = []
    for _ in range(40):
        field = model.sample_field(rng)
        p = rng.uniform(-2, 2, size=(500, 3))
        rms.append(np.sqrt(np.mean(field(p) ** 2)))
        # smooth: 1 mm apart, the error changes by far less than a micrometre per millimetre
        step = field(p + np.array([1e-3, 0.0, 0.0])) - field(p)
        assert np.abs(step).max() < 2 * math.pi * 5e-4 * 1e-3 / 0.5 * 3
    assert np.mean(rms) == pytest.approx(5e-4, rel=0.2)


def test_bad_values_name_the_field() -> None:
    with pytest.raises(PlanError, match=r"^max_translation_m: must be >= 0"):
        Misplacement(max_translation_m=-1.0)
    with pytest.raises(PlanError, match=r"^repeatability_sigma_m: must be >= 0"):
        RobotErrorModel(repeatability_sigma_m=-1e-5)
