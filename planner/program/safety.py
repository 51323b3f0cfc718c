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

A plan whose searches are sized for an adaptive program (``search_sizing: "steered"``,
:mod:`planner.program.steered_searches`) carries, for each search after the program's first
update, the smaller bound of the shift the estimate so far leaves (``steered_bounds_m``): its
program starts that search nearer and runs it shorter. Only a program that commands the search
in that estimate may do so, which :func:`planner.program.build.build_program` holds to.
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
        steered: the plan's searches are sized for an adaptive program (``search_sizing:
            "steered"``): only a program that commands them in its estimate may run them.
        steered_bounds_m: ``((point id, bound), ...)``: for the searches an adaptive program
            commands in an estimate, the largest shift of their face in that estimate, m
            (:func:`planner.program.steered_searches.steered_bounds`); the other points keep
            the whole misplacement's.
    """

    max_translation_m: float = 0.020
    max_angle_rad: float = math.radians(3.0)
    pivot_wobj_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    sensing_distance_m: float = 0.008
    margin_m: float = SAFETY_MARGIN_M
    steered: bool = False
    steered_bounds_m: tuple[tuple[str, float], ...] = ()

    def surface_shift_bound_m(self, point_wobj_m: ArrayLike, point_id: str | None = None) -> float:
        """Largest distance, along the nominal normal, of the true face from the nominal point,
        in the frame the point's search is commanded in, m.

        Args:
            point_wobj_m: ``(3,)`` nominal surface point, wobj frame, m.
            point_id: the plan's point id: its steered bound when it has one, never more
                than the whole misplacement's (``None``: the whole misplacement's).
        """
        lever = float(np.linalg.norm(np.asarray(point_wobj_m, float) - self.pivot_wobj_m))
        moved = self.max_translation_m + lever * self.max_angle_rad
        whole = moved / math.cos(self.max_angle_rad)
        steered = dict(self.steered_bounds_m).get(point_id) if point_id is not None else None
        return whole if steered is None else min(whole, steered)

    def start_clearance_m(self, point_wobj_m: ArrayLike, point_id: str | None = None) -> float:
        """Smallest safe distance of a search start outside the nominal surface, m
        (``point_id`` as :meth:`surface_shift_bound_m`)."""
        sd = self.sensing_distance_m / math.cos(self.max_angle_rad)
        return self.surface_shift_bound_m(point_wobj_m, point_id) + sd + self.margin_m

    def overtravel_m(self, point_wobj_m: ArrayLike, point_id: str | None = None) -> float:
        """Travel past the nominal surface that still finds a part misplaced away, m
        (``point_id`` as :meth:`surface_shift_bound_m`)."""
        return self.surface_shift_bound_m(point_wobj_m, point_id) + self.margin_m

    def describe(self) -> str:
        """One line for program headers (mm, degrees)."""
        c = ", ".join(f"{v * 1e3:.1f}" for v in self.pivot_wobj_m)
        steered = (
            f"; the searches of {', '.join(i for i, _ in self.steered_bounds_m)} start nearer, "
            "sized for what the estimate before them leaves (search_sizing steered: an "
            "adaptive program only)"
            if self.steered_bounds_m
            else ""
        )
        return (
            f"part misplaced up to {self.max_translation_m * 1e3:.1f} mm and "
            f"{math.degrees(self.max_angle_rad):.2f} deg about [{c}] mm (wobj), sensing "
            f"distance {self.sensing_distance_m * 1e3:.1f} mm{steered}"
        )
