"""The kinematic cell: the scene (:class:`planner.cell.scene.CellScene`) with its queries.

    with Cell(robot="builtin:irb4400", tool="builtin:cable_feeder") as cell:
        cell.set_work_object("part.stl", units="auto", T_world_wobj=T)
        cell.add_fixture("table", size_m=(1, 1, 0.05), T_world_fixture=T_table)
        results = cell.check_probes(points_wobj, normals_wobj, tcp="sensor")

The queries are functions of a scene in their own modules (:mod:`planner.cell.probe.feasibility`,
:mod:`planner.cell.probe.search_paths`, :mod:`planner.cell.probe.reachability`); the methods here
only forward to them, so the modules depend on the scene and never on this class.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from calib.probing import SearchCommand
from planner.cell.probe import (
    PathFeasibility,
    PosedSearch,
    ProbeFeasibility,
    ReachabilityMap,
    check_probes,
    check_search,
    check_searches,
    reachability_map,
)
from planner.cell.scene import CellScene


class Cell(CellScene):
    """A robot cell in its own PyBullet DIRECT client, with its feasibility queries.

    Takes the arguments of :class:`planner.cell.scene.CellScene`.
    """

    def __enter__(self) -> Cell:
        return self

    def check_probes(
        self, points_wobj: ArrayLike, normals_wobj: ArrayLike, **kw: Any
    ) -> list[ProbeFeasibility]:
        """Feasibility of probe poses; see :func:`planner.cell.probe.check_probes`."""
        return check_probes(self, points_wobj, normals_wobj, **kw)

    def check_search(self, command: SearchCommand, **kw: Any) -> PathFeasibility:
        """Feasibility of a search path; see :func:`planner.cell.probe.check_search`."""
        return check_search(self, command, **kw)

    def check_searches(
        self,
        commands: Sequence[SearchCommand],
        sensor_x: Sequence[ArrayLike],
        q_ref: Sequence[ArrayLike],
        branch: Sequence[int],
        **kw: Any,
    ) -> list[PathFeasibility]:
        """Feasibility of many search paths, each with its program's pose (sensor x axis,
        reference joints, IK branch; base frame, rad); see
        :func:`planner.cell.probe.check_searches`."""
        searches = [
            PosedSearch(c, np.asarray(x, dtype=float), np.asarray(q, dtype=float), int(b))
            for c, x, q, b in zip(commands, sensor_x, q_ref, branch, strict=True)
        ]
        return check_searches(self, searches, **kw)

    def reachability_map(
        self, n_samples: int, rng: np.random.Generator, **kw: Any
    ) -> ReachabilityMap:
        """Surface reachability map; see :func:`planner.cell.probe.reachability_map`."""
        return reachability_map(self, n_samples, rng, **kw)
