"""Simulated searches: a :data:`calib.probing.Probe` that runs against the true, misplaced part.

The robot moves the sensor TCP along the commanded straight path; where it really is differs by
its repeatability (a fresh offset per search) and, optionally, a smooth absolute-accuracy field.
The sensor model (:mod:`calib.models.proximity`) decides where it switches, from a ray bundle cast
against the true part. The probe returns what the robot controller records: the *commanded*
TCP position at the switching event, in the base frame.

- Approach search (motion along the sensor axis): every ray shortens by the travel, so the
  switching travel is solved in closed form from one ray cast (no stepping).
- Edge search ("move until the sensor stops detecting"): a coarse scan with few rays finds the
  step where the signal drops below the switch-off level, then the full bundle brackets it and
  the switch is resolved between rays (:mod:`planner.sim.subray`: each ray's switch bisected,
  its share handed over across its cell), re-casting only the rays whose surface changes.

Failures are returned as :class:`~calib.probing.ProbeResult` with a reason, never as a number:
no detection within the search length, already detecting at the start, not detecting at the
start of an edge search, the face touching the part (``search`` reasons, decided here and
recorded on the search's event), or an unreachable commanded path (when a reachability hook is
given: the cell's kind and pair). Every approach's landing is judged over the whole sensor face: the
triangles the ray bundle hits are looked up in the part's planar faces
(:class:`~planner.sim.search_events.FaceLookup`), and a face partly over a hole or an edge is
recorded with the fraction of its area that is off.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.models.proximity import ProximitySensor
from calib.probing import ProbeResult, SearchCommand
from planner.reasons import Reason
from planner.sim.search_events import (
    ProbeEvent,
    ReachabilityHook,
    cell_search_hook,
    robot_offset,
)
from planner.sim.sensor_base import SimulatedSensor, no_event_within
from planner.sim.subray import CellSignal, cell_width_m, first_switch

__all__ = ["ProbeEvent", "ReachabilityHook", "SimulatedProbe", "cell_search_hook", "robot_offset"]

FloatArray = NDArray[np.float64]

#: The sensor's face starts inside the (misplaced) part.
FACE_INSIDE = Reason("search", "sensor face inside the part at start")
#: An approach starts where the sensor already switches.
ALREADY_DETECTING = Reason("search", "sensor already detecting at start")
#: An edge search starts where the sensor does not detect the face it should slide over.
NOT_DETECTING = Reason("search", "sensor not detecting at start of edge search")
#: An approach's face meets the part before the sensor switches.
TOUCHED = Reason("search", "sensor face touched the part before switching")
#: A scanning search's face runs into the part before its event.
COLLIDED = Reason("search", "sensor face collided with the part during the search")


@dataclass
class SimulatedProbe(SimulatedSensor):
    """A proximity-sensor probe callback against the true part at ``T_base_wobj_true``.

    Args (besides :class:`~planner.sim.sensor_base.SimulatedSensor`'s):
        sensor: the proximity-sensor model.
        edge_inset_m: an edge search runs its track this far inside the commanded path along
            the sensor axis (so the sensor detects the face it slides over); the reported point
            stays on the commanded path, i.e. on the face (the contract of the A-H procedure).
        edge_tolerance_m: bisection tolerance of the edge event, m.
        scan_step_m: step of the coarse edge scan, m.
        between_rays: resolve a scanning search's switch between the rays of the bundle
            (:mod:`planner.sim.subray`); False: plain rays, each switching at once (for
            comparison: ``bench/bench_edge_events.py``).
    """

    sensor: ProximitySensor = field(default_factory=ProximitySensor)
    edge_inset_m: float = 0.003
    edge_tolerance_m: float = 2e-5
    scan_step_m: float = 0.0025
    between_rays: bool = True

    # -- helpers ---------------------------------------------------------------------------
    def _distances(self, tcp_base: FloatArray, axis: FloatArray, offsets: FloatArray) -> FloatArray:
        """Face-to-metal distances ``(K, n)`` for TCP positions ``(K, 3)`` (base frame)."""
        centres = tcp_base - self.sensor.sensing_distance_m * axis
        origins = (centres[:, None, :] + offsets).reshape(-1, 3)
        d_part = np.broadcast_to(self._T_wobj_base[:3, :3] @ axis, origins.shape)
        return self.caster.first_hits(self._to_part(origins), d_part).reshape(len(tcp_base), -1)

    def _signal_of(self, dist: FloatArray) -> FloatArray:
        """Signal ``(K,)`` from distances ``(K, n)``; ``-1`` where the face is inside the part."""
        return np.where(np.any(dist <= 0.0, axis=1), -1.0, self.sensor.signal(dist))

    def _succeed(
        self,
        cmd: SearchCommand,
        travel: float,
        triangles: NDArray[np.int64] | None = None,
        vetted: tuple[Reason | None] | None = None,
    ) -> ProbeResult:
        """The search's result after ``travel`` m, unless the hook refuses its path (vetted
        here, or ahead: ``vetted`` holds that verdict)."""
        if vetted is None:  # the path the robot really ran: start to the event
            refused = self._vet(cmd, travel)
        else:
            refused = None if vetted[0] is None else self._fail(cmd, vetted[0])
        if refused is not None:
            return refused
        point = np.asarray(cmd.start_m, float) + travel * np.asarray(cmd.direction, float)
        return self._record(cmd, travel, point, self._landing(cmd, triangles))

    # -- the probe -------------------------------------------------------------------------
    def _search(
        self, cmd: SearchCommand, start: FloatArray, axis: FloatArray, tcp0: FloatArray
    ) -> ProbeResult:
        """Run one commanded search against the true part (an approach along the sensor axis
        in closed form, any other by scanning)."""
        tcp0 = tcp0 + (self.edge_inset_m * axis if cmd.kind == "edge" else 0.0)
        direction = np.asarray(cmd.direction, float)
        length = float(cmd.length_m)
        if cmd.kind == "approach" and float(direction @ axis) > 1.0 - 1e-12:
            return self._approach_along_axis(cmd, tcp0, axis, length)
        return self._scan(cmd, tcp0, axis, direction, length, want_on=cmd.kind == "approach")

    def run_in_turn(self, commands: Sequence[SearchCommand]) -> list[ProbeResult]:
        """Run ``commands`` one after the other, up to and including the first that fails.

        The same results, events and noise as calling the probe on each in turn and stopping
        at a failure (the x-offset run does): approaches along their sensor axes are cast in
        one ray bundle for all of them, the rest one by one. The noise of a search is drawn
        in the same order (its robot offset, then its switching jitter); after a failure the
        generator may have drawn the next searches' noise, which nothing uses: a run that
        fails ends its trial.
        """
        out: list[ProbeResult] = []
        pending: list[tuple[SearchCommand, FloatArray, FloatArray, float]] = []
        for cmd in commands:
            axis = np.asarray(cmd.sensor_axis, float)
            along = cmd.kind == "approach" and float(np.asarray(cmd.direction) @ axis) > 1 - 1e-12
            if not along:
                out += self._cast_in_turn(pending)
                pending = []
                if out and not out[-1].ok:
                    return out
                out.append(self(cmd))
                if not out[-1].ok:
                    return out
                continue
            start = np.asarray(cmd.start_m, float)
            tcp0 = start + self._offset(start, axis)
            pending.append((cmd, tcp0, axis, self.sensor.sample_jitter_m(self.rng)))
        return out + self._cast_in_turn(pending)

    def _cast_in_turn(
        self, searches: Sequence[tuple[SearchCommand, FloatArray, FloatArray, float]]
    ) -> list[ProbeResult]:
        """Approaches along their axes ``(command, tcp0, axis, jitter)``: one ray cast, then
        each judged in turn as :meth:`_judge_approach` does, up to the first failure (their
        signals and nearest metal computed for all at once, row by row as one search's)."""
        if not searches:
            return []
        R = self._T_wobj_base[:3, :3]
        offsets: dict[bytes, FloatArray] = {}  # the face's ray offsets, once per sensor axis
        centres, rows = [], []
        for _, tcp0, axis, _ in searches:
            key = axis.tobytes()
            if key not in offsets:
                offsets[key] = self.sensor.face_offsets_m(axis)
            centres.append(tcp0 - self.sensor.sensing_distance_m * axis)
            rows.append(offsets[key])
        origins = self._to_part((np.array(centres)[:, None, :] + np.array(rows)).reshape(-1, 3))
        n_rays = len(origins) // len(searches)
        axes = np.repeat(np.array([R @ axis for _, _, axis, _ in searches]), n_rays, axis=0)
        dist_all, tri_all = self.caster.first_hits_ids(origins, axes)
        dist = dist_all.reshape(len(searches), n_rays)
        inside = np.any(dist <= 0.0, axis=1)
        signal = self.sensor.signal(dist)
        nearest = dist.min(axis=1)
        travels = [
            math.nan if inside[k] else self.sensor.travel_to_switch_m(float(signal[k]), jitter)
            for k, (_, _, _, jitter) in enumerate(searches)
        ]
        # the paths of the searches the sensor ends, up to the first it fails, vetted at once
        ran = []
        for k, (cmd, *_) in enumerate(searches):
            if inside[k] or _sensor_refusal(cmd, travels[k], float(nearest[k])) is not None:
                break
            ran.append((cmd, travels[k]))
        ahead = self._vet_ahead(ran)
        out: list[ProbeResult] = []
        for k, (cmd, *_) in enumerate(searches):
            tri = tri_all[k * n_rays : (k + 1) * n_rays]
            if inside[k]:
                res = self._fail(cmd, FACE_INSIDE)
            else:
                vetted = (ahead[k],) if k < len(ahead) else None
                res = self._judged(cmd, travels[k], float(nearest[k]), tri, vetted)
            out.append(res)
            if not res.ok:
                break
        return out

    def _approach_along_axis(
        self, cmd: SearchCommand, tcp0: FloatArray, axis: FloatArray, length: float
    ) -> ProbeResult:
        origins = self._to_part(self.sensor.ray_origins(tcp0, axis))
        axis_part = np.broadcast_to(self._T_wobj_base[:3, :3] @ axis, origins.shape)
        dist, tri = self.caster.first_hits_ids(origins, axis_part)
        if np.any(dist <= 0.0):
            return self._fail(cmd, FACE_INSIDE)
        return self._judge_approach(cmd, dist, tri, self.sensor.sample_jitter_m(self.rng))

    def _judge_approach(
        self, cmd: SearchCommand, dist: FloatArray, tri: NDArray[np.int64], jitter: float
    ) -> ProbeResult:
        """Where an approach along the sensor axis switches, from its rays' distances ``dist``
        and triangles ``tri`` at the start and the switching jitter (m)."""
        if np.any(dist <= 0.0):
            return self._fail(cmd, FACE_INSIDE)
        travel = self.sensor.switch_travel_m(dist, jitter)
        return self._judged(cmd, travel, float(dist.min()), tri)

    def _judged(
        self,
        cmd: SearchCommand,
        travel: float,
        nearest: float,
        tri: NDArray[np.int64],
        vetted: tuple[Reason | None] | None = None,
    ) -> ProbeResult:
        """An approach along the sensor axis that switches after ``travel`` (m), its nearest
        ray meeting metal ``nearest`` away (m), its rays' triangles ``tri``; ``vetted``: the
        hook's verdict of its path when it was vetted ahead (:meth:`_succeed`)."""
        why = _sensor_refusal(cmd, travel, nearest)
        if why is not None:
            return self._fail(cmd, why)
        # along the axis the rays are the footprint's
        return self._succeed(cmd, travel, tri, vetted)

    def _scan(
        self,
        cmd: SearchCommand,
        tcp0: FloatArray,
        axis: FloatArray,
        direction: FloatArray,
        length: float,
        want_on: bool,
    ) -> ProbeResult:
        """Stepping search for the first travel where the sensor turns on (or off)."""
        on = self.sensor.on_level(self.sensor.sample_jitter_m(self.rng))
        off = self.sensor.off_level(self.sensor.sample_jitter_m(self.rng))

        def event(sig: FloatArray) -> NDArray[np.bool_]:
            return (sig >= on) if want_on else (sig < off)

        fine_off = self.sensor.face_offsets_m(axis)
        coarse_off = self.sensor.face_offsets_m(axis, coarse=True)
        n_fine = len(fine_off)
        n_steps = max(1, math.ceil(length / self.scan_step_m))
        s_grid = np.linspace(0.0, length, n_steps + 1)
        tcps = tcp0 + s_grid[:, None] * direction
        # one cast: the full bundle at the start and the coarse bundle along the path
        centres = tcps - self.sensor.sensing_distance_m * axis
        origins = np.concatenate(
            [
                (centres[:1, None, :] + fine_off)[0],
                (centres[:, None, :] + coarse_off).reshape(-1, 3),
            ]
        )
        d_part = np.broadcast_to(self._T_wobj_base[:3, :3] @ axis, origins.shape)
        dist = self.caster.first_hits(self._to_part(origins), d_part)
        s0 = float(self._signal_of(dist[None, :n_fine])[0])
        coarse = self._signal_of(dist[n_fine:].reshape(len(s_grid), -1))
        if s0 < 0:
            return self._fail(cmd, FACE_INSIDE)
        if want_on and s0 >= on:
            return self._fail(cmd, ALREADY_DETECTING)
        if not want_on and s0 < on:
            return self._fail(cmd, NOT_DETECTING)
        if np.any(coarse < 0):
            first_hit = int(np.argmax(coarse < 0))
            if not np.any(event(coarse[1:first_hit])):
                return self._fail(cmd, COLLIDED)
        hits = np.flatnonzero(event(coarse[1:]) & (coarse[1:] >= 0)) + 1
        k = int(hits[0]) if len(hits) else n_steps

        def full(travels: list[float]) -> FloatArray:
            return self._distances(tcp0 + np.asarray(travels)[:, None] * direction, axis, fine_off)

        # the bracket [s_grid[k-1], s_grid[k]] with the full bundle (step back or on if needed)
        d_lo, d_hi = full([float(s_grid[k - 1]), float(s_grid[k])])
        while k > 1 and event(self._signal_of(d_lo[None]))[0]:
            k -= 1
            d_hi, d_lo = d_lo, full([float(s_grid[k - 1])])[0]
        while k <= n_steps and not event(self._signal_of(d_hi[None]))[0]:
            k += 1
            if k > n_steps:
                what = "detection" if want_on else "edge (sensor still detecting)"
                return self._fail(cmd, no_event_within(what, length))
            d_lo, d_hi = d_hi, full([float(s_grid[k])])[0]
        # the switch between rays (planner.sim.subray): in the bracket widened by a ray cell on
        # each side, the rays whose surface changes count by their share across their cell
        w = cell_width_m(self.sensor.radius_m, n_fine) if self.between_rays else 0.0
        lo0, hi0 = float(s_grid[k - 1]), float(s_grid[k])
        lo_e, hi_e = max(0.0, lo0 - w), min(length, hi0 + w)
        if lo_e < lo0 or hi_e > hi0:
            d_lo, d_hi = full([lo_e, hi_e])

        def cast(travels: FloatArray, rays: NDArray[np.int64]) -> FloatArray:
            tcps = tcp0 + travels[:, None] * direction - self.sensor.sensing_distance_m * axis
            origins = (tcps[:, None, :] + fine_off[rays]).reshape(-1, 3)
            d_part = np.broadcast_to(self._T_wobj_base[:3, :3] @ axis, origins.shape)
            d = self.caster.first_hits(self._to_part(origins), d_part)
            return d.reshape(len(travels), len(rays))

        def terms(d: FloatArray) -> FloatArray:
            return self.sensor.signal(d[..., None])

        def margin(sig: float) -> float:  # log distance from the switching level, < 0 = event
            log_s = math.log(max(sig, 1e-300))
            return math.log(on) - log_s if want_on else log_s - math.log(off)

        signal = CellSignal(cast, terms, lo_e, hi_e, d_lo, d_hi, w)
        knots = np.unique(np.array([lo_e, lo0, hi0, hi_e]))
        found = first_switch(signal, knots, event, margin, self.edge_tolerance_m)
        if found is None:  # the cells' average never crosses in the bracket: the plain rays'
            hi, s_hi = hi0, float(self._signal_of(full([hi0]))[0])
        else:
            hi, s_hi = found
        if s_hi < 0:
            return self._fail(cmd, COLLIDED)
        triangles = None
        if want_on and self.faces is not None:  # an approach across the axis: its footprint
            at = (tcp0 + hi * direction)[None]
            origins = self._to_part(
                (at - self.sensor.sensing_distance_m * axis)[:, None, :] + fine_off
            )
            d_part = np.broadcast_to(self._T_wobj_base[:3, :3] @ axis, origins[0].shape)
            triangles = self.caster.first_hits_ids(origins[0], d_part)[1]
        return self._succeed(cmd, hi, triangles)


def _sensor_refusal(cmd: SearchCommand, travel: float, nearest: float) -> Reason | None:
    """Why an approach along the sensor axis that would switch after ``travel`` (m), its
    nearest ray meeting metal ``nearest`` away (m), fails in the sensor; ``None`` when the
    sensor ends it."""
    length = float(cmd.length_m)
    if travel <= 0.0:
        return ALREADY_DETECTING
    if not math.isfinite(travel) or travel > length:
        return no_event_within("detection", length)
    if travel >= nearest:
        return TOUCHED
    return None
