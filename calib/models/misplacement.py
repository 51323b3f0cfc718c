"""How far the real part may lie from its nominal pose.

:class:`Misplacement` is the one definition of that tolerance: the plan file holds it
(``validation.misplacement``), the simulation draws true part poses from it, and the exporters
and the search checks size the safe search starts with it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_vector3
from calib.frames import make_transform, matrix_from_rotvec
from calib.structs import Strict, check_positive

FloatArray = NDArray[np.float64]


class Misplacement(Strict, frozen=True, kw_only=True):
    """Tolerance of the part's placement: a random rigid motion about a pivot.

    Attributes:
        max_translation_m: largest translation, uniform in a ball, m (paper: 20 mm).
        max_angle_rad: largest rotation, uniform in angle about a random axis, rad (paper: 3 deg).
    """

    max_translation_m: float = 0.020
    max_angle_rad: float = math.radians(3.0)

    def __post_init__(self) -> None:
        check_positive(self.max_translation_m, "max_translation_m", allow_zero=True)
        check_positive(self.max_angle_rad, "max_angle_rad", allow_zero=True)

    def motion_covariance(self, pivot_wobj_m: ArrayLike) -> FloatArray:
        """``(6, 6)`` covariance of the small motion ``delta = (dt, dr)`` of the wobj frame
        (its own axes, m and rad; :func:`calib.frames.small_motion`) that :meth:`sample`
        draws, to first order.

        The translation is uniform in a ball of radius ``a`` (``a^2 / 5`` per axis), the
        rotation vector a uniform angle in ``[-b, b]`` about a uniform axis (``b^2 / 9`` per
        axis); turning about the pivot ``c`` adds ``c x dr`` to the translation at the origin.
        """
        c = check_vector3(pivot_wobj_m, "pivot_wobj_m")
        A = np.eye(6)
        A[:3, 3:] = [[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]]
        S = np.diag([self.max_translation_m**2 / 5.0] * 3 + [self.max_angle_rad**2 / 9.0] * 3)
        cov: FloatArray = A @ S @ A.T
        return cov

    def sample(self, rng: np.random.Generator, pivot_wobj_m: ArrayLike) -> FloatArray:
        """``T_nominal_true`` ``(4, 4)``: the true part frame in the nominal one.

        The rotation turns about ``pivot_wobj_m`` (``(3,)``, nominal wobj, m), e.g. the middle
        of the probed region, so a 3 deg turn does not swing the far end of a 2 m part by 100 mm.
        """
        c = check_vector3(pivot_wobj_m, "pivot_wobj_m")
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        t = direction * self.max_translation_m * rng.uniform() ** (1.0 / 3.0)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        R = matrix_from_rotvec(axis * rng.uniform(-self.max_angle_rad, self.max_angle_rad))
        return make_transform(R, c - R @ c + t)
