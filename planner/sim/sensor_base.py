"""What every simulated sensor shares: :class:`SimulatedSensor`, the abstract base.

A simulated sensor is a :data:`calib.probing.Probe` that runs one commanded search (base frame)
against the true, misplaced part and returns what the robot controller records. Whatever the
sensor, a search goes the same way, and that way is written here once:

1. a search the sensor cannot run is refused before any noise is drawn (:meth:`_refusal`:
   the touch probe and an edge search);
2. the robot's offset is drawn: where the TCP really runs minus where it is commanded
   (repeatability per search, the accuracy field at the start, this calibration's TCP error:
   :func:`planner.sim.search_events.robot_offset`);
3. the sensor's own model finds the event (:meth:`_search`, the subclass: a ray bundle and a
   switching level, or a ball's first contact) against the mesh, in the part's frame
   (:meth:`_to_part`: rays are moved into the mesh frame, the mesh never moves);
4. a success is vetted by the reachability hook on the path really run (the command cut at
   the event; its reason fails the search), its landing judged against the planar faces
   (:meth:`_landing`), and recorded (:meth:`_record`); a failure is recorded with its reason
   (:meth:`_fail`). Every search, success or failure, leaves one :class:`ProbeEvent` in
   :attr:`events`, in the order run.

A failure is a :class:`planner.reasons.Reason` given where it is decided: the sensor's own
(nothing within the search's length, :func:`no_event_within`; a start inside the part or
already detecting; a refused search) are ``search`` reasons; the reachability hook's keep the
cell's kind and pair. The :class:`~calib.probing.ProbeResult` the procedure reads carries its
words (``reason``); the event carries the reason itself (``cause``).

:meth:`run_in_turn` runs a list of searches one after the other up to and including the first
that fails (the x-offset run); a subclass may run them as one batch (one ray cast for all:
:class:`planner.sim.proximity.SimulatedProbe`) as long as the results, events and noise are
those of calling it on each in turn.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.frames import check_transform, invert_transform
from calib.models.robot_error import AccuracyField, RobotErrorModel
from calib.probing import ProbeResult, SearchCommand
from planner.reasons import Reason
from planner.sim.raycast import MeshRayCaster
from planner.sim.search_events import FaceLookup, ProbeEvent, ReachabilityHook, robot_offset

FloatArray = NDArray[np.float64]


def no_event_within(event: str, length_m: float) -> Reason:
    """The ``search`` reason of a search that ran its whole length, ``length_m`` (m), without
    its ``event`` (``"detection"``, ``"contact"``): ``"no detection within 50 mm"``."""
    return Reason("search", f"no {event} within {length_m * 1e3:.0f} mm")


@dataclass
class SimulatedSensor(ABC):
    """A simulated search against the true part at ``T_base_wobj_true`` (module docstring).

    Subclasses set the sensor model's type and default, and implement :meth:`_search`.

    Args:
        caster: ray caster of the part mesh in its own (wobj) frame.
        T_base_wobj_true: ``(4, 4)`` where the part really is, base frame.
        rng: random generator for robot and sensor noise.
        sensor: the sensor model (:mod:`calib.models`).
        robot_error: robot repeatability (per search), accuracy and TCP model.
        accuracy_field: this robot's accuracy field (``robot_error.sample_field``), or None.
        faces: the true part's planar faces and the face each search should land on, to
            classify landings over the whole footprint; ``None``: not classified.
        tcp_error_m: ``(3,)`` this calibration's TCP error, sensor tool frame, m, or None.
        reachability: optional hook that vets the path each successful search really ran (the
            command cut at the event); its reason (kind and pair kept) fails the search.
        edge_inset_m: an edge search runs its track this far inside the commanded path along
            the sensor axis, m (sensors that run edge searches).
        edge_tolerance_m: tolerance of an edge event, m (sensors that run edge searches).
        events: what happened in each search run so far, in order (filled by the probe).
    """

    caster: MeshRayCaster
    T_base_wobj_true: ArrayLike
    rng: np.random.Generator
    sensor: Any
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

    # -- the search, the same for every sensor ----------------------------------------------
    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        """Run one commanded search against the true part."""
        why = self._refusal(cmd)
        if why is not None:
            return self._fail(cmd, why)
        start = np.asarray(cmd.start_m, float)
        axis = np.asarray(cmd.sensor_axis, float)
        return self._search(cmd, start, axis, start + self._offset(start, axis))

    def run_in_turn(self, commands: Sequence[SearchCommand]) -> list[ProbeResult]:
        """Run ``commands`` one after the other, up to and including the first that fails."""
        out: list[ProbeResult] = []
        for cmd in commands:
            out.append(self(cmd))
            if not out[-1].ok:
                break
        return out

    def _refusal(self, cmd: SearchCommand) -> Reason | None:
        """Why this sensor cannot run ``cmd`` at all (``None``: it can); checked before any
        noise is drawn."""
        return None

    @abstractmethod
    def _search(
        self, cmd: SearchCommand, start: FloatArray, axis: FloatArray, tcp0: FloatArray
    ) -> ProbeResult:
        """Run ``cmd`` from where the TCP really starts, ``tcp0`` ``(3,)`` (the commanded
        ``start`` plus the robot's offset), sensor ``axis`` ``(3,)``, all base frame, m; end
        with :meth:`_fail` or :meth:`_vet` and :meth:`_record`."""

    # -- shared helpers ------------------------------------------------------------------------
    def _offset(self, start: FloatArray, axis: FloatArray) -> FloatArray:
        """``(3,)`` the robot's offset for a search starting at ``start`` (base frame, m)."""
        return robot_offset(
            start, axis, self.rng, self.robot_error, self.accuracy_field, self.tcp_error_m
        )

    def _to_part(self, p_base: FloatArray) -> FloatArray:
        """Points ``(..., 3)`` from the base frame into the true part's (mesh) frame."""
        T = self._T_wobj_base
        return p_base @ T[:3, :3].T + T[:3, 3]

    def _fail(self, cmd: SearchCommand, reason: Reason) -> ProbeResult:
        """A failed search: its event with ``reason`` (its kind and pair), and no point, with
        the reason's words for the procedure."""
        self.events.append(ProbeEvent(cmd.point_id, cmd.kind, cause=reason))
        return ProbeResult(point_m=None, reason=str(reason))

    def _vet(self, cmd: SearchCommand, travel: float) -> ProbeResult | None:
        """The failure of a search the reachability hook refuses (the path from the start
        to the event, ``travel`` m), or ``None`` when it passes or there is no hook."""
        if self.reachability is None:
            return None
        why = self.reachability(replace(cmd, length_m=max(travel, 1e-6)))
        return None if why is None else self._fail(cmd, why)

    def _vet_ahead(self, runs: Sequence[tuple[SearchCommand, float]]) -> list[Reason | None]:
        """The hook's verdicts of searches ``(command, travel)`` that run in turn, asked before
        they run, without recording any event (``[]`` when there is no hook).

        A hook with a ``many`` method is asked about all of them at once (the cell checks
        their paths together); another is asked one by one up to its first refusal, the paths
        the robot runs. The verdicts end early where a hook raises: the search's own
        :meth:`_vet` asks it again when the search runs, so it raises there, as without this.
        The caller gives each search its verdict (:meth:`SimulatedProbe._succeed`'s
        ``vetted``) and asks :meth:`_vet` for the searches past the list's end.
        """
        if self.reachability is None or not runs:
            return []
        ran = [replace(cmd, length_m=max(travel, 1e-6)) for cmd, travel in runs]
        many = getattr(self.reachability, "many", None)
        if many is not None:
            try:
                return list(many(ran))
            except Exception:  # asked again, and raised, where the search runs
                return []
        out: list[Reason | None] = []
        for cmd in ran:
            try:
                why = self.reachability(cmd)
            except Exception:  # as above
                break
            out.append(why)
            if why is not None:
                break
        return out

    def _landing(
        self, cmd: SearchCommand, triangles: NDArray[np.int64] | None
    ) -> tuple[Reason | None, float]:
        """``(landing, off_fraction)`` of a footprint whose samples hit ``triangles``
        (:meth:`FaceLookup.landing`); ``(None, 0.0)`` when landings are not classified."""
        if self.faces is None or triangles is None:
            return None, 0.0
        return self.faces.landing(cmd.point_id, triangles)

    def _record(
        self,
        cmd: SearchCommand,
        travel: float,
        point: FloatArray,
        landing: tuple[Reason | None, float] = (None, 0.0),
    ) -> ProbeResult:
        """A successful search: its event (with where it landed, a ``footprint`` reason, and
        the fraction off its face) and what the controller records, ``point`` ``(3,)`` (base
        frame, m) after ``travel`` m."""
        self.events.append(
            ProbeEvent(
                cmd.point_id, cmd.kind, landing=landing[0], off_fraction=landing[1], travel_m=travel
            )
        )
        return ProbeResult(point_m=point, travel_m=travel)
