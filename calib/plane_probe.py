"""The one ideal probe: every search answered where it meets the plane of the face it looks for.

No mesh and no noise. Each search ends where its commanded line meets the plane of the face that
stops it (the command's ``nominal_m`` and ``stop_normal``, carried from the estimate it was
commanded in onto the part where it truly lies), an edge search ``edge_offset_m`` further (where
the sensor reports the edge). A search commanded off its face (an edge search started outside
the face) therefore switches off the face just as the robot's does, and only the procedure's own
corrections bring the result back.

Its users: the check's dry run of the procedure on the nominal part
(:func:`planner.check.job.layout_problem`, ``within_length=True``: a search finding nothing
within its length fails as on the robot), the linearisation of a procedure's run
(:func:`calib.procedures.linearize.linearize`, with each search's event moved by its ``eps``),
the prediction's misplacement columns, the landing check and the adaptive program's own dry run
(in ``planner``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.probing import ProbeResult, SearchCommand

FloatArray = NDArray[np.float64]
#: A search whose direction meets its face's normal at less than this cosine runs parallel to it.
PARALLEL_COS = 1e-9


@dataclass
class PlaneProbe:
    """An ideal probe on the nominal faces of the part posed at ``T_base_wobj_true``.

    The ``j``-th search's event moves by ``eps[j]`` along its direction. An edge search's event
    also moves with its track's standoff where it crosses the edge (``edge_axis_gain`` metres
    per metre the track runs closer to the face it slides over than commanded): a track
    commanded in an estimate whose face plane is off, or tilted, runs closer or farther there.
    A command without ``stop_normal`` is stopped by a face facing the search (``-direction``).

    Args:
        T_base_wobj_true: ``(4, 4)`` where the part is, base frame, metres.
        edge_offset_m: how far past a face's end an edge search reports it, metres.
        edge_axis_gain: the sensor's axis gain of an edge search
            (:attr:`calib.models.sensor.SearchNoise.axis_gain`).
        eps: event travel added to the ``j``-th search, metres.
        commands: every search received, in order (filled as the probe is called).
        within_length: ``True``: a search whose event lies outside ``[0, length_m]`` of its
            start fails, as on the robot; ``False``: the travel is returned wherever the plane
            lies (a linearisation, and the landing check that judges the travel itself).
    """

    T_base_wobj_true: FloatArray
    edge_offset_m: float = 0.0
    edge_axis_gain: float = 0.0
    eps: Mapping[int, float] = field(default_factory=dict)
    commands: list[SearchCommand] = field(default_factory=list)
    within_length: bool = False

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        """The recorded sensor-TCP point of one search (base frame, metres) and its travel."""
        j = len(self.commands)
        self.commands.append(cmd)
        d = np.asarray(cmd.direction, dtype=np.float64)
        stop = -d if cmd.stop_normal is None else np.asarray(cmd.stop_normal, dtype=np.float64)
        T_est = cmd.T_base_wobj_estimate  # the estimate onto the true part: R_move, t_move
        R_move = self.T_base_wobj_true[:3, :3] @ T_est[:3, :3].T
        t_move = self.T_base_wobj_true[:3, 3] - R_move @ T_est[:3, 3]
        p = R_move @ np.asarray(cmd.nominal_m, dtype=np.float64) + t_move
        m = R_move @ stop
        denom = float(d @ m)
        if abs(denom) < PARALLEL_COS:
            return ProbeResult(None, "search runs parallel to the face that should stop it")
        start = np.asarray(cmd.start_m, dtype=np.float64)
        t = float((p - start) @ m) / denom
        if cmd.kind == "edge":  # the track's standoff where it crosses the edge
            face_n = -(R_move @ np.asarray(cmd.sensor_axis, dtype=np.float64))
            closer = -float((start + t * d - p) @ face_n)
            t += self.edge_offset_m + self.edge_axis_gain * closer
        t += float(self.eps.get(j, 0.0))
        if self.within_length and not 0.0 <= t <= cmd.length_m:
            return ProbeResult(None, f"no event within {cmd.length_m * 1e3:.1f} mm")
        return ProbeResult(start + t * d, travel_m=t)
