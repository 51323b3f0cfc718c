"""The touch-trigger probe: a ball-tipped stylus on a kinematic seat, held by the robot.

This struct is the one definition of the touch probe: the plan holds it (``validation.sensor``
with ``"kind": "touch"``), the simulation (:mod:`planner.sim.touch`) finds where its ball meets
the true part, the planar-face check sizes the footprint with the ball's radius, and the
exporters take its standoff (0: the ball touches when the TCP reaches the surface).

*TCP.* The sensor TCP is the ball's pole on the stylus axis (the ball centre plus one radius
along the axis), so on a face square to the stylus the TCP is on the surface at the touch, as
with the proximity sensor. The program records the TCP where the probe triggers and
*compensates the ball radius along the surface normal*: the contact point is the ball centre
minus one radius along the face's outward normal, taken from the work object as estimated when
the search was commanded (the true normal is unknown). On a face tilted by ``theta`` from the
estimate the compensated point lies ``r (1 - cos theta)`` off the true face (the cosine error),
and a ball that meets an edge or a hole rim instead of the face reports that contact.

*Pre-travel.* The stylus deflects before the kinematic seat opens; the mean pre-travel along
the stylus axis is removed by qualifying the probe on a reference (as CMM software does), so it
does not bias a measurement. What remains is the pre-travel *variation* with the direction of the
contact force (lobing: a kinematic seat of three rods triggers with a three-lobed pattern around
the stylus, and axial contacts need more force than side contacts) and the trigger's
repeatability. For a contact whose force makes the angle ``psi`` with the stylus axis at azimuth
``phi`` about it (in the tool frame of :func:`calib.models.sensor.face_frame`)::

    pretravel(psi, phi) = axial cos^2 psi + (side + lobing cos(3 phi + phase)) sin^2 psi

and the error left after qualification along the axis is ``pretravel - axial``. Sources and
plausible ranges of the defaults are in ``docs/simulation.md`` (Estler et al. 1996 and 1997,
Precision Engineering: the kinematic-seat lobing model; NPL Good Practice Guide 43, CMM probing:
pre-travel, qualification and ball-radius compensation; probe makers' datasheets).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from calib.errors import PlanError
from calib.limits import MAX_RAYS
from calib.models.proximity import sunflower_disk
from calib.models.sensor import SearchNoise, face_frame
from calib.structs import Strict, check_count, check_positive

FloatArray = NDArray[np.float64]
#: Why the ball's rays are bounded (:data:`calib.limits.MAX_RAYS`).
TOUCH_RAYS_WHY = "each contact casts them at once, ~0.3 kB a ray; the default 121 covers the ball"


class TouchProbe(Strict, frozen=True, kw_only=True, tag="touch", tag_field="kind"):
    """A kinematic touch-trigger probe with a ball stylus along the sensor axis.

    Attributes:
        tip_diameter_m: diameter of the stylus ball, m (default a 6 mm ruby ball).
        axial_pretravel_m: mean pre-travel of a contact along the stylus axis, m (removed by
            qualification along the axis).
        side_pretravel_m: mean pre-travel of a contact square to the stylus, m.
        lobing_amplitude_m: amplitude of the three-lobed variation of the side pre-travel
            around the stylus, m.
        lobing_phase_rad: azimuth phase of the lobes in the tool frame, rad.
        trigger_repeatability_sigma_m: 1-sigma scatter of the trigger point of repeated
            contacts from one direction, m.
        n_rays: rays from the ball's front half used to find the first contact on the mesh.
    """

    #: The sensor kind's name in the sensor registry (:mod:`planner.sim.sensors`).
    KIND: ClassVar[str] = "touch"

    tip_diameter_m: float = 0.006
    axial_pretravel_m: float = 0.000012
    side_pretravel_m: float = 0.000006
    lobing_amplitude_m: float = 0.000002
    lobing_phase_rad: float = 0.0
    trigger_repeatability_sigma_m: float = 0.0000005
    n_rays: int = 121

    def __post_init__(self) -> None:
        check_positive(self.tip_diameter_m, "tip_diameter_m")
        check_positive(self.axial_pretravel_m, "axial_pretravel_m", allow_zero=True)
        check_positive(self.side_pretravel_m, "side_pretravel_m", allow_zero=True)
        check_positive(self.lobing_amplitude_m, "lobing_amplitude_m", allow_zero=True)
        if not math.isfinite(self.lobing_phase_rad):
            raise PlanError(f"lobing_phase_rad: must be finite, got {self.lobing_phase_rad}")
        check_positive(
            self.trigger_repeatability_sigma_m, "trigger_repeatability_sigma_m", allow_zero=True
        )
        check_count(self.n_rays, "n_rays", minimum=7, maximum=MAX_RAYS, why=TOUCH_RAYS_WHY)

    @classmethod
    def ideal(cls) -> TouchProbe:
        """A probe without pre-travel variation or trigger scatter (exactness tests)."""
        return cls(
            axial_pretravel_m=0.0,
            side_pretravel_m=0.0,
            lobing_amplitude_m=0.0,
            trigger_repeatability_sigma_m=0.0,
        )

    # ------------------------------------------------------------------ the SensorModel
    @property
    def radius_m(self) -> float:
        """Ball radius, m."""
        return self.tip_diameter_m / 2

    @property
    def footprint_radius_m(self) -> float:
        """Radius of the planar area the ball needs around a probe point, m (its radius)."""
        return self.radius_m

    @property
    def standoff_m(self) -> float:
        """0: the ball touches when the TCP (its pole) reaches the surface."""
        return 0.0

    @property
    def runs_edge_searches(self) -> bool:
        """False: a touch probe triggers on contact and cannot slide to the end of a face."""
        return False

    def edge_event_offset_m(self, inset_m: float) -> float:
        """0: a touch probe runs no edge searches."""
        return 0.0

    def search_noise(self, kind: str, edge_inset_m: float) -> SearchNoise:
        """The trigger's scatter along the search (see :class:`SearchNoise`).

        Raises:
            PlanError: ``kind`` is ``"edge"`` (a touch probe cannot run an edge search).
        """
        if kind != "approach":
            raise PlanError("validation.sensor: a touch probe cannot run an edge search")
        return SearchNoise(self.trigger_repeatability_sigma_m, 0.0)

    # ------------------------------------------------------------------ geometry
    def front_points_m(self, axis: FloatArray) -> FloatArray:
        """``(n_rays, 3)`` points on the ball's front half, relative to its centre, m.

        The half facing along ``axis`` (the stylus axis, into the surface) is sampled by
        projecting an equal-area disk onto it, so the rays cover the ball's silhouette evenly;
        the first point is the pole.
        """
        a = np.asarray(axis, dtype=np.float64)
        u, v = face_frame(a)
        disk, h = _ball_front(self.n_rays, self.radius_m)
        pts = disk[:, :1] * u + disk[:, 1:] * v + h[:, None] * a
        return np.vstack([self.radius_m * a, pts])

    # ------------------------------------------------------------------ pre-travel
    def pretravel_error_m(self, contact_normal: FloatArray, axis: FloatArray) -> float:
        """Pre-travel left after axial qualification for a contact on a face, m.

        Args:
            contact_normal: ``(3,)`` outward unit normal of the surface at the contact.
            axis: ``(3,)`` the stylus axis (into the surface), same frame.

        Returns:
            ``pretravel(psi, phi) - axial_pretravel_m`` (see the module docstring): positive
            when the probe triggers later than on a square face.
        """
        a = np.asarray(axis, dtype=np.float64)
        f = -np.asarray(contact_normal, dtype=np.float64)  # the push on the ball, into the probe
        cos_psi = min(max(float(f @ a), -1.0), 1.0)
        sin2 = max(0.0, 1.0 - cos_psi * cos_psi)
        if sin2 == 0.0:
            return 0.0
        u, v = face_frame(a)
        phi = math.atan2(float(f @ v), float(f @ u))
        side = self.side_pretravel_m + self.lobing_amplitude_m * math.cos(
            3.0 * phi + self.lobing_phase_rad
        )
        return (side - self.axial_pretravel_m) * sin2

    def sample_trigger_m(self, rng: np.random.Generator) -> float:
        """One trigger scatter ``N(0, trigger_repeatability_sigma_m)``, m."""
        if self.trigger_repeatability_sigma_m == 0.0:
            return 0.0
        return float(rng.normal(0.0, self.trigger_repeatability_sigma_m))


@lru_cache(maxsize=16)
def _ball_front(n_rays: int, radius_m: float) -> tuple[FloatArray, FloatArray]:
    """``(disk (n_rays - 1, 2), height (n_rays - 1,))`` of :meth:`TouchProbe.front_points_m`:
    the equal-area disk over the ball's silhouette and each point's height on the ball's front
    half, m (depend on the ball only; shared, read-only)."""
    disk = sunflower_disk(n_rays - 1, radius_m * (1.0 - 1e-9))
    h = np.sqrt(np.maximum(radius_m**2 - np.sum(disk**2, axis=1), 0.0))
    h.setflags(write=False)
    return disk, h
