"""An exact sensor on the nominal part: the probe of the procedure's dry run.

:func:`planner.check.job.layout_problem` runs the plan's procedure against this probe: each search
is answered where its line meets the true plane it looks for, the face of an approach search or
the face an edge search runs off (the command's ``nominal_m`` and ``stop_normal``, moved from
the estimate it was commanded in onto the part where it truly lies). A search commanded off the
face (``edge_start_from_measured`` with an offset) therefore switches off the face just as the
robot's does, and only the procedure's own corrections bring the result back. No mesh, no
noise: a layout whose dry run does not give back the nominal frame breaks the procedure's
assumptions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from calib.probing import Probe, ProbeResult, SearchCommand

FloatArray = NDArray[np.float64]


def nominal_part_probe(T_base_wobj: FloatArray, edge_offset_m: float = 0.0) -> Probe:
    """A probe answering searches on the part lying at ``T_base_wobj`` (base frame, m).

    Args:
        T_base_wobj: ``(4, 4)`` where the part truly is (the nominal frame for a dry run).
        edge_offset_m: how far past the edge, along the search, the sensor reports an edge, m.
    """
    T_true = np.asarray(T_base_wobj, dtype=np.float64)

    def probe(command: SearchCommand) -> ProbeResult:
        if command.stop_normal is None:
            return ProbeResult(None, "the search does not say which face stops it")
        # the estimate's nominal plane, carried onto the true part
        M = T_true @ invert_transform(np.asarray(command.T_base_wobj_estimate, float))
        at = M[:3, :3] @ np.asarray(command.nominal_m, float) + M[:3, 3]
        m = M[:3, :3] @ np.asarray(command.stop_normal, float)
        d = np.asarray(command.direction, float)
        along = float(d @ m)
        if abs(along) < 1e-12:
            return ProbeResult(None, "the search runs parallel to the face it looks for")
        t = float((at - command.start_m) @ m) / along
        if command.kind == "edge":
            t += edge_offset_m
        if not 0.0 <= t <= command.length_m:
            return ProbeResult(None, f"no event within {command.length_m * 1e3:.1f} mm")
        return ProbeResult(command.start_m + t * d, travel_m=t)

    return probe
