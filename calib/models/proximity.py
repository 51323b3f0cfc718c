"""The inductive proximity sensor: when does an M18 shielded sensor switch over a real part?

This struct is the one definition of the sensor: the plan file holds it
(``validation.sensor``), the simulation casts its ray bundle (:mod:`planner.sim.proximity`), the
planar-face check sizes its footprint with it, and the exporters take its sensing distance for
the safe starts.

The sensor face is a disk (diameter ``face_diameter_m``) sampled by a bundle of equal-area rays
cast along the sensor axis. A ray that meets metal at distance ``d`` from the face contributes
``exp(-(d - Sn) / decay_length)`` (eddy-current damping falls off roughly exponentially with the
gap); the signal is the area-weighted mean over the face:

    S = sum_i w_i exp(-(d_i - Sn) / lambda),     sum_i w_i = 1.

A full flat target at the nominal sensing distance ``Sn`` gives ``S = 1``: the sensor switches on
when ``S >= exp(-nu / lambda)`` (``nu`` the switching-point jitter, ``nu ~ N(0, sigma_rep)``),
and off again when ``S < exp(-(h Sn + nu) / lambda)`` (``h`` the hysteresis fraction). So a face
that only partly covers the sensor (a slot hole, an edge) switches closer: over a covered fraction
``c`` of a flat face the switching distance shrinks by ``lambda ln(1 / c)``; inclined faces and
holes change the reading in the same way, through the ray distances. The sensor TCP lies at
``Sn`` in front of the face, so on a full flat target the TCP is on the surface at the switch.

Defaults and their sources are in ``docs/simulation.md``. Pure numpy: no ray casting here.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from calib.errors import PlanError
from calib.limits import MAX_RAYS, MAX_SCAN_RAYS
from calib.models.sensor import SearchNoise, face_frame
from calib.structs import Strict, check_count, check_positive

FloatArray = NDArray[np.float64]

_GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))
#: Why the rays are bounded (:data:`calib.limits.MAX_RAYS`, :data:`calib.limits.MAX_SCAN_RAYS`).
RAYS_WHY = "each search casts them at once, ~0.3 kB a ray; the default 256 resolves 0.4 %"
SCAN_RAYS_WHY = "an edge scan casts them at every 2.5 mm step at once, ~0.3 kB a ray"


@lru_cache(maxsize=32)
def _sunflower(n: int, radius_m: float) -> FloatArray:
    pts = np.zeros((1, 2))
    if n > 1:
        i = np.arange(n)
        r = radius_m * np.sqrt((i + 0.5) / n)
        theta = i * _GOLDEN_ANGLE
        pts = np.column_stack([r * np.cos(theta), r * np.sin(theta)])
    pts.flags.writeable = False
    return pts


def sunflower_disk(n: int, radius_m: float) -> FloatArray:
    """``(n, 2)`` equal-area sample points on a disk (Vogel's sunflower); one point: the centre.

    The array is shared and read-only.
    """
    return _sunflower(int(n), float(radius_m))


class ProximitySensor(Strict, frozen=True, kw_only=True, tag="proximity", tag_field="kind"):
    """A cylindrical shielded inductive proximity sensor (defaults: M18, Sn = 8 mm).

    In a plan: ``"sensor": {"kind": "proximity", ...}``; a plan written before the touch probe
    existed has no ``kind`` and loads as this sensor (:func:`calib.plan.file.plan_from_json`).

    Attributes:
        face_diameter_m: diameter of the active face, m (paper: 18 mm).
        sensing_distance_m: nominal sensing distance Sn on a full flat steel target, m (paper: 8).
        decay_length_m: length ``lambda`` over which the damping signal falls by ``e``, m.
        hysteresis_fraction: switch-off distance exceeds the switch-on distance by this part of Sn.
        repeatability_sigma_m: 1-sigma jitter of the switching distance, m.
        n_rays: rays over the face used for switching decisions (resolution of the coverage).
        n_scan_rays: fewer rays used only to scan an edge search coarsely before refining.
    """

    #: The sensor kind's name in the sensor registry (:mod:`planner.sim.sensors`).
    KIND: ClassVar[str] = "proximity"

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
        check_count(self.n_rays, "n_rays", maximum=MAX_RAYS, why=RAYS_WHY)
        check_count(self.n_scan_rays, "n_scan_rays", maximum=MAX_SCAN_RAYS, why=SCAN_RAYS_WHY)

    @classmethod
    def ideal(cls) -> ProximitySensor:
        """A point sensor without noise or hysteresis: switches exactly at Sn on any surface."""
        return cls(
            face_diameter_m=0.0,
            hysteresis_fraction=0.0,
            repeatability_sigma_m=0.0,
            n_rays=1,
            n_scan_rays=1,
        )

    # ------------------------------------------------------------------ geometry
    @property
    def radius_m(self) -> float:
        """Face radius, m."""
        return self.face_diameter_m / 2

    @property
    def footprint_radius_m(self) -> float:
        """Radius of the area that must lie on one planar face under the sensor, m."""
        return self.radius_m

    @property
    def standoff_m(self) -> float:
        """Distance from the sensor face to the TCP (the surface point at the switch), m."""
        return self.sensing_distance_m

    @property
    def face_points_m(self) -> FloatArray:
        """``(n_rays, 2)`` ray origins on the face, sensor-face coordinates, m (read-only)."""
        return sunflower_disk(self.n_rays, self.radius_m)

    @property
    def scan_points_m(self) -> FloatArray:
        """``(n_scan_rays, 2)`` coarse ray origins on the face, m (read-only)."""
        return sunflower_disk(self.n_scan_rays, self.radius_m)

    @property
    def runs_edge_searches(self) -> bool:
        """True: the sensor stops detecting where the face under it ends."""
        return True

    def face_frame(self, axis: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Two unit vectors ``(u, v)`` spanning the face, perpendicular to ``axis`` ``(3,)``
        (:func:`calib.models.sensor.face_frame`)."""
        return face_frame(axis)

    def face_offsets_m(self, axis: FloatArray, coarse: bool = False) -> FloatArray:
        """``(n, 3)`` ray-origin offsets from the face centre for a sensor axis ``(3,)``, m."""
        pts = self.scan_points_m if coarse else self.face_points_m
        u, v = self.face_frame(axis)
        return pts[:, :1] * u + pts[:, 1:] * v

    def ray_origins(self, tcp_m: FloatArray, axis: FloatArray, coarse: bool = False) -> FloatArray:
        """Ray origins on the face for TCP position(s) ``(..., 3)``: ``(..., n, 3)``, same frame.

        The face centre lies ``Sn`` behind the TCP along ``axis``.
        """
        centre = np.asarray(tcp_m, float) - self.sensing_distance_m * np.asarray(axis, float)
        return centre[..., None, :] + self.face_offsets_m(axis, coarse)

    # ------------------------------------------------------------------ response
    def signal(self, distances_m: FloatArray) -> FloatArray:
        """Damping signal ``(...)`` from face-to-metal distances ``(..., n)`` (m, ``inf``: none).

        1.0 is the switch-on level of a full flat target at Sn (without jitter).
        """
        d = np.asarray(distances_m, dtype=np.float64)
        with np.errstate(over="ignore"):
            terms = np.exp((self.sensing_distance_m - d) * (1.0 / self.decay_length_m))
        return np.add.reduce(terms, axis=-1) * (1.0 / d.shape[-1])

    def on_level(self, jitter_m: float = 0.0) -> float:
        """Signal level at which the sensor switches on, given a switching-distance jitter (m)."""
        return math.exp(-jitter_m / self.decay_length_m)

    def off_level(self, jitter_m: float = 0.0) -> float:
        """Signal level below which a switched-on sensor switches off (hysteresis), jitter in m."""
        gap = self.hysteresis_fraction * self.sensing_distance_m + jitter_m
        return math.exp(-gap / self.decay_length_m)

    def switch_travel_m(self, distances_m: FloatArray, jitter_m: float = 0.0) -> float:
        """Travel along the sensor axis until the sensor switches on, m (<= 0: already on).

        Moving along the axis shortens every ray by the travel, so ``S(s) = S(0) exp(s / lambda)``
        and the switching travel is ``lambda ln(on_level / S(0))`` exactly; ``inf`` when no ray
        meets metal.
        """
        return self.travel_to_switch_m(float(self.signal(distances_m)), jitter_m)

    def travel_to_switch_m(self, signal: float, jitter_m: float = 0.0) -> float:
        """:meth:`switch_travel_m` from the signal at the start, ``signal`` (:meth:`signal`:
        dimensionless, 1.0 over a full flat target at Sn), for callers that have the signals of
        many searches at once; the travel is in m, ``inf`` for a signal of 0 (no metal)."""
        if signal <= 0.0:
            return math.inf
        return self.decay_length_m * math.log(self.on_level(jitter_m) / signal)

    def coverage_shift_m(self, covered_fraction: float) -> float:
        """How much closer the switch happens over a flat face covering ``covered_fraction``, m.

        Raises:
            PlanError: ``covered_fraction`` is not in ``(0, 1]``.
        """
        if not 0.0 < covered_fraction <= 1.0:
            raise PlanError(f"covered_fraction must be in (0, 1], got {covered_fraction}")
        return self.decay_length_m * math.log(1.0 / covered_fraction)

    def edge_event_offset_m(self, inset_m: float) -> float:
        """How far past a straight edge the face centre is when the sensor switches off, m.

        The sensor slides over a flat face ``inset_m`` closer than Sn (signal ``exp(inset /
        lambda)`` while fully covered) towards a straight edge; it switches off (no jitter) when
        the covered fraction ``c(t) = (acos(t/R) - (t/R) sqrt(1 - (t/R)^2)) / pi`` of the disk
        falls to ``off_level() exp(-inset / lambda)``. Solved for ``t`` on the exact disk, not
        the ray bundle: this is the analytic bias of an edge search, which a robot program
        measures once on a reference edge (the A-H settings' ``edge_event_offset_m``).

        Raises:
            PlanError: the inset is too small for the sensor to detect the face at all.
        """
        c_off = self.off_level() * math.exp(-float(inset_m) / self.decay_length_m)
        if c_off >= 1.0:
            raise PlanError(
                f"edge inset {inset_m} m is too small: the sensor would not detect the face"
            )
        r = self.radius_m
        if r == 0.0:
            return 0.0

        def covered(t: float) -> float:
            u = min(max(t / r, -1.0), 1.0)
            return (math.acos(u) - u * math.sqrt(1.0 - u * u)) / math.pi

        lo, hi = -r, r  # covered(-r) = 1 > c_off > 0 = covered(r)
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if covered(mid) > c_off:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    def search_noise(self, kind: str, edge_inset_m: float) -> SearchNoise:
        """First-order noise of a search (see :class:`calib.models.sensor.SearchNoise`).

        An approach switches when the signal reaches the on level, so the jitter ``nu`` moves
        the event by ``nu`` itself. An edge search switches off where the covered fraction of
        the face falls to ``off_level(nu) exp(-inset / lambda)``: the jitter and a TCP running
        closer to the face (a larger inset) both move the event by ``k = d offset / d inset``
        per metre (:meth:`edge_event_offset_m`, on the exact disk; about 1.2 for the defaults).
        """
        if kind == "approach":
            return SearchNoise(self.repeatability_sigma_m, 0.0)
        h = 1e-5
        k = self.edge_event_offset_m(edge_inset_m + h) - self.edge_event_offset_m(edge_inset_m - h)
        k /= 2 * h
        return SearchNoise(abs(k) * self.repeatability_sigma_m, k)

    def sample_jitter_m(self, rng: np.random.Generator) -> float:
        """One switching-distance jitter ``nu ~ N(0, repeatability_sigma_m)``, m."""
        if self.repeatability_sigma_m == 0.0:
            return 0.0
        return float(rng.normal(0.0, self.repeatability_sigma_m))
