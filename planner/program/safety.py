"""Safe search starts: how far from the nominal surface a search must start so that a part
misplaced within the plan's tolerance never has the sensor inside or against it.

A misplacement is a rigid motion of the part: a translation up to ``max_translation_m`` and a
rotation up to ``max_angle_rad`` about a pivot (by default the centroid of the probe points, as
:func:`planner.sim.montecarlo.default_pivot`). A nominal surface point ``p`` moves by at most
``t + |p - c| * angle`` and the face tilts by at most ``angle``, so along the nominal normal the
true face lies within ``(t + |p - c| * angle) / cos(angle)`` of the nominal one
(:func:`surface_shift_bound_m`). A search whose sensor TCP starts ``bound + sensing_distance /
cos(angle) + margin`` outside the nominal surface starts at least ``sensing_distance`` from the
true face, i.e. the sensor cannot already touch or detect it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

#: Extra clearance on top of the bound, metres.
SAFETY_MARGIN_M = 0.002


@dataclass(frozen=True)
class SafetySpec:
    """What the safe starts of a program are computed for.

    Attributes:
        max_translation_m: largest translation of the part from its nominal pose, m.
        max_angle_rad: largest rotation of the part about ``pivot_wobj_m``, rad.
        pivot_wobj_m: ``(3,)`` pivot of that rotation, nominal wobj frame, m.
        sensing_distance_m: the sensor's switching distance (TCP to sensor face), m.
        margin_m: extra clearance, m.
    """

    max_translation_m: float = 0.020
    max_angle_rad: float = math.radians(3.0)
    pivot_wobj_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    sensing_distance_m: float = 0.008
    margin_m: float = SAFETY_MARGIN_M

    def surface_shift_bound_m(self, point_wobj_m: ArrayLike) -> float:
        """Largest distance, along the nominal normal, of the true face from the nominal point, m.

        Args:
            point_wobj_m: ``(3,)`` nominal surface point, wobj frame, m.
        """
        lever = float(np.linalg.norm(np.asarray(point_wobj_m, float) - self.pivot_wobj_m))
        moved = self.max_translation_m + lever * self.max_angle_rad
        return moved / math.cos(self.max_angle_rad)

    def start_clearance_m(self, point_wobj_m: ArrayLike) -> float:
        """Smallest safe distance of a search start outside the nominal surface, m."""
        sd = self.sensing_distance_m / math.cos(self.max_angle_rad)
        return self.surface_shift_bound_m(point_wobj_m) + sd + self.margin_m

    def overtravel_m(self, point_wobj_m: ArrayLike) -> float:
        """Travel past the nominal surface that still finds a part misplaced away, m."""
        return self.surface_shift_bound_m(point_wobj_m) + self.margin_m

    def describe(self) -> str:
        """One line for program headers (mm, degrees)."""
        c = ", ".join(f"{v * 1e3:.1f}" for v in self.pivot_wobj_m)
        return (
            f"part misplaced up to {self.max_translation_m * 1e3:.1f} mm and "
            f"{math.degrees(self.max_angle_rad):.2f} deg about [{c}] mm (wobj), sensing "
            f"distance {self.sensing_distance_m * 1e3:.1f} mm"
        )
