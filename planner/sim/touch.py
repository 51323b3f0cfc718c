"""The simulated touch-trigger probe: where the stylus ball meets the true, misplaced part.

A :data:`calib.probing.Probe` for :class:`calib.models.touch.TouchProbe`. The robot moves the
TCP (the ball's pole) along the commanded approach, off by its repeatability, accuracy field
and TCP error (:func:`planner.sim.probe.robot_offset`). Rays cast along the approach from the
ball's front half find the first triangle the ball meets; the contact is then solved exactly
against that triangle's plane (the sphere touches the plane when its centre is one radius
away) as long as the tangent point lies on the same planar face, else (an edge or a hole rim)
the sampled contact is kept. The probe triggers after the pre-travel left over from axial
qualification for that contact's direction (lobing) plus the trigger's scatter, and the
program compensates the ball radius along the face normal of the estimate the search was
commanded in (``calib.models.touch``); that compensated point is returned.

Failures are reasons, never numbers: no contact within the search length, the ball already
inside the part at the start, an edge search (a touch probe cannot run one), or an unreachable
commanded path (reachability hook). Every approach's landing is judged over the ball's
silhouette against the planar faces of the part.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.frames import check_transform, invert_transform
from calib.models.robot_error import AccuracyField, RobotErrorModel
from calib.models.touch import TouchProbe
from calib.probing import ProbeResult, SearchCommand
from planner.sim.probe import robot_offset
from planner.sim.raycast import MeshRayCaster
from planner.sim.search_events import FaceLookup, ProbeEvent, ReachabilityHook

FloatArray = NDArray[np.float64]

#: The tangent point is checked by a ray started this far before it, m.
_CHECK_LIFT_M = 1e-3


@dataclass
class SimulatedTouchProbe:
    """A touch-probe callback against the true part at ``T_base_wobj_true``.

    Args:
        caster: ray caster of the part mesh in its own (wobj) frame.
        T_base_wobj_true: ``(4, 4)`` where the part really is, base frame.
        rng: random generator for robot and trigger noise.
        sensor: the touch probe.
        robot_error: robot repeatability and accuracy model.
        accuracy_field: this robot's accuracy field, or None.
        faces: planar faces of the part and the face each search should land on, or None.
        tcp_error_m: ``(3,)`` this calibration's TCP error, sensor tool frame, m, or None.
        reachability: optional hook that vets the path each successful search really ran.
        edge_inset_m: unused (the proximity sensor's edge searches); accepted so that every
            simulator is built alike (:mod:`planner.sim.sensors`).
        edge_tolerance_m: unused, as ``edge_inset_m``.
    """

    caster: MeshRayCaster
    T_base_wobj_true: ArrayLike
    rng: np.random.Generator
    sensor: TouchProbe = field(default_factory=TouchProbe)
    robot_error: RobotErrorModel = field(default_factory=RobotErrorModel)
    accuracy_field: AccuracyField | None = None
    faces: FaceLookup | None = None
    tcp_error_m: FloatArray | None = None
    reachability: ReachabilityHook | None = None
    edge_inset_m: float = 0.0
    edge_tolerance_m: float = 0.0
    events: list[ProbeEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.T_base_wobj_true = check_transform(self.T_base_wobj_true, "T_base_wobj_true")
        self._T_wobj_base = invert_transform(self.T_base_wobj_true)

    def _fail(self, cmd: SearchCommand, reason: str) -> ProbeResult:
        self.events.append(ProbeEvent(cmd.point_id, cmd.kind, reason=reason))
        return ProbeResult(point_m=None, reason=reason)

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        """Run one commanded approach against the true part."""
        if cmd.kind != "approach":
            return self._fail(cmd, "a touch probe cannot run an edge search")
        start = np.asarray(cmd.start_m, float)
        axis = np.asarray(cmd.sensor_axis, float)
        direction = np.asarray(cmd.direction, float)
        offset = robot_offset(
            start, axis, self.rng, self.robot_error, self.accuracy_field, self.tcp_error_m
        )
        if float(direction @ axis) < 1.0 - 1e-9:
            return self._fail(cmd, "touch probe: only approaches along the stylus axis")
        r = self.sensor.radius_m
        R, t = self._T_wobj_base[:3, :3], self._T_wobj_base[:3, 3]
        centre0 = R @ (start + offset - r * axis) + t  # part frame from here on
        a = R @ axis
        origins = centre0 + self.sensor.front_points_m(a)
        dist, tri = self.caster.first_hits_ids(origins, np.broadcast_to(a, origins.shape))
        if np.any(dist <= 0.0):
            return self._fail(cmd, "stylus ball inside the part at start")
        k = int(np.argmin(dist))
        travel = float(dist[k])
        length = float(cmd.length_m)
        if not math.isfinite(travel):
            return self._fail(cmd, f"no contact within {length * 1e3:.0f} mm")
        normal = self.caster.triangle_normal(int(tri[k]))
        exact = self._plane_contact(centre0, a, int(tri[k]), normal)
        if exact is not None:
            travel = exact
        if travel <= 0.0:
            return self._fail(cmd, "stylus ball touching the part at start")
        normal_base = R.T @ normal  # the lobes turn with the probe: its tool frame is in base
        travel += self.sensor.pretravel_error_m(normal_base, axis) + self.sensor.sample_trigger_m(
            self.rng
        )
        if travel > length:
            return self._fail(cmd, f"no contact within {length * 1e3:.0f} mm")
        if self.reachability is not None:
            why = self.reachability(replace(cmd, length_m=max(travel, 1e-6)))
            if why:
                return self._fail(cmd, why)
        landing, frac = ("", 0.0) if self.faces is None else self.faces.landing(cmd.point_id, tri)
        self.events.append(
            ProbeEvent(cmd.point_id, cmd.kind, landing=landing, off_fraction=frac, travel_m=travel)
        )
        pole = start + travel * direction  # what the controller records (the TCP)
        n_est = -axis if cmd.stop_normal is None else np.asarray(cmd.stop_normal, float)
        point = pole - r * axis - r * n_est  # ball centre, then one radius along the normal
        return ProbeResult(point_m=point, travel_m=travel)

    def _plane_contact(
        self, centre0: FloatArray, a: FloatArray, triangle: int, normal: FloatArray
    ) -> float | None:
        """Travel at which the ball touches the plane of ``triangle`` (part frame), when its
        tangent point lies on the same planar face (else ``None``: an edge or rim contact)."""
        cos = float(a @ normal)
        if cos > -1e-9:
            return None
        gap = float(normal @ centre0) - self.caster.triangle_offset(triangle) - self.sensor.radius_m
        travel = gap / -cos
        tangent = centre0 + travel * a - self.sensor.radius_m * normal
        lift = tangent - _CHECK_LIFT_M * a
        d, hit = self.caster.first_hits_ids(lift[None], a[None])
        if not abs(float(d[0]) - _CHECK_LIFT_M) <= 1e-7:
            return None
        if self.faces is None:
            same = int(hit[0]) == triangle or bool(
                np.allclose(self.caster.triangle_normal(int(hit[0])), normal, atol=1e-9)
            )
        else:
            faces = self.faces.triangle_face
            same = int(hit[0]) >= 0 and faces[int(hit[0])] == faces[triangle] >= 0
        return travel if same else None
