"""The simulated touch-trigger probe: where the stylus ball meets the true, misplaced part.

A :data:`calib.probing.Probe` for :class:`calib.models.touch.TouchProbe`. The robot moves the
TCP (the ball's pole) along the commanded approach, off by its repeatability, accuracy field
and TCP error (:func:`planner.sim.search_events.robot_offset`). Rays cast along the approach
from the ball's front half find the triangles the ball meets first; the contact is then solved
exactly for the sweeping ball against each of them (:func:`sweep_contact`: its face when the tangent
point lies inside it, else an edge or a corner, e.g. a hole's rim or the face's end). The
probe triggers after the pre-travel left over from axial qualification for that contact's
direction (lobing) plus the trigger's scatter, and the program compensates the ball radius
along the face normal of the estimate the search was commanded in (``calib.models.touch``);
that compensated point is returned.

Failures are reasons, never numbers: no contact within the search length, the ball already
inside the part at the start, an edge search (a touch probe cannot run one): ``search``
reasons, decided here; or an unreachable commanded path (reachability hook: the cell's kind and
pair). Every approach's landing is judged over the ball's silhouette against the planar faces
of the part, and a ball that meets an edge or another face first is counted as landed off its
face (``footprint`` reasons).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.models.touch import TouchProbe
from calib.probing import ProbeResult, SearchCommand
from planner.reasons import Reason
from planner.sim.raycast import MeshRayCaster
from planner.sim.search_events import LANDED_OFF_FACE
from planner.sim.sensor_base import SimulatedSensor, no_event_within

FloatArray = NDArray[np.float64]

#: A touch probe is asked for an edge search.
NO_EDGE_SEARCH = Reason("search", "a touch probe cannot run an edge search")
#: A touch probe is asked to approach along another direction than its stylus.
OFF_AXIS = Reason("search", "touch probe: only approaches along the stylus axis")
#: The ball starts inside the (misplaced) part.
BALL_INSIDE = Reason("search", "stylus ball inside the part at start")
#: The ball starts touching the part.
BALL_TOUCHING = Reason("search", "stylus ball touching the part at start")


@dataclass
class SimulatedTouchProbe(SimulatedSensor):
    """A touch-probe callback against the true part at ``T_base_wobj_true``.

    Args (besides :class:`~planner.sim.sensor_base.SimulatedSensor`'s):
        sensor: the touch probe.
        edge_inset_m, edge_tolerance_m: unused (the proximity sensor's edge searches);
            accepted so that every simulator is built alike (:mod:`planner.sim.sensors`).
    """

    sensor: TouchProbe = field(default_factory=TouchProbe)

    def _refusal(self, cmd: SearchCommand) -> Reason | None:
        return None if cmd.kind == "approach" else NO_EDGE_SEARCH

    def _search(
        self, cmd: SearchCommand, start: FloatArray, axis: FloatArray, tcp0: FloatArray
    ) -> ProbeResult:
        """Run one commanded approach against the true part."""
        direction = np.asarray(cmd.direction, float)
        if float(direction @ axis) < 1.0 - 1e-9:
            return self._fail(cmd, OFF_AXIS)
        r = self.sensor.radius_m
        R, t = self._T_wobj_base[:3, :3], self._T_wobj_base[:3, 3]
        centre0 = R @ (tcp0 - r * axis) + t  # part frame from here on
        a = R @ axis
        origins = centre0 + self.sensor.front_points_m(a)
        along = np.empty_like(origins)
        along[:] = a
        dist, tri = self.caster.first_hits_ids(origins, along)
        length = float(cmd.length_m)
        if np.any(dist <= 0.0):
            return self._fail(cmd, BALL_INSIDE)
        if not np.any(np.isfinite(dist)):
            return self._fail(cmd, no_event_within("contact", length))
        # the exact first contact of the sweeping ball with the triangles the rays met near
        # the first hit: a face (tangent point inside it), an edge or a corner
        near = np.unique(tri[np.isfinite(dist) & (dist <= float(dist.min()) + 0.25 * r)])
        travel, normal, on_face_of = sweep_contact(self.caster, centre0, a, r, near)
        if travel <= 0.0:
            return self._fail(cmd, BALL_TOUCHING)
        normal_base = R.T @ normal  # the lobes turn with the probe: its tool frame is in base
        travel += self.sensor.pretravel_error_m(normal_base, axis) + self.sensor.sample_trigger_m(
            self.rng
        )
        if travel > length:
            return self._fail(cmd, no_event_within("contact", length))
        refused = self._vet(cmd, travel)
        if refused is not None:
            return refused
        landing, frac = self._landing(cmd, tri)
        if self.faces is not None and landing is None:
            want = self.faces.intended.get(cmd.point_id, -1)
            face = self.faces.triangle_face[on_face_of] if on_face_of >= 0 else -1
            if want >= 0 and face != want:  # the ball met an edge or another face first
                landing = LANDED_OFF_FACE
        pole = start + travel * direction  # what the controller records (the TCP)
        n_est = -axis if cmd.stop_normal is None else np.asarray(cmd.stop_normal, float)
        point = pole - r * axis - r * n_est  # ball centre, then one radius along the normal
        return self._record(cmd, travel, point, (landing, frac))


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
    All triangles are solved in one compiled loop (:mod:`planner.sim.sweep_kernel`).
    """
    from planner.sim.sweep_kernel import EDGE, FACE, NONE, first_contact  # numba: when used

    tri = np.ascontiguousarray(triangles, dtype=np.int64)
    start = np.ascontiguousarray(centre0, dtype=np.float64)
    axis = np.ascontiguousarray(a, dtype=np.float64)
    normals, offsets, vertices = caster.triangle_arrays()
    kind, travel, k, i, s = first_contact(normals, offsets, vertices, tri, start, axis, float(r))
    if kind == NONE:
        return math.inf, -axis, -1
    if kind == FACE:
        return travel, caster.triangle_normal(int(tri[k])), int(tri[k])
    v = caster.triangle_vertices(int(tri[k]))
    centre = start + travel * axis
    if kind == EDGE:
        e = v[(i + 1) % 3] - v[i]
        foot = v[i] + s * (e / np.linalg.norm(e))
        return travel, (centre - foot) / r, -1
    return travel, (centre - v[i]) / r, -1
