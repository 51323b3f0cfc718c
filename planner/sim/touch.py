"""The simulated touch-trigger probe: where the stylus ball meets the true, misplaced part.

A :data:`calib.probing.Probe` for :class:`calib.models.touch.TouchProbe`. The robot moves the
TCP (the ball's pole) along the commanded approach, off by its repeatability, accuracy field
and TCP error (:func:`planner.sim.probe.robot_offset`). Rays cast along the approach from the
ball's front half find the triangles the ball meets first; the contact is then solved exactly
for the sweeping ball against each of them (:func:`sweep_contact`: its face when the tangent
point lies inside it, else an edge or a corner, e.g. a hole's rim or the face's end). The
probe triggers after the pre-travel left over from axial qualification for that contact's
direction (lobing) plus the trigger's scatter, and the program compensates the ball radius
along the face normal of the estimate the search was commanded in (``calib.models.touch``);
that compensated point is returned.

Failures are reasons, never numbers: no contact within the search length, the ball already
inside the part at the start, an edge search (a touch probe cannot run one), or an unreachable
commanded path (reachability hook). Every approach's landing is judged over the ball's
silhouette against the planar faces of the part, and a ball that meets an edge or another face
first is counted as landed off its face.
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
from planner.sim.search_events import LANDED_OFF_FACE, FaceLookup, ProbeEvent, ReachabilityHook

FloatArray = NDArray[np.float64]


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
        length = float(cmd.length_m)
        if np.any(dist <= 0.0):
            return self._fail(cmd, "stylus ball inside the part at start")
        if not np.any(np.isfinite(dist)):
            return self._fail(cmd, f"no contact within {length * 1e3:.0f} mm")
        # the exact first contact of the sweeping ball with the triangles the rays met near
        # the first hit: a face (tangent point inside it), an edge or a corner
        near = np.unique(tri[np.isfinite(dist) & (dist <= float(dist.min()) + r)])
        travel, normal, on_face_of = sweep_contact(self.caster, centre0, a, r, near)
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
        if self.faces is not None and not landing:
            want = self.faces.intended.get(cmd.point_id, -1)
            face = self.faces.triangle_face[on_face_of] if on_face_of >= 0 else -1
            if want >= 0 and face != want:  # the ball met an edge or another face first
                landing = LANDED_OFF_FACE
        self.events.append(
            ProbeEvent(cmd.point_id, cmd.kind, landing=landing, off_fraction=frac, travel_m=travel)
        )
        pole = start + travel * direction  # what the controller records (the TCP)
        n_est = -axis if cmd.stop_normal is None else np.asarray(cmd.stop_normal, float)
        point = pole - r * axis - r * n_est  # ball centre, then one radius along the normal
        return ProbeResult(point_m=point, travel_m=travel)


def sweep_contact(
    caster: MeshRayCaster,
    centre0: FloatArray,
    a: FloatArray,
    r: float,
    triangles: NDArray[np.int64],
) -> tuple[float, FloatArray, int]:
    """First contact of a ball of radius ``r`` moving from ``centre0`` along unit ``a`` with
    ``triangles`` (mesh frame): ``(travel, contact normal, triangle)``.

    Each triangle is met at its face (the tangent point inside it), an edge or a corner,
    whichever comes first; the normal points from the contact to the ball's centre. The
    triangle is returned when the contact is on its face, else ``-1`` (an edge or corner).
    """
    best = (math.inf, -a, -1)
    for k in triangles:
        n = caster.triangle_normal(int(k))
        v = caster.triangle_vertices(int(k))
        cos = float(a @ n)
        if cos < -1e-12:  # the face, when the tangent point falls inside the triangle
            tt = (float(n @ centre0) - caster.triangle_offset(int(k)) - r) / -cos
            q = centre0 + tt * a - r * n
            if tt < best[0] and _inside(q, v, n):
                best = (tt, n, int(k))
        for i in range(3):  # the edges and corners
            p, e = v[i], v[(i + 1) % 3] - v[i]
            length = float(np.linalg.norm(e))
            e = e / length
            u = centre0 - p
            u_perp, a_perp = u - (u @ e) * e, a - (a @ e) * e
            tt = _first_root(
                float(a_perp @ a_perp), float(u_perp @ a_perp), float(u_perp @ u_perp) - r * r
            )
            if tt < best[0]:
                s = float((centre0 + tt * a - p) @ e)
                if 0.0 <= s <= length:
                    c = centre0 + tt * a
                    best = (tt, (c - p - s * e) / r, -1)
            tt = _first_root(1.0, float(u @ a), float(u @ u) - r * r)
            if tt < best[0]:
                best = (tt, (centre0 + tt * a - p) / r, -1)
    return best[0], np.asarray(best[1], dtype=np.float64), best[2]


def _first_root(A: float, half_b: float, c: float) -> float:
    """Smaller root of ``A t^2 + 2 half_b t + c = 0`` (``inf`` when none, or A is 0)."""
    if A <= 1e-18:
        return math.inf
    disc = half_b * half_b - A * c
    if disc < 0.0:
        return math.inf
    return (-half_b - math.sqrt(disc)) / A


def _inside(q: FloatArray, v: FloatArray, n: FloatArray) -> bool:
    """True when ``q`` (in the triangle's plane) lies inside triangle ``v`` ``(3, 3)``."""
    return all(float(np.cross(v[(i + 1) % 3] - v[i], q - v[i]) @ n) >= -1e-12 for i in range(3))
