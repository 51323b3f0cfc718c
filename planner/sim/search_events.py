"""Bookkeeping of simulated searches: events, where a footprint landed, reachability hooks.

Used by :class:`planner.sim.probe.SimulatedProbe` to report, besides the measured point, what
happened in each search (the Monte Carlo failure report counts these), and to vet the path a
search really ran against a :class:`planner.cell.cell.Cell`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from calib.probing import SearchCommand
from planner.parts.stator import StatorGeometry

FloatArray = NDArray[np.float64]

#: A reachability hook: returns "" when the commanded search is feasible, else the reason.
ReachabilityHook = Callable[[SearchCommand], str]


def cell_search_hook(cell: Any, step_m: float = 0.002) -> ReachabilityHook:
    """A hook that vets each commanded search with ``cell.check_search`` (a
    :class:`planner.cell.cell.Cell`); place the cell's work object where the part really is, so a
    search that collides because the part moved is caught.

    The reason returned is ``"unreachable or colliding: <the cell's reason>"``.
    """

    def hook(command: SearchCommand) -> str:
        res = cell.check_search(command, step_m=step_m)
        return "" if res.feasible else f"unreachable or colliding: {res.reason}"

    return hook


@dataclass(frozen=True)
class ProbeEvent:
    """What happened in one simulated search (for the failure report).

    Attributes:
        point_id: id of the probe point.
        kind: ``"approach"`` or ``"edge"``.
        reason: empty on success, else why the search failed.
        landing: ``"over slot hole"``, ``"off face"`` or ``""``: where an approach really landed.
        travel_m: travel from the start to the event, m (``nan`` on failure).
    """

    point_id: str
    kind: str
    reason: str = ""
    landing: str = ""
    travel_m: float = float("nan")


def footprint_landing(
    geom: StatorGeometry, tcp_wobj_m: FloatArray, axis_wobj: FloatArray, radius_m: float
) -> str:
    """Classify where a sensor footprint lies on the true part (wobj of the true part).

    Returns:
        ``"over slot hole"`` when the footprint centre is over a hole of the side face,
        ``"off face"`` when the footprint hangs over an edge of the face it looks at, else ``""``.
    """
    n = -np.asarray(axis_wobj, float)
    i = int(np.argmax(np.abs(n)))
    x, y, z = (float(c) for c in tcp_wobj_m)
    lo = {0: -geom.depth_m, 1: -geom.length_m, 2: -geom.height_m}
    in_plane = [a for a in range(3) if a != i]
    coords = {0: x, 1: y, 2: z}
    if i == 0 and n[0] > 0 and bool(geom.hole_near(y, z)):
        return "over slot hole"
    for a in in_plane:
        if coords[a] + radius_m > 1e-9 or coords[a] - radius_m < lo[a] - 1e-9:
            return "off face"
    return ""
