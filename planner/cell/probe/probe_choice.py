"""Deciding probe points from their candidates: broad phase first, Bullet only where needed.

The rule is :mod:`planner.cell.probe.probe_rule`'s (the same as the exact check's,
:func:`planner.cell.probe.check_probes` with ``staged=False``).

The work is done in four passes; the answers do not depend on them:

1. one broad-phase call for every point's first candidate (:mod:`planner.cell.broad.broad_phase`):
   when no part is left open, its clearance is the look distance and the point is decided;
2. a lean loop over the others: the open parts of the first candidate with Bullet (often just
   the sensor, which stands at the sensing distance from the surface);
3. one broad-phase call for the first :data:`FIRST_BLOCK` candidates of the points still open
   (the rest of the rows of the points that need more, up to ``max_checks``, in one call
   after pass 4 has paused them: see the end of this docstring); a point
   whose first candidate not shown below the margin is clear of everything is decided here;
4. per point: candidates in order until one passes (a candidate whose slack is shown below the
   margin, by the broad phase or by its GJK upper bound, :mod:`planner.cell.broad.slack_bounds`, is
   skipped), each one's open parts cheapest first, stopping as soon as its slack is shown
   below the margin; then the least-bad one, best candidates first (by upper bounds: GJK's and
   those of the parts already known), a candidate dropped as soon as its slack is shown to be
   more than the tie below the best exact slack found. With ``statuses_only`` (the heat map's
   :func:`planner.cell.probe.probe_statuses`), a point none of whose candidates passes
   stops at its status instead (:meth:`ProbeSearch._status`). A point that needs more of its
   candidates' broad-phase rows than the first block waits: the rest of the rows of all such
   points go to the broad phase in one call, then each point goes on where it stopped.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Generator
from functools import partial
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from planner.cell.broad import BroadPhase, EnvArrays, PartMap, SlackBounds, broad_phase_of
from planner.cell.kernels.broad_kernels import FIELD
from planner.cell.probe.probe_clearance import PointState, ProbeClearance
from planner.cell.probe.probe_flags import Block, CandidateFlags, clear_ahead
from planner.cell.probe.probe_parts import OpenParts
from planner.cell.probe.probe_rule import CLEARANCE_TIE_M, Decision, Verdict, least_bad, passes
from planner.cell.scene import Clearance, QueryPart

if TYPE_CHECKING:
    from planner.cell.probe.probe_candidates import ProbeCandidates
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Candidates of an open point whose broad phase runs with the batch (most such points pass
#: within them); a point that needs more gets the rest in one call.
FIRST_BLOCK = 16

#: Pass 4 of one point (:meth:`ProbeSearch._search`): yields when it needs rows of its flags not
#: yet known, returns its decision.
_Steps = Generator[None, None, "Decision | Verdict"]


def _finish(steps: _Steps) -> Decision | Verdict:
    """Run a point's pass 4 to its decision (rows still missing are computed one point at a
    time by its flags)."""
    while True:
        try:
            next(steps)
        except StopIteration as done:
            return done.value


class ProbeSearch:
    """Decides probe points of one cell (see the module docstring).

    Args:
        cell: the cell (its joint state changes; restore it with ``cell.saved_state()``).
        margin_m: required distance to the work object and fixtures, m.
        max_checks: most candidates considered per point.
    """

    def __init__(
        self, cell: CellScene, margin_m: float, max_checks: int, statuses_only: bool = False
    ) -> None:
        self._cell = cell
        self.statuses_only = statuses_only
        self.margin = margin_m
        self.max_checks = max_checks
        self.stages = ProbeClearance(cell, margin_m)
        self.broad: BroadPhase = broad_phase_of(cell)
        self.env: EnvArrays = self.broad.environment(cell)
        self.parts: PartMap = self.broad.part_map(cell, self.stages.plan, self.env)
        plan_parts = self.stages.plan.parts
        self._env_parts: list[QueryPart] = [plan_parts[int(i)] for i in self.parts.part_index]
        #: per env part: 0 against a box, cylinder or sphere (cheap in Bullet), 1 against a
        #: mesh; and the size of its link (its tree's root radius): small links go first.
        self._cost = [int(self.env.arrays[0][e] == FIELD) for e in self.parts.part_env]
        self._size = [self.broad.link_radius(int(k)) for k in self.parts.part_link]
        self.bounds = SlackBounds(self.broad, self.parts, self.env, self.stages.plan)
        self.open_parts = OpenParts(self.stages, self._env_parts, self._cost, self._size)
        #: how many points each pass decided (for profiling and the bench).
        self.decided_by = {"broad": 0, "first": 0, "ahead": 0, "search": 0}

    def run(self, cands: ProbeCandidates) -> list[Decision | Verdict | None]:
        """One decision per point (``None`` for points without a usable candidate); with
        ``statuses_only``, a :class:`~planner.cell.probe.probe_rule.Verdict` for a point none of
        whose candidates passes when its status is known without the least-bad one."""
        N = cands.q.shape[0]
        out: list[Decision | Verdict | None] = [None] * N
        first = cands.first()
        idx = np.flatnonzero(first >= 0)
        if idx.size == 0:
            return out
        K = cands.per_rotation
        c0 = first[idx]
        pc, sc, _ = self._broad(cands, idx, c0)
        near = cands.near_limit[idx, c0]
        look = Clearance(True, self.stages.plan.look_m, self.stages.look_slack_m, None)
        all_clear = ((pc == 1).all(axis=1) & (sc == 1).all(axis=1)).tolist()
        fails = ((pc == -1).any(axis=1) | (sc == -1).any(axis=1)).tolist()
        open_pts = []
        for n, i in enumerate(idx.tolist()):
            if all_clear[n]:  # nothing within the look distance
                out[i] = Decision(int(c0[n]), look, True)
                self.decided_by["broad"] += 1
            else:
                open_pts.append(n)
        rest = []
        for n in open_pts:
            i, c = int(idx[n]), int(c0[n])
            if fails[n]:
                rest.append(i)  # it cannot pass
                continue
            self.stages.start_point(cands.T_base_flange[i])
            cl, _ = self.open_parts.evaluate(c // K, cands.q[i, c], pc[n] == 1, sc[n] == 1, {})
            top = cl.slack_m >= self.stages.look_slack_m - CLEARANCE_TIE_M
            if passes(cl, self.margin) and (not near[n] or top):
                out[i] = Decision(c, cl, True)  # passes; or near a limit and none can beat it
                self.decided_by["first"] += 1
            else:
                rest.append(i)
        if rest:  # one broad-phase call for the first candidates of all these points
            orders = [cands.order(i, self.max_checks) for i in rest]
            heads = [o[:FIRST_BLOCK] for o in orders]
            pts = np.repeat(np.array(rest), [len(h) for h in heads])
            pc_all, sc_all, op_all, ub_all = self._block(cands, pts, np.concatenate(heads))
            start = 0
            waiting: list[tuple[int, _Steps, CandidateFlags, PointState]] = []
            for i, order, head in zip(rest, orders, heads):
                sl = slice(start, start + len(head))
                start += len(head)
                c = clear_ahead(cands.near_limit[i], head, pc_all[sl], sc_all[sl])
                if c >= 0:  # what pass 4 would find first, without Bullet
                    out[i] = Decision(c, look, True)
                    self.decided_by["ahead"] += 1
                    continue
                flags = CandidateFlags(order, partial(self._point_block, cands, i))
                flags.put((pc_all[sl], sc_all[sl], op_all[sl], ub_all[sl]))
                steps = self._search(cands, i, order, flags)
                self.decided_by["search"] += 1
                try:
                    next(steps)
                except StopIteration as done:
                    out[i] = done.value
                    continue
                waiting.append((i, steps, flags, self.stages.point_state()))
            # the points that need more rows: the rest of their orders in one broad-phase call
            self._fill(cands, [(i, flags) for i, _, flags, _ in waiting])
            for i, steps, _, state in waiting:
                self.stages.resume_point(state)
                out[i] = _finish(steps)
        return out

    # ------------------------------------------------------------------ passes
    def _broad(
        self, cands: ProbeCandidates, pts: NDArray[np.int_], cs: NDArray[np.int_]
    ) -> tuple[NDArray[np.int8], NDArray[np.int8], NDArray[np.int64]]:
        """Broad-phase states of candidates ``cs`` of points ``pts`` (see
        :meth:`planner.cell.broad.BroadPhase.states`)."""
        K = cands.per_rotation
        T_bf = cands.T_base_flange[pts, cs // K]
        T_links = self.broad.link_poses(self._cell, cands.q[pts, cs], T_bf)
        return self.broad.states(self.parts, self.env, T_links)

    def _point_block(self, cands: ProbeCandidates, i: int, cs: NDArray[np.int_]) -> Block:
        """:meth:`_block` of candidates ``cs`` of point ``i``."""
        return self._block(cands, np.full(cs.size, i), cs)

    def _block(self, cands: ProbeCandidates, pts: NDArray[np.int_], cs: NDArray[np.int_]) -> Block:
        """Broad-phase states and slack upper bounds of candidates ``cs`` of points ``pts``."""
        K = cands.per_rotation
        T_bf = cands.T_base_flange[pts, cs // K]
        T_links = self.broad.link_poses(self._cell, cands.q[pts, cs], T_bf)
        pc, sc, opened = self.broad.states(self.parts, self.env, T_links)
        return pc, sc, opened, self.bounds.upper(T_links, pc, sc)

    def _fill(self, cands: ProbeCandidates, points: list[tuple[int, CandidateFlags]]) -> None:
        """The missing rows of the flags of ``points`` (point, its flags) in one call."""
        missing = [flags.missing() for _, flags in points]
        sizes = [m.size for m in missing]
        if sum(sizes) == 0:
            return
        pts = np.repeat(np.array([i for i, _ in points]), sizes)
        pc, sc, op, ub = self._block(cands, pts, np.concatenate(missing))
        start = 0
        for (_, flags), size in zip(points, sizes):
            sl = slice(start, start + size)
            start += size
            if size:
                flags.put((pc[sl], sc[sl], op[sl], ub[sl]))

    def _search(
        self, cands: ProbeCandidates, i: int, order: NDArray[np.int_], flags: CandidateFlags
    ) -> _Steps:
        """Pass 4 for point ``i``: candidates ``order``, broad-phase flags from ``flags``.

        A generator: it stops (yields) before it reads a row of ``flags`` not yet known, so
        that the caller can compute the missing rows of many points in one call
        (:meth:`_fill`) and then resume it; it returns the decision. Rows asked for without
        that are computed by ``flags`` itself, one point at a time.
        """
        K = cands.per_rotation
        near = cands.near_limit[i]
        self.stages.start_point(cands.T_base_flange[i])
        results: list[dict[int, Clearance | None]] = [{} for _ in range(order.size)]
        tried: list[dict[int, float]] = [{} for _ in range(order.size)]
        exact: dict[int, Clearance] = {}
        bound: dict[int, float] = {}  # j -> upper bound of the slack
        look = self.stages.look_slack_m

        def run(
            j: int, stop_below: float, max_cost: int = 1, max_parts: int = -1, certify: bool = False
        ) -> None:
            c = int(order[j])
            clear, pairs_clear = flags.clear(j)
            cl, complete = self.open_parts.evaluate(
                c // K, cands.q[i, c], clear, pairs_clear, results[j], stop_below, max_cost,
                max_parts, certify, tried[j],
            )  # fmt: skip
            if complete:
                exact[j] = cl
                bound.pop(j, None)
            else:
                bound[j] = min(bound.get(j, math.inf), cl.slack_m)

        below_margin = math.nextafter(self.margin, -math.inf)
        for j, c in enumerate(order.tolist()):
            if near[c]:
                break  # the rest are near a limit too: none can be chosen outright
            if j >= flags.rows:
                yield  # the caller computes the missing rows
            u = flags.upper(j)
            if flags.fails(j):
                u = min(u, below_margin)  # shown below the margin
            if u < math.inf:
                bound[j] = u
            if u < self.margin:
                continue  # it cannot pass
            if flags.all_clear(j):  # nothing near: the look distance, which passes
                return Decision(c, self.stages.merge({}), True)
            run(j, self.margin)
            if j in exact and passes(exact[j], self.margin):
                return Decision(c, exact[j], True)
        if flags.rows < len(order):
            yield  # the phases below read every row
        if self.statuses_only:
            verdict = self._status(order, flags, exact, bound, run)
            if verdict is not None:
                return verdict
        # the least-bad one: candidates the broad phase clears have the look distance
        for j in range(len(order)):
            if j not in exact and flags.all_clear(j):
                run(j, -math.inf)
        for j in range(len(order)):  # the bounds without Bullet (GJK on the exact shapes)
            if j not in exact and flags.upper(j) < bound.get(j, math.inf):
                bound[j] = flags.upper(j)
        top = max((cl.slack_m for cl in exact.values()), default=-math.inf)
        if top < look - CLEARANCE_TIE_M:  # bounds from the cheap parts order the rest
            rest = sorted((j for j in range(len(order)) if j not in exact),
                          key=lambda j: -bound.get(j, look))  # fmt: skip
            for j in rest:
                if bound.get(j, look) < top - CLEARANCE_TIE_M:
                    continue  # cannot reach the tie
                run(j, -math.inf, max_cost=0)
                if j in exact:
                    top = max(top, exact[j].slack_m)
        # best first: refine the candidate with the highest bound (no slack exceeds the look
        # distance's), one part at a time, until no open candidate can reach the tie
        heap = [
            (-bound.get(j, look), flags.opened(j), j) for j in range(len(order)) if j not in exact
        ]
        heapq.heapify(heap)
        while heap:
            neg, opened, j = heapq.heappop(heap)
            floor = top - CLEARANCE_TIE_M
            if -neg < floor:
                break  # nor can any other
            lead = next((k for k in sorted(exact) if exact[k].slack_m >= floor), None)
            if lead is not None and j > lead and -neg <= exact[lead].slack_m + CLEARANCE_TIE_M:
                continue  # comes after a tie member it cannot push out of the tie
            run(j, floor, max_parts=1, certify=floor < 0)
            if j in exact:
                top = max(top, exact[j].slack_m)
            else:
                heapq.heappush(heap, (-bound[j], opened, j))
        seen = [(int(order[j]), exact[j]) for j in sorted(exact)]
        return least_bad(seen)

    def _status(
        self,
        order: NDArray[np.int_],
        flags: CandidateFlags,
        exact: dict[int, Clearance],
        bound: dict[int, float],
        run: Callable[..., None],
    ) -> Verdict | None:
        """The status of a point none of whose candidates passes, without its least-bad one.

        The least-bad candidate is ``marginal`` when its slack is >= 0 (no collision); it has
        the largest slack but for the tie, so a candidate with slack >= the tie makes the point
        ``marginal`` and every candidate shown below 0 makes it ``infeasible``. Candidates go
        highest upper bound first; each one's open parts stop as soon as its slack is shown
        below 0 (deep work-object parts with a capped query first). ``None`` (decide it by the
        rule) when the largest slack lies within the tie above 0.
        """
        tie = False
        look = self.stages.look_slack_m
        rows = sorted(range(len(order)), key=lambda j: -min(bound.get(j, look), flags.upper(j)))
        for j in rows:
            if flags.all_clear(j):  # the look distance: no collision, so a joint near its limit
                return Verdict("marginal", "joint_limit")
            if min(bound.get(j, look), flags.upper(j)) < 0.0 and j not in exact:
                continue  # shown to collide
            if j not in exact:
                run(j, 0.0, certify=True)
            if j in exact:
                if exact[j].slack_m >= CLEARANCE_TIE_M:
                    near = exact[j].slack_m >= self.margin  # clear enough: near a limit
                    return Verdict("marginal", "joint_limit" if near else "collision")
                tie = tie or exact[j].slack_m >= 0.0
        return None if tie else Verdict("infeasible", "collision")
