"""A probe candidate's open clearance parts with Bullet, cheapest first.

:class:`OpenParts` is the exact step of :mod:`planner.cell.probe.probe_choice`: for one candidate,
the parts the broad phase left open go to Bullet (:class:`planner.cell.probe.probe_clearance.
ProbeClearance`) one at a time, cached ones first (they cost nothing), then the self part,
then against boxes and cylinders, then against meshes by link size, stopping as soon as the
candidate's slack is shown below a level. Deep work-object parts can first be asked with a
capped query (:meth:`~planner.cell.probe.probe_clearance.ProbeClearance.evaluate_capped`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from planner.cell.probe.probe_clearance import ProbeClearance
from planner.cell.probe.probe_rule import CLEARANCE_TIE_M
from planner.cell.scene import Clearance, QueryPart

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


class OpenParts:
    """Evaluates the open parts of candidates with Bullet.

    Args:
        stages: the exact part results (and their caches) of the current point.
        parts: the environment parts in the broad phase's order (``part_index`` of its map).
        cost: per part, 0 against a box, cylinder or sphere (cheap in Bullet), 1 against a mesh.
        size: per part, the radius of its link's bounding sphere, m (small links go first).
    """

    def __init__(
        self, stages: ProbeClearance, parts: list[QueryPart], cost: list[int], size: list[float]
    ) -> None:
        self._stages = stages
        self._parts = parts
        self._cost = cost
        self._size = size

    def evaluate(
        self,
        rotation: int,
        q: FloatArray,
        clear: BoolArray,
        pairs_clear: BoolArray,
        results: dict[int, Clearance | None],
        stop_below: float = -math.inf,
        max_cost: int = 1,
        max_parts: int = -1,
        certify: bool = False,
        tried: dict[int, float] | None = None,
    ) -> tuple[Clearance, bool]:
        """The candidate's open parts with Bullet, cheapest first (cached ones before all).

        Stops once the slack is shown below ``stop_below``, before a part costing more than
        ``max_cost``, or after ``max_parts`` parts not cached (-1: no limit). With
        ``certify``, the work-object parts not cached are first asked with a query capped at
        the tie above ``stop_below`` (:meth:`ProbeClearance.evaluate_capped`, a fraction of a
        full query when the collision is deep), smallest links first: it gives the part's
        exact result when it lies below the cap (one below ``stop_below`` stops the
        candidate). ``tried`` keeps, per part, the deepest cap a query failed to reach (not
        asked again). ``results`` collects the parts evaluated (plan index -> result, kept between
        calls).

        Returns:
            The merge of the parts known so far (the exact clearance when complete, else an
            upper bound of the slack) and whether every open part is known.
        """
        st = self._stages
        running = min((r.slack_m for r in results.values() if r is not None), default=math.inf)
        todo: list[tuple[int, int, float, int]] = []  # (not cached, cost, size, k)
        for k in range(len(self._parts)):
            part = self._parts[k]
            if not clear[k] and part.index not in results:
                cached = st.known(rotation, q, part)
                todo.append((int(not cached), self._cost[k], self._size[k], k))
        todo.sort()
        self_open = not pairs_clear.all() and st.self_part.index not in results
        fresh = 0
        if running >= stop_below and self_open and max_parts != 0:
            res = st.evaluate(rotation, q, st.self_part, ~pairs_clear)
            results[st.self_part.index] = res
            self_open = False
            fresh += 1
            if res is not None:
                running = min(running, res.slack_m)
        complete = not self_open
        for new, _, _, k in todo:  # cached parts first: they cost nothing
            if new:
                break
            part = self._parts[k]
            res = st.evaluate(rotation, q, part)
            results[part.index] = res
            if res is not None:
                running = min(running, res.slack_m)
        if certify and running >= stop_below and tried is not None:
            # capped queries first, smallest links first: each looks only as deep as can still
            # matter (the tie above stop_below) and gives the part's exact result, or shows
            # that it lies above that; one below stop_below shows the candidate below
            cap = stop_below + 2 * CLEARANCE_TIE_M
            for new, cost, _, k in todo:
                part = self._parts[k]
                if not new or cost < 1 or tried.get(k, -math.inf) >= cap:
                    continue
                res = st.evaluate_capped(rotation, q, part, cap)
                if res is None:
                    tried[k] = cap  # not that deep: no deeper cap can show it either
                    continue
                results[part.index] = res
                fresh += 1
                running = min(running, res.slack_m)
                if running < stop_below:
                    return st.merge(results), False
        for new, cost, _, k in todo:
            part = self._parts[k]
            if part.index in results:
                continue  # known from a capped query
            if running < stop_below or cost > max_cost or (new and fresh == max_parts):
                complete = False
                break
            res = st.evaluate(rotation, q, part)
            results[part.index] = res
            fresh += new
            if res is not None:
                running = min(running, res.slack_m)
        return st.merge(results), complete
