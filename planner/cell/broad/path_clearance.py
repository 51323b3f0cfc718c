"""The clearance of a sampled path: its first sample whose clearance query fails, and every
sample's clearance up to it.

:func:`first_failure` gives what the plain loop gives up to its first failing sample::

    for j, q in enumerate(q_path):
        cell.set_joint_positions(q)
        cl = cell.clearance(margin_m, sensor_wobj_allowed=True, skip_wobj=skip_wobj[j])
        if not cl.ok:
            return j, cl

that sample and its whole query's :class:`~planner.cell.scene.Clearance` (so its reason
reads exactly the same), or none. The broad phase (:mod:`planner.cell.broad.broad_phase`) shows,
for every sample of the path at once, which parts of the query report nothing in Bullet; only
the others are asked, one part at a time, and a sample stops at its first part that fails
(a sample fails when any part has a point nearer than it needs; a part the broad phase clears
has none). The whole query runs only at a failing sample. What it does not give is the
clearance of the passing samples (the loop's running minimum): a verdict, not a measure.

Used where only the verdict counts: the vetting of simulated searches
(:func:`planner.sim.search_events.program_search_hook`, ``check_search(..., exact_clearance=
False)``), thousands of short paths.

:func:`path_clearances` is the measure: every sample's whole query, bit for bit, up to the
first that fails. A part the broad phase clears reports nothing, and the query's result is the
merge of what its parts report (:meth:`~planner.cell.scene.QueryPlan.merge`), so only the open
parts go to Bullet, all of them (a sample does not stop at its first failing part). Used by
``check_search``'s default (its ``min_clearance_m``), as the plan check runs it on every search.

``tests/planner/cell/broad/test_path_clearance.py`` holds both to the loop.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from planner.cell.broad.broad_phase import broad_phase_of
from planner.cell.scene import Clearance

if TYPE_CHECKING:
    from planner.cell.scene import CellScene, QueryPart, QueryPlan

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


def first_failure(
    cell: CellScene,
    q_path: FloatArray,
    T_base_flange: FloatArray,
    skip_wobj: BoolArray,
    margin_m: float,
) -> tuple[int, Clearance | None]:
    """The first sample of a path whose clearance query fails (module docstring).

    Args:
        cell: the cell (its joint state changes; restore it with ``cell.saved_state()``).
        q_path: ``(M, n)`` joint values of the samples, rad.
        T_base_flange: ``(M, 4, 4)`` the flange pose of each sample (where the tool sits),
            robot base frame, m.
        skip_wobj: ``(M,)`` samples checked without the work object (an approach past its
            nominal point).
        margin_m: required distance of robot and tool to the work object and fixtures, m.

    Returns:
        ``(j, clearance)`` of the first failing sample, or ``(M, None)`` when all pass.
    """
    return first_failures(cell, [(q_path, T_base_flange, skip_wobj)], margin_m)[0]


def first_failures(
    cell: CellScene,
    paths: Sequence[tuple[FloatArray, FloatArray, BoolArray]],
    margin_m: float,
) -> list[tuple[int, Clearance | None]]:
    """:func:`first_failure` of each of many paths ``(q_path, T_base_flange, skip_wobj)``,
    the same answers; the broad phase runs once over the samples of all of them.

    Args:
        cell: the cell (its joint state changes; restore it with ``cell.saved_state()``).
        paths: each path's ``(M_i, n)`` joint values (rad), ``(M_i, 4, 4)`` flange poses
            (robot base frame, m) and ``(M_i,)`` samples checked without the work object.
        margin_m: required distance of robot and tool to the work object and fixtures, m.

    Returns:
        Per path, ``(j, clearance)`` of its first failing sample, or ``(M_i, None)``.
    """
    sizes = [int(np.asarray(q).shape[0]) for q, _, _ in paths]
    out: list[tuple[int, Clearance | None]] = [(0, None)] * len(paths)
    if sum(sizes) == 0:
        return out
    live = [i for i, m in enumerate(sizes) if m > 0]
    q_all = np.concatenate([np.asarray(paths[i][0], float) for i in live])
    T_all = np.concatenate([np.asarray(paths[i][1], float) for i in live])
    broad = _BroadStates.of(cell, q_all, T_all, margin_m)
    checker = cell.checker
    at = 0
    for i in live:
        q_path, _, skip_wobj = paths[i]
        M = sizes[i]
        out[i] = (M, None)
        for j in range(M):
            row = at + j
            todo, pairs = broad.open(row, bool(skip_wobj[j]))
            if not todo.any() and not pairs.any():
                continue
            cell.set_joint_positions(q_path[j])
            failed = False
            for k in np.flatnonzero(todo).tolist():
                res = checker.evaluate(broad.env_parts[k])
                if res is not None and not res.ok:
                    failed = True
                    break
            if not failed and pairs.any():
                res = checker.evaluate(broad.self_part, pairs)
                failed = res is not None and not res.ok
            if failed:  # the whole query, for its reason (it fails as its part did)
                whole = cell.clearance(
                    margin_m, sensor_wobj_allowed=True, skip_wobj=bool(skip_wobj[j])
                )
                if not whole.ok:
                    out[i] = (j, whole)
                    break
        at += M
    return out


def path_clearances(
    cell: CellScene,
    q_path: FloatArray,
    T_base_flange: FloatArray,
    skip_wobj: BoolArray,
    margin_m: float,
) -> list[Clearance]:
    """Each sample's clearance query, up to and including the first that fails (module
    docstring): what the loop of ``cell.clearance(margin_m, sensor_wobj_allowed=True,
    skip_wobj=skip_wobj[j])`` gives, bit for bit, pair names and all.

    Args:
        cell: the cell (its joint state changes; restore it with ``cell.saved_state()``).
        q_path: ``(M, n)`` joint values of the samples, rad.
        T_base_flange: ``(M, 4, 4)`` the flange pose of each sample, robot base frame, m.
        skip_wobj: ``(M,)`` samples checked without the work object.
        margin_m: required distance of robot and tool to the work object and fixtures, m.

    Returns:
        The samples' :class:`Clearance`, ``M`` of them when none fails, else up to the first
        that is not ``ok``.
    """
    M = int(np.asarray(q_path).shape[0])
    if M == 0:
        return []
    broad = _BroadStates.of(
        cell, np.asarray(q_path, float), np.asarray(T_base_flange, float), margin_m
    )
    checker = cell.checker
    nothing = broad.plan.merge([])  # no part reports anything: the look distance
    out: list[Clearance] = []
    for j in range(M):
        todo, pairs = broad.open(j, bool(skip_wobj[j]))
        if not todo.any() and not pairs.any():
            out.append(nothing)
            continue
        cell.set_joint_positions(q_path[j])
        # the parts that report, in the query's canonical order (merge keeps the first of a tie)
        results: list[tuple[int, Clearance | None]] = [
            (broad.env_parts[k].index, checker.evaluate(broad.env_parts[k]))
            for k in np.flatnonzero(todo).tolist()
        ]
        if pairs.any():
            results.append((broad.self_part.index, checker.evaluate(broad.self_part, pairs)))
        results.sort(key=lambda r: r[0])
        cl = broad.plan.merge([r for _, r in results])
        out.append(cl)
        if not cl.ok:
            break
    return out


@dataclass(frozen=True)
class _BroadStates:
    """The broad phase's answer for the samples of one or more paths: which parts of the
    query (robot and tool links against each environment body, and the self pairs) may report
    anything in Bullet, per sample."""

    plan: QueryPlan
    env_parts: list[QueryPart]
    on_wobj: BoolArray
    self_part: QueryPart
    open_parts: BoolArray
    open_pairs: BoolArray

    @staticmethod
    def of(
        cell: CellScene, q: FloatArray, T_base_flange: FloatArray, margin_m: float
    ) -> _BroadStates:
        """The states of the samples ``q (M, n)`` with flange poses ``T_base_flange``."""
        checker = cell.checker
        plan = checker.plan(margin_m, cell.self_margin_m, None, True, False)
        broad = broad_phase_of(cell)
        env = broad.environment(cell)
        parts = broad.part_map(cell, plan, env)
        T_links = broad.link_poses(cell, q, T_base_flange)
        part_state, pair_state, _ = broad.states(parts, env, T_links)
        env_parts = [plan.parts[int(i)] for i in parts.part_index]
        on_wobj = np.array([p.env == checker.wobj_body for p in env_parts], dtype=bool)
        return _BroadStates(
            plan, env_parts, on_wobj, plan.parts[-1], part_state != 1, pair_state != 1
        )

    def open(self, row: int, skip_wobj: bool) -> tuple[BoolArray, BoolArray]:
        """``(environment parts, self pairs)`` of sample ``row`` that may report (the work
        object's parts left out when ``skip_wobj``)."""
        todo = self.open_parts[row] & ~self.on_wobj if skip_wobj else self.open_parts[row]
        return todo, self.open_pairs[row]
